// SPDX-License-Identifier: Apache-2.0
// The master's view of one CiA 402 drive, I/O-free: start-up (NMT, SDO configuration of the
// mode and periods, NMT start), the enable sequence driven by the drive's statusword, the
// per-tick CSP RPDO, and supervision of its heartbeat, EMCY and feedback. The servo loop owns
// one per axis, feeds it every received frame and asks it each tick for the RPDO to send.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <climits>
#include <optional>
#include <span>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/emcy.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/process_data.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/canopen/watchdog.hpp"
#include "settle/hal/enum_text.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen {

// The master's half of the power state machine: for the state a statusword reports, the
// controlword that moves the drive one step towards operation enabled
// (Shutdown 0x06 -> Switch on 0x07 -> Enable operation 0x0F; a fault is reset by a rising
// bit 7, so 0x80 alternates with 0x00 until the drive leaves the fault state).
class EnableSequence {
 public:
  [[nodiscard]] std::uint16_t next(std::uint16_t statusword) noexcept;
  [[nodiscard]] static bool done(std::uint16_t statusword) noexcept { return is_operation_enabled(statusword); }
  void reset() noexcept { last_ = 0; }

 private:
  std::uint16_t last_{0};
};

// 0x60C2 as value x 10^index s for a period in µs: the largest index whose value fits a byte.
struct InterpolationPeriod {
  std::uint8_t value{1};
  std::int8_t index{-3};
};
[[nodiscard]] std::optional<InterpolationPeriod> interpolation_period_from_us(std::uint32_t period_us) noexcept;

// How start-up sets up the drive's PDOs (see process_data.hpp).
enum class PdoSetup : std::uint8_t {
  assume,       // the drive's mapping is `layout` already (Settle's drive: the default): nothing written
  dynamic,      // CiA 301 dynamic mapping of `layout`; the PDOs it does not use are disabled
  read_static,  // read the drive's mapping (RPDO/TPDO 1..4) and derive the layout from it; a mapping
                // without the controlword + target position in one RPDO, without the statusword or the
                // position actual in a TPDO, or with an RPDO the master cannot fill, is refused
};

struct RemoteDriveConfig {
  NodeId node{1};
  OperationMode mode{OperationMode::cyclic_synchronous_position};
  std::uint32_t sync_period_us{default_sync_period_us};
  // Write sync_period_us to the drive's 0x1006. CiA 301 asks 0x1006 only of the SYNC producer: a
  // drive whose description lacks it is not written (eds::drive_config_from_eds clears this; the
  // drive then takes its period from 0x60C2). Settle's own drive has it.
  bool write_sync_period{true};
  // Write the period to 0x60C2 (interpolation time period). A drive without it takes the period
  // from 0x1006 (eds::drive_config_from_eds clears this for such a description).
  bool write_interpolation_period{true};
  std::uint32_t sdo_timeout_us{100'000};        // per SDO request; a request that times out is sent once more
  std::uint32_t enable_timeout_us{1'000'000};   // from NMT start to operation enabled
  std::uint16_t heartbeat_timeout_ms{0};        // watch the drive's heartbeat; 0 = do not
  NodeId master_node{0};                        // non-zero: the drive watches this heartbeat (0x1016)
  std::uint16_t master_heartbeat_timeout_ms{0};
  std::uint8_t communication_loss_periods{0};   // non-zero: written to the drive's 0x2001
  std::uint16_t heartbeat_period_ms{0};         // non-zero: written to the drive's 0x1017
  // The drive's identity (0x1018:1..4) when the user knows which drive must be there; 0 = any.
  std::uint32_t expected_vendor_id{0};
  std::uint32_t expected_product_code{0};
  std::uint32_t expected_revision{0};
  std::uint32_t expected_serial{0};
  // Following error window 0x6065 (counts) and time-out 0x6066 (ms), written when the window is
  // non-zero; otherwise the drive keeps its own.
  std::uint32_t following_error_window{0};
  std::uint16_t following_error_timeout_ms{0};
  PdoSetup pdo_setup{PdoSetup::assume};
  ProcessDataLayout layout{};
};

// What the drive said about its limits at start-up (0x607D, 0x607F); a drive without the objects
// leaves the defaults, which limit nothing.
struct RemoteDriveLimits {
  std::int32_t position_min{INT32_MIN};  // 0x607D:1, counts
  std::int32_t position_max{INT32_MAX};  // 0x607D:2, counts
  std::uint32_t max_profile_velocity{0};  // 0x607F, counts/s; 0 = not stated
  [[nodiscard]] constexpr bool has_position_limits() const noexcept {
    return position_min < position_max && (position_min != INT32_MIN || position_max != INT32_MAX);
  }
};

// One SDO transfer of start-up, eight bytes, so a long list costs little RAM:
//   write  download `value` (size bytes), then upload the same object: another value read back
//          fails start-up (wrong_value naming the object), so a drive that ignores a write is caught;
//   check  upload and compare the low `size` bytes with `value`;
//   read   upload and keep the value in a field of RemoteDriveLimits;
//   read_mapping  upload a PDO's COB-ID (communication object sub 1) and, unless bit 31 says the
//          PDO does not exist, its mapping object's sub 0 and entries, and place what they map
//          into the layout (PdoSetup::read_static).
// An optional step is skipped when the drive has no such object (abort 0x06020000/0x06090011).
// A COB-ID write compares its read-back without bit 30 (a drive may set "no RTR" by itself).
enum class StartupAction : std::uint8_t { write = 0, check = 1, read = 2, read_mapping = 3 };
enum class StartupField : std::uint8_t { none = 0, position_min = 1, position_max = 2, max_profile_velocity = 3 };

class StartupStep {
 public:
  constexpr StartupStep() noexcept = default;
  [[nodiscard]] static constexpr StartupStep write(std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                                                   std::uint8_t size) noexcept {
    return StartupStep{index, sub, StartupAction::write, size, StartupField::none, false, value};
  }
  [[nodiscard]] static constexpr StartupStep check(std::uint16_t index, std::uint8_t sub, std::uint32_t expected,
                                                   std::uint8_t compared_bytes) noexcept {
    return StartupStep{index, sub, StartupAction::check, compared_bytes, StartupField::none, false, expected};
  }
  [[nodiscard]] static constexpr StartupStep read(std::uint16_t index, std::uint8_t sub, StartupField field,
                                                  bool optional) noexcept {
    return StartupStep{index, sub, StartupAction::read, 4, field, optional, 0};
  }
  [[nodiscard]] static constexpr StartupStep write_cob_id(std::uint16_t index, std::uint32_t value,
                                                          bool optional = false) noexcept {
    StartupStep s{index, 1, StartupAction::write, 4, StartupField::none, optional, value};
    s.op_ = static_cast<std::uint8_t>(s.op_ | 0x10U);
    return s;
  }
  [[nodiscard]] static constexpr StartupStep read_mapping(std::uint16_t mapping_index) noexcept {
    return StartupStep{mapping_index, 0, StartupAction::read_mapping, 1, StartupField::none, true, 0};
  }

  [[nodiscard]] constexpr std::uint16_t index() const noexcept { return index_; }
  [[nodiscard]] constexpr std::uint8_t sub() const noexcept { return sub_; }
  [[nodiscard]] constexpr StartupAction action() const noexcept { return static_cast<StartupAction>(op_ & 0x3U); }
  [[nodiscard]] constexpr StartupField field() const noexcept { return static_cast<StartupField>((op_ >> 2U) & 0x3U); }
  [[nodiscard]] constexpr bool cob_id() const noexcept { return (op_ & 0x10U) != 0; }
  [[nodiscard]] constexpr bool optional() const noexcept { return (op_ & 0x20U) != 0; }
  // Bytes written, or compared (from the low end of the value read).
  [[nodiscard]] constexpr std::uint8_t size() const noexcept { return static_cast<std::uint8_t>(((op_ >> 6U) & 0x3U) + 1U); }
  [[nodiscard]] constexpr std::uint32_t value() const noexcept { return value_; }
  // The bits of a value read that must equal value().
  [[nodiscard]] constexpr std::uint32_t mask() const noexcept {
    if (cob_id()) return ~pdo_cob_id_no_rtr;
    return size() >= 4 ? 0xFFFF'FFFFU : (std::uint32_t{1} << (8U * size())) - 1U;
  }
  friend constexpr bool operator==(const StartupStep&, const StartupStep&) = default;

 private:
  constexpr StartupStep(std::uint16_t index, std::uint8_t sub, StartupAction action, std::uint8_t size,
                        StartupField field, bool optional, std::uint32_t value) noexcept
      : index_{index},
        sub_{sub},
        op_{static_cast<std::uint8_t>(static_cast<unsigned>(action) | (static_cast<unsigned>(field) << 2U) |
                                      (optional ? 0x20U : 0U) |
                                      ((static_cast<unsigned>(size < 1 ? 1 : (size > 4 ? 4 : size)) - 1U) << 6U))},
        value_{value} {}

  std::uint16_t index_{0};
  std::uint8_t sub_{0};
  std::uint8_t op_{0};  // bits 0-1 action, 2-3 field, 4 COB-ID, 5 optional, 6-7 size - 1
  std::uint32_t value_{0};
};

// Steps a RemoteDrive holds. The Cortex-M0 image, whose RAM is nearly full, builds with a smaller
// list (SETTLE_REMOTE_DRIVE_MAX_STEPS); a configuration needing more fails start-up (plan_too_long).
#ifndef SETTLE_REMOTE_DRIVE_MAX_STEPS
#define SETTLE_REMOTE_DRIVE_MAX_STEPS 64
#endif
inline constexpr std::size_t remote_drive_max_steps = SETTLE_REMOTE_DRIVE_MAX_STEPS;

// The steps for a configuration, in the order start-up runs them:
//   0x1000 low 16 bits = 402 (not_cia402); 0x1018:1..4 when expected (wrong_identity);
//   0x6060 mode; 0x60C2:1/2 interpolation period; 0x1006 SYNC period unless told not to; 0x2001 when set;
//   0x1016:1 master heartbeat when set; 0x1017 when set; 0x6065/0x6066 when the window is set;
//   the PDOs (dynamic: per PDO used: COB-ID bit 31 set, mapping sub 0 = 0, the entries, sub 0 = n,
//   transmission type 1, COB-ID enabled; every other PDO disabled, when the drive has it;
//   read_static: the mapping objects read); 0x607D:1/2 and 0x607F read (optional); 0x6061 shows the mode (mode_not_applied).
// Returns the number of steps, or nullopt when `out` is too short.
[[nodiscard]] std::optional<std::size_t> plan_start_up(const RemoteDriveConfig& config,
                                                       std::span<StartupStep> out) noexcept;

// Made from one list (enum_text.hpp): enumerator (= code, to_string) and sentence (describe).
#define SETTLE_HAL_REMOTE_DRIVE_STATES(X) \
  X(idle, "start() not called") \
  X(configuring, "NMT pre-operational, SDO configuration, NMT start") \
  X(enabling, "enable sequence over RPDO1/TPDO1: the loop must tick (RPDO + SYNC)") \
  X(ready, "operation enabled in the configured mode: setpoints may be streamed") \
  X(stopped, "the drive left operation enabled (fault, quick stop): call recover()") \
  X(lost, "its heartbeat timed out") \
  /* no process data; start() runs start-up again */ \
  X(not_operational, \
    "its heartbeat said pre-operational or stopped after it had been operational (someone else's NMT command)") \
  X(failed, "configuration refused or timed out, or enabling timed out: see failure()") \
  /* until the statusword shows the drive out of operation enabled */ \
  X(releasing, "release(): the RPDO carries Shutdown (0x06) with the target held") \
  /* no process data; recover() enables it again */ \
  X(released, "the statusword confirmed the release (ready to switch on, or switched on)")
enum class RemoteDriveState : std::uint8_t { SETTLE_HAL_REMOTE_DRIVE_STATES(SETTLE_ENUM_ENUMERATOR) };

[[nodiscard]] const char* to_string(RemoteDriveState state) noexcept;
[[nodiscard]] const char* describe(RemoteDriveState state) noexcept;

// Why start-up failed, in one word.
#define SETTLE_HAL_STARTUP_ERRORS(X) \
  X(none, "no error") \
  X(sdo_aborted, "the drive refused a transfer: see abort") \
  X(sdo_timed_out, "no answer, twice") \
  X(wrong_value, "a write read back as another value") \
  X(not_cia402, "0x1000's low 16 bits are not 402") \
  X(wrong_identity, "0x1018:sub is not the expected one") \
  X(mode_not_applied, "0x6061 does not show the mode written") \
  X(plan_too_long, "the configuration needs more steps than remote_drive_max_steps") \
  X(bad_layout, "the configured ProcessDataLayout is not valid (check_layout): nothing sent") \
  /* read_static */ \
  X(mapping_unsuitable, \
    "the drive's mapping lacks the object `index` (or maps, in an RPDO, the object `index`, which the " \
    "master cannot fill)") \
  X(enable_timeout, "operation enabled not reached in time")
enum class StartupError : std::uint8_t { SETTLE_HAL_STARTUP_ERRORS(SETTLE_ENUM_ENUMERATOR) };
[[nodiscard]] const char* to_string(StartupError error) noexcept;
[[nodiscard]] const char* describe(StartupError error) noexcept;

// Why start-up failed.
struct RemoteDriveFailure {
  std::uint16_t index{0};
  std::uint8_t sub{0};
  SdoClientStatus status{SdoClientStatus::idle};
  SdoAbort abort{SdoAbort::none};
  bool wrong_value{false};    // read a value other than the one configured (or expected): see error
  bool enable_timeout{false};
  StartupError error{StartupError::none};
  std::uint32_t expected{0};  // with wrong_value: what was written (or expected), and what came back
  std::uint32_t actual{0};
};

// Things that happened since the last take_events(), for the loop to report.
namespace remote_event {
inline constexpr std::uint16_t boot_up = 0x0001;          // the drive restarted: start-up re-runs
inline constexpr std::uint16_t heartbeat_lost = 0x0002;
inline constexpr std::uint16_t heartbeat_back = 0x0004;
inline constexpr std::uint16_t emcy = 0x0008;             // see last_emcy()
inline constexpr std::uint16_t became_ready = 0x0010;
inline constexpr std::uint16_t left_enabled = 0x0020;     // fault or quick stop while ready
inline constexpr std::uint16_t failed = 0x0040;
inline constexpr std::uint16_t left_operational = 0x0080;  // heartbeat: pre-operational or stopped
}  // namespace remote_event

// What on_frame found a received frame to be.
enum class RemoteFrame : std::uint8_t {
  ignored,    // another node's, not CANopen, or a service the master does not consume
  nmt,        // another node's NMT command that took this drive out of operational
  heartbeat,  // this drive's heartbeat or boot-up
  emcy,
  tpdo1,      // a TPDO of the layout before its period's last (Settle's TPDO1: statusword + position
              // actual): feedback() updated
  tpdo2,      // the period's last TPDO (Settle's TPDO2; the statusword's when it is the layout's only
              // feedback TPDO; under split feedback, feedback_split, the whole period taken): feedback()
              // updated, the period complete. A TPDO carrying nothing the master reads is ignored.
  sdo,        // an SDO response (used while configuring)
  // Split feedback: one period's values come in several TPDOs, which the drive sends on the same
  // SYNC in PDO order (TPDO1 before TPDO2: also their priority on the bus). Each is held until the
  // period's last arrives; a TPDO out of that order means one of a period's TPDOs is missing, and
  // what was held of that period is dropped, never completed with another period's values.
  held,       // a period's TPDO before its last: held, feedback() unchanged
  dropped,    // a TPDO of a period whose earlier TPDO is missing: dropped (RemoteFeedback::tpdos_dropped)
};

struct RemoteFeedback {
  std::uint16_t statusword{0};
  std::int32_t position_actual{0};
  std::int32_t load_position{0};
  std::int32_t velocity_actual{0};
  std::int32_t following_error{0};  // 0x60F4, when the layout maps it
  std::uint64_t tpdo1_received{0};
  // Periods whose last TPDO came (in every layout: Settle's TPDO2; the statusword's TPDO when it is
  // the only feedback TPDO; under split feedback, periods taken whole): the loop logs one sample each.
  std::uint64_t periods_complete{0};
  std::uint64_t tpdo1_time_us{0};  // when the latest TPDO1 was taken (the caller's time)
  // Split feedback: TPDOs of periods that never came complete (held ones, and ones whose period's
  // earlier TPDO was missing), dropped rather than mixed with another period's.
  std::uint32_t tpdos_dropped{0};
};

class RemoteDrive {
 public:
  explicit RemoteDrive(const RemoteDriveConfig& config) noexcept;

  // Begins (or restarts) start-up from the configuration step.
  void start(std::uint64_t now_us, FrameSink& out) noexcept;
  // After stopped/failed/released: runs the enable sequence again (the configuration is kept).
  void recover(std::uint64_t now_us) noexcept;
  // Ready -> releasing: the master is about to go quiet (no more SYNCs or setpoints), so it takes
  // the drive out of operation enabled first, rather than leaving it to detect the silence (an
  // EMCY and a quick stop). rpdo() carries the controlword Shutdown (CiA 402 transition 8, to
  // ready to switch on) with the target the caller holds; poll() sees the statusword confirm it
  // (released) or show anything else but operation enabled (stopped, left_enabled: a fault or a
  // quick stop instead). In any other state: nothing (a drive not enabled needs no release).
  void release() noexcept;

  // Every received frame goes here; frames of other nodes are ignored. The drive's process data
  // (two frames every period) and its heartbeat are recognised inline by exact identifier and
  // length and decoded in place (on_process_frame); everything else (on_other_frame) is routed by
  // its function code, out of line, so a frame costs one decoder, not a try of each.
  RemoteFrame on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept {
    RemoteFrame what{RemoteFrame::ignored};
    if (on_process_frame(frame, now_us, out, what)) return what;
    return on_other_frame(frame, now_us, out);
  }
  // on_frame's inline part, on any frame type with CanFrame's id, flags, len and word-aligned data
  // (a CanFrame; a controller's receive record read in place, hal::MailboxBus::Record): the default
  // layout's two TPDOs and the heartbeat. True with what on_frame would return in `what`; false,
  // nothing changed, for every other frame, which on_other_frame then takes.
  template <typename Frame>
  [[nodiscard]] bool on_process_frame(const Frame& frame, std::uint64_t now_us, FrameSink& out,
                                      RemoteFrame& what) noexcept {
    if (frame.flags != 0) return false;  // a classic data frame with a standard identifier
    if (default_layout_) {
      if (frame.id == tpdo1_id_ && frame.len == tpdo1_len_) {
        take_tpdo1(tpdo1_fields(frame), now_us);
        what = RemoteFrame::tpdo1;
        return true;
      }
      if (frame.id == tpdo2_id_ && frame.len == tpdo2_len_) {
        const Tpdo2 p = tpdo2_fields(frame);
        feedback_.load_position = p.load_position;
        feedback_.velocity_actual = p.velocity_actual;
        ++feedback_.periods_complete;
        what = RemoteFrame::tpdo2;
        return true;
      }
    }
    if (frame.id == heartbeat_id_ && frame.len == 1) {
      what = on_heartbeat(frame.data[0], now_us, out);
      return true;
    }
    return false;
  }
  // Every frame on_process_frame leaves: another layout's TPDOs (by exact identifier and length,
  // as on_process_frame takes the default layout's), SDO, EMCY, NMT.
  RemoteFrame on_other_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept;
  // Timeouts (SDO, heartbeat, enabling) and the next configuration step (sent from here, in a
  // later tick than the response to the step before).
  void poll(std::uint64_t now_us, FrameSink& out) noexcept;

  // The RPDO for this tick (RPDO1 under the default layout), written over `out`; false (and `out` untouched) when the drive must
  // not be sent process data. Enabling -> the enable sequence's controlword with the drive's own
  // position as target (so enabling never moves the axis); ready -> enable operation with the
  // given target; releasing -> Shutdown with the given target (the caller's last, held).
  [[nodiscard]] bool rpdo(std::int32_t target_counts, CanFrame& out) noexcept {
    if (state_ != RemoteDriveState::ready) return enabling_rpdo(target_counts, out);
    std::uint16_t cw = controlword::enable_operation;
    if (config_.mode == OperationMode::interpolated_position) cw |= controlword::enable_ip_mode;
    encode_rpdo(cw, target_counts, out);
    return true;
  }

  [[nodiscard]] RemoteDriveState state() const noexcept { return state_; }
  [[nodiscard]] bool ready() const noexcept { return state_ == RemoteDriveState::ready; }
  [[nodiscard]] Cia402State drive_state() const noexcept { return state_from_statusword(feedback_.statusword); }
  [[nodiscard]] const RemoteFeedback& feedback() const noexcept { return feedback_; }
  [[nodiscard]] const RemoteDriveFailure& failure() const noexcept { return failure_; }
  [[nodiscard]] const EmcyConsumer& emcy() const noexcept { return emcy_; }
  [[nodiscard]] std::uint16_t take_events() noexcept {
    const std::uint16_t e = events_;
    events_ = 0;
    return e;
  }
  [[nodiscard]] NodeId node() const noexcept { return config_.node; }
  [[nodiscard]] const RemoteDriveConfig& config() const noexcept { return config_; }
  // What start-up read: the software position limits and the maximum profile velocity.
  [[nodiscard]] const RemoteDriveLimits& limits() const noexcept { return limits_; }
  // The start-up steps planned for the configuration (empty when it needs too many).
  [[nodiscard]] std::span<const StartupStep> steps() const noexcept { return {steps_.data(), step_count_}; }

 private:
  void take_tpdo1(const Tpdo1& p, std::uint64_t now_us) noexcept {
    feedback_.statusword = p.statusword;
    feedback_.position_actual = p.position_actual;
    feedback_.tpdo1_time_us = now_us;
    ++feedback_.tpdo1_received;
    operational_seen_ = true;  // TPDOs flow only in NMT operational
    const bool enabled = EnableSequence::done(p.statusword);
    if (enabled != (state_ == RemoteDriveState::ready)) enabled_changed(enabled);
  }
  // Enabling -> ready on the first enabled statusword; ready -> stopped when it is no longer.
  void enabled_changed(bool enabled) noexcept;
  void encode_rpdo(std::uint16_t cw, std::int32_t target, CanFrame& out) const noexcept {
    if (default_layout_) {
      encode_rpdo1(config_.node, Rpdo1{cw, target}, out);
    } else {
      encode_layout_rpdo(config_.layout, config_.node, cw, target, out);
    }
  }
  // A TPDO of a layout other than the default: every value it carries.
  RemoteFrame take_layout_tpdo(const CanFrame& frame, std::uint8_t number, std::uint64_t now_us) noexcept;
  // Split feedback: TPDO `number` held, dropped, or completing its period.
  RemoteFrame take_period_tpdo(const CanFrame& frame, std::uint8_t number, std::uint64_t now_us) noexcept;
  // The load position, velocity actual and following error the TPDO carries.
  void take_extra_feedback(const CanFrame& frame, std::uint8_t number) noexcept;
  // The identifiers and lengths on_frame matches, from the layout in use.
  void apply_layout() noexcept;
  // read_mapping: one entry (or sub 0) read; false when start-up must stop.
  [[nodiscard]] bool take_mapping_entry(const StartupStep& s, std::uint32_t value) noexcept;
  // read_static, after the last mapping: the layout derived is one streaming can use.
  [[nodiscard]] bool check_derived_layout(std::uint64_t now_us) noexcept;
  // rpdo() in every state but ready.
  [[nodiscard]] bool enabling_rpdo(std::int32_t target_counts, CanFrame& out) noexcept;
  RemoteFrame on_heartbeat(std::uint8_t state_byte, std::uint64_t now_us, FrameSink& out) noexcept;
  // Someone else's NMT command that takes this drive out of operational (the master sends none
  // while streaming): acted on when seen, not a heartbeat period or a feedback timeout later.
  RemoteFrame on_nmt_command(const CanFrame& frame) noexcept;
  // The states in which the drive must stay NMT operational for what the master streams.
  [[nodiscard]] bool streaming_state() const noexcept;
  void leave_operational() noexcept;
  void next_step(std::uint64_t now_us, FrameSink& out) noexcept;
  void fail(std::uint64_t now_us) noexcept;
  void fail_step(const SdoResult& r, StartupError error, std::uint64_t now_us) noexcept;
  // The step's transfer (or its read-back) ended done: check or keep the value; true to go on.
  [[nodiscard]] bool take_step_result(const StartupStep& s, const SdoResult& r, std::uint64_t now_us) noexcept;
  void begin_enabling(std::uint64_t now_us) noexcept;

  RemoteDriveConfig config_;
  // The identifiers on_frame matches inline; an impossible one for an invalid node, so that
  // nothing matches.
  std::uint32_t tpdo1_id_{~std::uint32_t{0}};  // the TPDO with the statusword
  std::uint32_t tpdo2_id_{~std::uint32_t{0}};  // the next TPDO the layout uses
  std::uint8_t tpdo1_len_{0};
  std::uint8_t tpdo2_len_{0};
  std::uint8_t status_pdo_{1};
  std::uint8_t second_pdo_{2};
  bool default_layout_{true};                  // the inline codecs of default_mapping.hpp apply
  std::array<std::uint8_t, layout_pdo_count> tpdo_len_{};  // bytes each TPDO carries (0 = unused)
  // The TPDOs one period's values come in (bit n - 1 for TPDO n: feedback_tpdos). Split feedback
  // (feedback_split): those held of the current period, and the statusword and position actual
  // last taken, held until their period is complete.
  std::uint8_t period_tpdos_{0};
  bool split_{false};  // feedback_split (never set where split feedback is left out)
  std::uint8_t held_tpdos_{0};
  std::uint16_t held_statusword_{0};
  std::int32_t held_position_{0};
  // read_mapping's progress through a PDO (from start()): its COB-ID (map_sub_cob_id), then its
  // mapping object's sub 0 and entries.
  static constexpr std::uint8_t map_sub_cob_id = 0xFF;
  std::uint8_t map_sub_{0};
  std::uint8_t map_count_{0};
  std::uint8_t map_bytes_{0};
  std::uint16_t unfillable_index_{0};  // read_static: the first object an RPDO maps that the master cannot fill
  std::uint8_t unfillable_pdo_{0};     // ... and that RPDO (it matters only if it is the one used)
  std::uint32_t heartbeat_id_;
  RemoteDriveState state_{RemoteDriveState::idle};
  SdoClient sdo_;
  HeartbeatConsumer heartbeat_;
  EmcyConsumer emcy_;
  EnableSequence enable_{};
  Watchdog enable_timer_{};
  std::array<StartupStep, remote_drive_max_steps> steps_{};
  std::uint8_t step_count_{0};
  std::uint8_t step_{0};
  bool step_sent_{false};
  // The time of the tick whose received frame answered the last request: the next request goes out
  // from poll() in a later tick, so one tick never both decodes a response and encodes a request
  // (the Cortex-M0's tick budget, firmware/README.md); start-up takes one more period per step.
  std::uint64_t answered_us_{0};
  bool answered_{false};
  bool verifying_{false};    // a write step's read-back is running
  bool retried_{false};      // the current request has been sent again after a timeout
  bool plan_too_long_{false};
  // The configured layout cannot be streamed (check_layout, once at construction: the tick that
  // takes a boot-up runs start()); never set for PdoSetup::read_static, derived at start-up.
  bool layout_unusable_{false};
  RemoteDriveLimits limits_{};
  // The drive has been seen operational since start-up sent NMT start (a TPDO or an operational
  // heartbeat): from then on a pre-operational or stopped heartbeat is news, not a late echo.
  bool operational_seen_{false};
  RemoteFeedback feedback_{};
  RemoteDriveFailure failure_{};
  std::uint16_t events_{0};
};

}  // namespace settle::hal::canopen
