// The master's view of one CiA 402 drive, I/O-free: start-up (NMT, SDO configuration of the
// mode and periods, NMT start), the enable sequence driven by the drive's statusword, the
// per-tick CSP RPDO, and supervision of its heartbeat, EMCY and feedback. The servo loop owns
// one per axis, feeds it every received frame and asks it each tick for the RPDO to send.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/emcy.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/canopen/watchdog.hpp"
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

struct RemoteDriveConfig {
  NodeId node{1};
  OperationMode mode{OperationMode::cyclic_synchronous_position};
  std::uint32_t sync_period_us{default_sync_period_us};
  std::uint32_t sdo_timeout_us{100'000};
  std::uint32_t enable_timeout_us{1'000'000};   // from NMT start to operation enabled
  std::uint16_t heartbeat_timeout_ms{0};        // watch the drive's heartbeat; 0 = do not
  NodeId master_node{0};                        // non-zero: the drive watches this heartbeat (0x1016)
  std::uint16_t master_heartbeat_timeout_ms{0};
  std::uint8_t communication_loss_periods{0};   // non-zero: written to the drive's 0x2001
};

enum class RemoteDriveState : std::uint8_t {
  idle,         // start() not called
  configuring,  // NMT pre-operational, SDO configuration, NMT start
  enabling,     // enable sequence over RPDO1/TPDO1: the loop must tick (RPDO + SYNC)
  ready,        // operation enabled in the configured mode: setpoints may be streamed
  stopped,      // the drive left operation enabled (fault, quick stop): call recover()
  lost,         // its heartbeat timed out
  not_operational,  // its heartbeat said pre-operational or stopped after it had been operational
                    // (someone else's NMT command): no process data; start() runs start-up again
  failed,       // configuration refused or timed out, or enabling timed out: see failure()
};

[[nodiscard]] const char* to_string(RemoteDriveState state) noexcept;

// Why start-up failed.
struct RemoteDriveFailure {
  std::uint16_t index{0};
  std::uint8_t sub{0};
  SdoClientStatus status{SdoClientStatus::idle};
  SdoAbort abort{SdoAbort::none};
  bool wrong_value{false};    // read back a value other than the one configured
  bool enable_timeout{false};
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
  heartbeat,  // this drive's heartbeat or boot-up
  emcy,
  tpdo1,      // statusword + position actual: feedback() updated
  tpdo2,      // load position + velocity actual: feedback() updated
  sdo,        // an SDO response (used while configuring)
};

struct RemoteFeedback {
  std::uint16_t statusword{0};
  std::int32_t position_actual{0};
  std::int32_t load_position{0};
  std::int32_t velocity_actual{0};
  std::uint64_t tpdo1_received{0};
  std::uint64_t tpdo2_received{0};
  std::uint64_t tpdo1_time_us{0};  // when the latest TPDO1 was taken (the caller's time)
};

class RemoteDrive {
 public:
  explicit RemoteDrive(const RemoteDriveConfig& config) noexcept;

  // Begins (or restarts) start-up from the configuration step.
  void start(std::uint64_t now_us, FrameSink& out) noexcept;
  // After stopped/failed: runs the enable sequence again (the configuration is kept).
  void recover(std::uint64_t now_us) noexcept;

  // Every received frame goes here; frames of other nodes are ignored. The drive's process data
  // (two frames every period) and its heartbeat are recognised inline by exact identifier and
  // length and decoded in place; everything else is routed by its function code, out of line, so
  // a frame costs one decoder, not a try of each.
  RemoteFrame on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept {
    if (frame.flags == 0) {  // a classic data frame with a standard identifier
      if (frame.id == tpdo1_id_ && frame.len == tpdo1_len) {
        take_tpdo1(tpdo1_fields(frame), now_us);
        return RemoteFrame::tpdo1;
      }
      if (frame.id == tpdo2_id_ && frame.len == tpdo2_len) {
        const Tpdo2 p = tpdo2_fields(frame);
        feedback_.load_position = p.load_position;
        feedback_.velocity_actual = p.velocity_actual;
        ++feedback_.tpdo2_received;
        return RemoteFrame::tpdo2;
      }
      if (frame.id == heartbeat_id_ && frame.len == 1) return on_heartbeat(frame.data[0], now_us, out);
    }
    return on_service_frame(frame, now_us, out);
  }
  // Timeouts (SDO, heartbeat, enabling) and the next configuration step.
  void poll(std::uint64_t now_us, FrameSink& out) noexcept;

  // The RPDO1 for this tick, written over `out`; false (and `out` untouched) when the drive must
  // not be sent process data. Enabling -> the enable sequence's controlword with the drive's own
  // position as target (so enabling never moves the axis); ready -> enable operation with the
  // given target.
  [[nodiscard]] bool rpdo(std::int32_t target_counts, CanFrame& out) noexcept {
    if (state_ != RemoteDriveState::ready) return enabling_rpdo(out);
    std::uint16_t cw = controlword::enable_operation;
    if (config_.mode == OperationMode::interpolated_position) cw |= controlword::enable_ip_mode;
    encode_rpdo1(config_.node, Rpdo1{cw, target_counts}, out);
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

 private:
  struct SdoStep {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint32_t value;
    std::uint8_t size;
    bool upload;             // read back and compare (value & mask)
    std::uint32_t mask;
  };
  static constexpr std::size_t max_steps = 8;

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
  // rpdo() in every state but ready.
  [[nodiscard]] bool enabling_rpdo(CanFrame& out) noexcept;
  RemoteFrame on_heartbeat(std::uint8_t state_byte, std::uint64_t now_us, FrameSink& out) noexcept;
  RemoteFrame on_service_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept;
  void plan_configuration() noexcept;
  void next_step(std::uint64_t now_us, FrameSink& out) noexcept;
  void fail(std::uint64_t now_us) noexcept;
  void begin_enabling(std::uint64_t now_us) noexcept;

  RemoteDriveConfig config_;
  // The identifiers on_frame matches inline; an impossible one for an invalid node, so that
  // nothing matches.
  std::uint32_t tpdo1_id_;
  std::uint32_t tpdo2_id_;
  std::uint32_t heartbeat_id_;
  RemoteDriveState state_{RemoteDriveState::idle};
  SdoClient sdo_;
  HeartbeatConsumer heartbeat_;
  EmcyConsumer emcy_;
  EnableSequence enable_{};
  Watchdog enable_timer_{};
  std::array<SdoStep, max_steps> steps_{};
  std::size_t step_count_{0};
  std::size_t step_{0};
  bool step_sent_{false};
  // The drive has been seen operational since start-up sent NMT start (a TPDO or an operational
  // heartbeat): from then on a pre-operational or stopped heartbeat is news, not a late echo.
  bool operational_seen_{false};
  RemoteFeedback feedback_{};
  RemoteDriveFailure failure_{};
  std::uint16_t events_{0};
};

}  // namespace settle::hal::canopen
