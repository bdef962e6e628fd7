// SPDX-License-Identifier: Apache-2.0
// The drive end of the bus as one I/O-free object: a CiA 402 slave with NMT, heartbeat,
// SDO server over its object dictionary, the default PDO mapping, the power state machine,
// EMCY and the drive-side safety rules. The simulated drive (sim) owns the plant behind it
// and feeds it frames and time; the same object can run on a microcontroller.
//
// Per SYNC: on_frame() returns DriveEvent::sync once the RPDO received before it has been
// applied; the application then moves its axis towards setpoint() for one period when
// following(), brings it to rest when stopping() (and says so with stop_complete()), and
// reports the result with publish(), which sends TPDO1/2.
//
// Drive-side safety rules (hal/README.md, "The drive"), each ending in a CiA 402 state and an EMCY:
// - Enabling never moves the axis: entering operation enabled latches 0x607A (and 0x60C1:1) to
//   the position actual; the target that came with the enabling controlword is not applied.
//   The position actual is the machine's: NMT reset node keeps it (the axis did not move), and
//   before the axis has reported one (set_feedback() or publish()) an enabled drive holds without
//   following until the first publish() tells it where the axis is, then latches that.
// - Step limit: a setpoint further than 0x607F x period from the previous one (the latched
//   position after enabling) is never applied: fault, EMCY 0x8400, the axis stays where it was.
//   Whatever wrote 0x607A (RPDO or SDO) is checked the same way, at the SYNC that would apply it.
// - Step window: within one period the axis moves at most that limit, so SYNC+RPDO pairs bunched
//   by a late bus or a late drive do not add their steps up; the setpoint is held back and
//   catches up at the next SYNCs (see step_window.hpp and axis_moves_one_period_per_sync).
// - Following error: |setpoint - position actual| over 0x6065 for longer than 0x6066 ms:
//   fault, EMCY 0x8611. On by default.
// - SYNC checks while the axis is driven: a counter (0x1019) that does not step by one, a
//   missing counter, or more SYNCs than one per 0x1006 period beyond the burst 0x2001 allows
//   (a SYNC that brings its own fresh RPDO is never refused for its rate: the master's period,
//   delivered late): the SYNC is refused (DriveEvent::sync_rejected: no period is run), EMCY
//   (0x8240 for a missing counter, 0x8100 otherwise) and the 0x6007 reaction.
// - An NMT command that takes the node out of operational (stop, enter pre-operational, reset
//   communication) while operation enabled: EMCY 0x8100, sent before the state changes, and the
//   0x6007 reaction; the power stage never stays enabled (0x6007 = 0: disable voltage; a quick
//   stop ends switch on disabled whatever 0x605A).
// - A SYNC of 2..8 bytes (a length 0x1019 does not ask for): EMCY 0x8240, refused.
// - While the axis is driven, SDO writes that change the step limit, the SYNC period or the checks
//   (0x607F, 0x1006, 0x60C2, 0x1019, 0x2001, 0x6065, 0x6066, 0x1016), and, unless
//   pre-operational, the PDO communication and mapping objects: abort 0x08000022. The master's heartbeat lost (0x1016): EMCY 0x8130 and the 0x6007 reaction.
// - SYNC loss, RPDO loss beyond 0x2001 periods: quick stop, EMCY 0x8100 / 0x8250.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/emcy.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/object_dictionary.hpp"
#include "settle/hal/canopen/pdo.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/canopen/step_window.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/hal/canopen/watchdog.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen {

// 0x6065 = this value switches the following-error check off (CiA 402).
inline constexpr std::uint32_t following_error_window_off = 0xFFFF'FFFF;
// Defaults of the limits (hal/eds/settle_drive.eds). 0x607F: 1e7 counts/s is 10 m/s at 1 count =
// 1 um, or 150 rev/s at 2^16 counts per revolution, five times the fastest move the demo
// streams; at 1 kHz it allows 10 000 counts per SYNC. 0x6065: 100 000 counts, above the lag of
// the simulator's 30 Hz servo model at that velocity (about 74 000 counts); 0x6066: 10 ms.
inline constexpr std::uint32_t default_max_profile_velocity = 10'000'000;
inline constexpr std::uint32_t default_following_error_window = 100'000;
inline constexpr std::uint16_t default_following_error_timeout_ms = 10;

// Byte 0 of the manufacturer-specific part of the drive's EMCY (frame bytes 3..7): which rule
// fired; bytes 1..4 carry a detail, little-endian (the refused step in counts, saturated to
// int32, for step_limit; the NMT command specifier in byte 1 for nmt_command).
namespace emcy_cause {
inline constexpr std::uint8_t none = 0;
inline constexpr std::uint8_t step_limit = 1;
inline constexpr std::uint8_t following_error = 2;
inline constexpr std::uint8_t sync_counter = 3;  // 0x1019: counter repeated, skipped or beyond overflow
inline constexpr std::uint8_t sync_length = 4;   // 0x1019 set, SYNC without counter
inline constexpr std::uint8_t sync_rate = 5;     // more SYNCs than the 0x1006 period allows
inline constexpr std::uint8_t nmt_command = 6;   // a third party's NMT command while enabled
inline constexpr std::uint8_t heartbeat = 7;     // the master's heartbeat (0x1016) lost
inline constexpr std::uint8_t sync_loss = 8;
inline constexpr std::uint8_t rpdo_loss = 9;
}  // namespace emcy_cause

// 0x1008..0x100A (const VISIBLE_STRINGs, served by segmented SDO upload): what the default drive
// says it is (DriveNodeConfig can name other text). hal/eds/settle_drive.eds carries the same.
inline constexpr char drive_device_name[] = "Settle simulated CiA 402 drive";
inline constexpr char drive_hardware_version[] = "simulated";
inline constexpr char drive_software_version[] = "Settle 0.1.0";

// The manufacturer-specific bytes of an EMCY (see emcy_cause).
using EmcyDetail = std::array<std::uint8_t, 5>;
[[nodiscard]] EmcyDetail emcy_detail(std::uint8_t cause, std::int64_t value = 0) noexcept;

// How many PDOs the drive can have, and how many objects each can map: the dictionary has a row
// per communication and mapping sub-index, so these are compile-time capacities. A firmware
// image short of RAM sets them lower (the micro:bit image: SETTLE_DRIVE_RPDOS=1,
// SETTLE_DRIVE_TPDOS=2, SETTLE_DRIVE_PDO_ENTRIES=2, which hold Settle's default mapping).
#ifndef SETTLE_DRIVE_RPDOS
#define SETTLE_DRIVE_RPDOS 4
#endif
#ifndef SETTLE_DRIVE_TPDOS
#define SETTLE_DRIVE_TPDOS 4
#endif
#ifndef SETTLE_DRIVE_PDO_ENTRIES
#define SETTLE_DRIVE_PDO_ENTRIES 8
#endif
inline constexpr std::size_t drive_rpdo_capacity = SETTLE_DRIVE_RPDOS;
inline constexpr std::size_t drive_tpdo_capacity = SETTLE_DRIVE_TPDOS;
inline constexpr std::size_t drive_pdo_entry_capacity = SETTLE_DRIVE_PDO_ENTRIES;
static_assert(drive_rpdo_capacity >= 1 && drive_rpdo_capacity <= 4, "CiA 301 predefined set: RPDO1..4");
static_assert(drive_tpdo_capacity >= 2 && drive_tpdo_capacity <= 4, "TPDO1..4; the default mapping uses two");
static_assert(drive_pdo_entry_capacity >= 2 && drive_pdo_entry_capacity <= pdo_max_entries,
              "the default mapping maps two objects per PDO");

// A PDO's COB-ID (comm sub 1) as CiA 301 writes it: bit 31 set = not valid (the PDO is off).
inline constexpr std::uint32_t pdo_cob_invalid = 0x8000'0000U;
inline constexpr std::uint32_t pdo_cob_no_rtr = 0x4000'0000U;  // TPDO: no remote request (ignored)
inline constexpr std::uint32_t pdo_cob_extended = 0x2000'0000U;  // 29-bit id: not supported
inline constexpr std::uint32_t pdo_cob_id_mask = 0x7FFU;

// The drive's default PDOs (Settle's default mapping, default_mapping.hpp): RPDO1 and TPDO1/2
// valid and synchronous, the others not valid and empty. In a DriveNodeConfig a COB-ID whose
// 11-bit id is 0 stands for the predefined connection set's id of the node (an EDS's
// $NODEID+0x200 and so on), so the same configuration serves any node id.
template <std::size_t N, std::size_t K>
[[nodiscard]] constexpr std::array<PdoMapping, N> drive_pdos(const std::array<PdoMapping, K>& valid) noexcept {
  static_assert(K <= N);
  std::array<PdoMapping, N> pdos{};
  for (std::size_t i = 0; i < N; ++i) {
    if (i < K) {
      pdos[i] = valid[i];
      pdos[i].cob_id = 0;  // the predefined id of the node
    } else {
      pdos[i].cob_id = pdo_cob_invalid;
    }
  }
  return pdos;
}
[[nodiscard]] constexpr std::array<PdoMapping, drive_rpdo_capacity> default_drive_rpdos() noexcept {
  return drive_pdos<drive_rpdo_capacity>(std::array{default_rpdo1_mapping(0)});
}
[[nodiscard]] constexpr std::array<PdoMapping, drive_tpdo_capacity> default_drive_tpdos() noexcept {
  return drive_pdos<drive_tpdo_capacity>(std::array{default_tpdo1_mapping(0), default_tpdo2_mapping(0)});
}
// The COB-ID the drive's PDO has for `node`: a configured id of 0 becomes the predefined one
// (RPDOn 0x200 + 0x100 (n-1) + node, TPDOn 0x180 + 0x100 (n-1) + node); bits 29..31 are kept.
[[nodiscard]] constexpr std::uint32_t drive_pdo_cob_id(std::uint32_t configured, bool receive, std::size_t number,
                                                       NodeId node) noexcept {
  if ((configured & pdo_cob_id_mask) != 0) {
    return configured;
  }
  const std::uint32_t base = (receive ? cob::rpdo1 : cob::tpdo1) + 0x100U * static_cast<std::uint32_t>(number - 1);
  return configured | cob_id(static_cast<std::uint16_t>(base), node);
}

struct DriveNodeConfig {
  NodeId node{1};
  std::uint16_t heartbeat_period_ms{100};                 // 0x1017
  std::uint32_t sync_period_us{default_sync_period_us};   // 0x1006
  std::uint8_t sync_counter_overflow{0};                  // 0x1019: 0 = SYNC counter not checked
  std::uint8_t communication_loss_periods{3};             // 0x2001: SYNC/RPDO periods tolerated
  std::int16_t quick_stop_option{2};                      // 0x605A: quick-stop ramp, then disabled
  std::int16_t abort_connection_option{1};                // 0x6007: fault
  std::uint32_t following_error_window{default_following_error_window};  // 0x6065, counts
  std::uint16_t following_error_timeout_ms{default_following_error_timeout_ms};  // 0x6066
  std::uint32_t max_profile_velocity{default_max_profile_velocity};       // 0x607F, counts/s
  std::int32_t position_limit_min{std::numeric_limits<std::int32_t>::min()};  // 0x607D:1
  std::int32_t position_limit_max{std::numeric_limits<std::int32_t>::max()};  // 0x607D:2
  std::uint32_t vendor_id{0};                             // 0x1018
  std::uint32_t product_code{0x5E77'1E00};
  std::uint32_t revision{1};
  std::uint32_t serial{0};
  std::uint32_t device_type{cia402_device_type};          // 0x1000
  // 0x1008..0x100A: NUL-terminated text the drive serves as it is, not copied: it must outlive
  // the DriveNode (string literals do). nullptr serves an empty string.
  const char* device_name{drive_device_name};
  const char* hardware_version{drive_hardware_version};
  const char* software_version{drive_software_version};
  // Optional objects: absent ones are not in the dictionary (SDO abort 0x06020000).
  bool has_interpolation_period{true};       // 0x60C2 (absent: the step limit uses 0x1006 alone)
  bool has_following_error_actual{true};     // 0x60F4
  bool has_velocity_actual{true};            // 0x606C (absent: the drive reports no velocity)
  bool has_load_position{true};              // 0x2000, the load encoder (absent: the drive reports no load)
  // Where the load encoder is: 0x2000:0 on Settle's drive; another vendor's manufacturer object
  // (0x2000 or 0x2002..0x5FFF, any sub), where its description puts it. Any other index keeps 0x2000:0.
  std::uint16_t load_position_index{obj::load_position_actual};
  std::uint8_t load_position_sub{0};
  bool has_communication_cycle_period{true};  // 0x1006 (absent: the SYNC checks run as with 0x1006 = 0)
  // Dynamic PDO mapping (CiA 301): the PDOs' COB-IDs, transmission types and mapping objects are
  // writable, in the order CiA 301 prescribes. Otherwise they are read-only (abort 0x06010002)
  // and the mapping below is static.
  bool pdo_mapping_writable{false};
  // The PDOs in the dictionary: RPDO1..rpdo_count, TPDO1..tpdo_count (at most the capacities).
  std::uint8_t rpdo_count{1};
  std::uint8_t tpdo_count{2};
  // Their defaults: COB-ID (see default_drive_rpdos), transmission type and mapping.
  std::array<PdoMapping, drive_rpdo_capacity> rpdos{default_drive_rpdos()};
  std::array<PdoMapping, drive_tpdo_capacity> tpdos{default_drive_tpdos()};
  // A static mapping object's sub-indices 1..n: its mapped entries, or more where a description
  // lists entries past its count (unused: served read-only with the values `entries` holds there).
  std::array<std::uint8_t, drive_rpdo_capacity> rpdo_mapping_rows{};
  std::array<std::uint8_t, drive_tpdo_capacity> tpdo_mapping_rows{};
  // The clock the step window measures periods in (step_window.hpp): when the axis moves. A
  // drive that moves its axis as it processes a SYNC (firmware) uses the time it processes it.
  // A simulated axis that advances one period per SYNC (sim's PlantNode) lives in SYNC time:
  // each SYNC is one period after the previous however the bus bunched them (a replay that
  // catches up sends dozens at once), so its simulated axis never moves faster than the step
  // limit allows and the window never holds it back.
  bool axis_moves_one_period_per_sync{false};
};

// The dictionary's variables, in two groups because NMT resets them in two groups:
// "reset communication" restores comm, "reset node" restores both. The application reads
// them; writes go through the bus.
struct DriveCommObjects {  // 0x1000..0x1FFF, CiA 301
  std::uint32_t device_type{cia402_device_type};
  std::uint8_t error_register{0};
  std::uint32_t cob_id_sync{0x80};
  std::uint32_t cycle_period_us{default_sync_period_us};
  std::uint32_t cob_id_emcy{0};
  std::uint16_t inhibit_time_emcy{0};  // 100 µs units
  std::uint8_t consumer_heartbeat_count{1};
  std::uint32_t consumer_heartbeat{0};  // (node << 16) | timeout ms; 0 = off
  std::uint16_t producer_heartbeat_ms{0};
  std::uint8_t identity_count{4};
  std::uint32_t vendor_id{0};
  std::uint32_t product_code{0};
  std::uint32_t revision{0};
  std::uint32_t serial{0};
  std::uint8_t sync_counter_overflow{0};
  std::uint8_t sdo_parameter_count{2};
  std::uint32_t sdo_cob_rx{0};
  std::uint32_t sdo_cob_tx{0};
  struct PdoComm {  // the word first: 8 bytes, not 12 (the micro:bit image counts them)
    std::uint32_t cob_id{0};
    std::uint8_t count{2};
    std::uint8_t transmission_type{pdo_transmission::synchronous};
  };
  struct PdoMap {
    std::uint8_t count{0};
    std::array<std::uint32_t, drive_pdo_entry_capacity> entries{};  // PdoMappingEntry::raw()
  };
  std::array<PdoComm, drive_rpdo_capacity> rpdo_comm{};
  std::array<PdoMap, drive_rpdo_capacity> rpdo_map{};
  std::array<PdoComm, drive_tpdo_capacity> tpdo_comm{};
  std::array<PdoMap, drive_tpdo_capacity> tpdo_map{};
};

struct DriveAppObjects {  // 0x2000.. Settle, 0x6000.. CiA 402
  std::int32_t load_position{0};
  std::uint8_t communication_loss_periods{3};
  std::int16_t abort_connection_option{1};
  std::uint16_t error_code{0};
  std::uint16_t controlword{0};
  std::uint16_t statusword{0};
  std::int16_t quick_stop_option{2};
  std::int8_t mode{static_cast<std::int8_t>(OperationMode::cyclic_synchronous_position)};
  std::int8_t mode_display{static_cast<std::int8_t>(OperationMode::cyclic_synchronous_position)};
  std::int32_t position_actual{0};
  std::uint32_t following_error_window{default_following_error_window};
  std::uint16_t following_error_timeout_ms{default_following_error_timeout_ms};
  std::int32_t velocity_actual{0};
  std::int32_t target_position{0};
  std::int32_t following_error_actual{0};  // 0x60F4: setpoint - position actual, counts
  std::uint8_t position_limit_count{2};
  std::int32_t position_limit_min{0};
  std::int32_t position_limit_max{0};
  std::uint32_t max_profile_velocity{default_max_profile_velocity};
  std::uint8_t ip_data_count{1};
  std::int32_t ip_data{0};
  std::uint8_t ip_period_count{2};
  std::uint8_t ip_period_value{1};
  std::int8_t ip_period_index{-3};
  std::uint32_t supported_modes{0};
};

struct DriveObjects {
  DriveCommObjects comm{};
  DriveAppObjects app{};
};

enum class DriveEvent : std::uint8_t {
  none,     // not for this node (or ignored in the current NMT state)
  handled,  // taken (NMT, SDO, RPDO latched, heartbeat of the master)
  sync,     // a SYNC was processed: run the axis for one period, then publish()
  sync_rejected,  // a SYNC failed the counter or rate check: run NO period (see counters().sync_errors)
  reset,    // NMT reset node: objects are back to their defaults (0x6064, 0x606C, 0x2000 excepted:
            // they are the machine's, which stays where it is), the power state is switch on disabled
};

struct DriveFeedback {
  std::int32_t position_actual{0};  // counts
  std::int32_t velocity_actual{0};  // counts/s
  std::int32_t load_position{0};    // counts
};

struct DriveCounters {
  std::uint64_t syncs{0};
  std::uint64_t rpdos_applied{0};
  std::uint64_t rpdos_overwritten{0};  // a second RPDO before the SYNC replaced the first
  std::uint64_t rpdos_rejected{0};     // wrong length or value out of range
  std::uint64_t rpdos_missing{0};      // SYNCs without a fresh RPDO while enabled
  std::uint64_t sync_gaps{0};          // SYNCs whose counter skipped (0x1019 set): SYNCs lost on the way
  std::uint64_t sync_errors{0};        // SYNCs that failed the counter or rate check (refused while driven)
  std::uint64_t steps_refused{0};      // setpoints over the step limit (0x607F x period)
  std::uint64_t steps_bounded{0};      // setpoints held back by the step window (SYNCs bunched in one period)
  std::uint64_t emcy_sent{0};
};

class DriveNode {
 public:
  explicit DriveNode(const DriveNodeConfig& config) noexcept;
  DriveNode(const DriveNode&) = delete;
  DriveNode& operator=(const DriveNode&) = delete;

  // Power on: boot-up message, then pre-operational with heartbeats every producer period.
  void start(std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] DriveEvent on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept;
  // Heartbeat production and the time-based rules (master heartbeat, SYNC loss, EMCY inhibit).
  void poll(std::uint64_t now_us, FrameSink& out) noexcept;

  // After a sync event: the axis state at the end of the period. Checks the following error
  // and sends TPDO1 and TPDO2 when operational.
  void publish(const DriveFeedback& feedback, std::uint64_t now_us, FrameSink& out) noexcept;
  // The axis state outside a SYNC: where the machine stands at power-on, or after it was moved
  // by hand while disabled. Updates 0x6064/0x606C/0x2000 (and, while not enabled, the position
  // the drive holds), so that enabling before the first SYNC latches the machine's position.
  void set_feedback(const DriveFeedback& feedback) noexcept;
  // A fault the application detected (an error code from CiA 402 / 301): fault reaction.
  void raise_fault(std::uint16_t error_code, std::uint64_t now_us, FrameSink& out) noexcept;
  // The axis has come to rest after a quick stop or a fault reaction.
  void stop_complete() noexcept;

  // While following(): where the axis must be at the end of this period (the target received
  // before this SYNC, clamped to the software limits). Otherwise the drive commands nothing and
  // setpoint() is the last position actual, so that enabling starts from where the axis is.
  [[nodiscard]] std::int32_t setpoint() const noexcept { return setpoint_; }
  // Operation enabled in CSP (or IP with bit 4 of the controlword set).
  [[nodiscard]] bool following() const noexcept;
  [[nodiscard]] bool stopping() const noexcept { return power_.stopping(); }
  [[nodiscard]] Cia402State state() const noexcept { return power_.state(); }
  [[nodiscard]] NmtState nmt_state() const noexcept { return nmt_.state(); }
  [[nodiscard]] OperationMode mode() const noexcept { return static_cast<OperationMode>(objects_.app.mode_display); }
  [[nodiscard]] std::uint32_t interpolation_period_us() const noexcept;
  // The largest setpoint step the drive applies in one SYNC period: 0x607F (counts/s) times the
  // shorter of 0x1006 and 0x60C2 (0x1006 = 0 counts as absent), rounded up. 64-bit: no overflow.
  [[nodiscard]] std::int64_t step_limit_counts() const noexcept;
  // The period step_limit_counts() is for: the shorter of 0x1006 and 0x60C2 (0x1006 = 0: 0x60C2).
  [[nodiscard]] std::uint32_t step_period_us() const noexcept;
  [[nodiscard]] const DriveObjects& objects() const noexcept { return objects_; }
  [[nodiscard]] ObjectDictionary& dictionary() noexcept { return od_; }
  [[nodiscard]] const DriveCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] NodeId node() const noexcept { return config_.node; }
  // The first default mapping of a valid PDO that cannot be bound (an object missing, not
  // mappable or not of the PDO's direction, more than 64 bits): none for a usable configuration.
  // Such a PDO is neither sent nor applied; a configuration reader reports this as its error.
  [[nodiscard]] SdoAbort default_mapping_error() noexcept;
  // Whether the PDO (0-based: 0 = RPDO1 / TPDO1) is valid (COB-ID bit 31 clear) and bound.
  [[nodiscard]] bool rpdo_active(std::size_t i) const noexcept;
  [[nodiscard]] bool tpdo_active(std::size_t i) const noexcept;

 private:
  // Rows of the dictionary at most: the fixed objects, the optional ones, and per PDO its
  // communication sub 0..2 and mapping sub 0..capacity.
  static constexpr std::size_t entry_capacity =
      46 + (drive_rpdo_capacity + drive_tpdo_capacity) * (4 + drive_pdo_entry_capacity);

  void restore(bool application) noexcept;
  void apply_configuration(std::uint16_t index) noexcept;  // 0: every configuration object
  void apply_written_controlword(std::uint64_t now_us, FrameSink& out) noexcept;
  void bind_pdos() noexcept;
  [[nodiscard]] std::span<const OdEntry> make_entries() noexcept;
  [[nodiscard]] SdoAbort check_pdo_write(const OdEntry& entry, std::int64_t value) noexcept;
  [[nodiscard]] bool fresh_target() const noexcept;
  [[nodiscard]] DriveEvent on_sync(const SyncMessage& sync, std::uint64_t now_us, std::uint64_t received_us,
                                   FrameSink& out) noexcept;
  void on_nmt(const NmtMessage& message, std::uint64_t now_us, FrameSink& out) noexcept;
  void apply_setpoint(std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] DriveEvent on_sync_length_error(std::uint8_t length, std::uint64_t now_us, FrameSink& out) noexcept;
  void latch_target() noexcept;
  // step_limit_counts() for a step period already known (one SYNC computes it once).
  [[nodiscard]] std::int64_t step_limit_counts(std::uint32_t period_us) const noexcept;
  void fault_with(std::uint16_t error_code, const EmcyDetail& detail, std::uint64_t now_us, FrameSink& out) noexcept;
  void connection_lost(std::uint16_t error_code, const EmcyDetail& detail, std::uint64_t now_us,
                       FrameSink& out) noexcept;
  void quick_stop_with_emcy(std::uint16_t error_code, const EmcyDetail& detail, std::uint64_t now_us,
                            FrameSink& out) noexcept;
  void signal_error(std::uint16_t error_code, std::uint8_t register_bits, const EmcyDetail& detail,
                    std::uint64_t now_us, FrameSink& out) noexcept;
  void clear_errors(std::uint64_t now_us, FrameSink& out) noexcept;
  void update_statusword() noexcept;
  // The power stage drives the axis: operation enabled, or bringing it to rest.
  [[nodiscard]] bool driving() const noexcept { return power_.enabled() || power_.stopping(); }

  [[nodiscard]] static OdBytes constant_text(const char* text) noexcept;
  static SdoAbort check_write(void* self, const OdEntry& entry, std::int64_t value) noexcept;
  static void on_written(void* self, const OdEntry& entry) noexcept;

  DriveNodeConfig config_;
  DriveObjects objects_{};
  // The configured strings, served in place (constant objects: never written through these).
  OdBytes device_name_{constant_text(config_.device_name)};
  OdBytes hardware_version_{constant_text(config_.hardware_version)};
  OdBytes software_version_{constant_text(config_.software_version)};
  std::array<OdEntry, entry_capacity> entries_{};
  ObjectDictionary od_;
  NmtSlave nmt_;
  SdoServer sdo_;
  HeartbeatProducer heartbeat_;
  HeartbeatConsumer master_heartbeat_;
  SyncConsumer sync_;
  EmcyProducer emcy_;
  PowerStateMachine power_{};
  std::array<PdoBinding, drive_rpdo_capacity> rpdo_{};
  std::array<PdoBinding, drive_tpdo_capacity> tpdo_{};
  std::array<std::optional<CanFrame>, drive_rpdo_capacity> pending_rpdo_{};
  Watchdog following_error_timer_{};
  DriveCounters counters_{};
  std::int32_t setpoint_{0};
  std::int32_t accepted_target_{0};     // the last target the step limit accepted
  std::uint64_t period_time_us_{0};  // when the axis moves for the SYNC being processed
  StepWindow step_window_{};
  std::uint32_t rpdo_missing_run_{0};
  bool following_error_{false};
  bool limit_active_{false};
  bool controlword_written_{false};
  bool position_known_{false};  // the axis has reported its position (set_feedback or publish)
  bool latch_pending_{false};   // enabled before it had: hold, latch at the first publish()
  bool disable_after_stop_{false};  // a quick stop an NMT command caused ends switch on disabled
  bool sync_error_reported_{false};  // one EMCY per episode: cleared with the errors
  bool pdo_length_error_{false};       // an RPDO had the wrong length: a later right one clears it
  bool length_ok_since_error_{false};  // the RPDO latched since then has the mapped length
};

}  // namespace settle::hal::canopen
