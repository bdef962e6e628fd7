// SPDX-License-Identifier: Apache-2.0
// CiA 402 drive profile: object indices, controlword commands, statusword states with the
// standard masks, and the drive-side power state machine that turns one into the other.
// Both ends use it: the drive runs the machine, the master decodes the statusword.
#pragma once

#include <cstdint>

#include "settle/hal/enum_text.hpp"

namespace settle::hal::canopen {

// Objects of the drive profile (and Settle's manufacturer-specific ones) by index.
namespace obj {
inline constexpr std::uint16_t device_type = 0x1000;
inline constexpr std::uint16_t error_register = 0x1001;
inline constexpr std::uint16_t cob_id_sync = 0x1005;
inline constexpr std::uint16_t communication_cycle_period = 0x1006;  // µs
inline constexpr std::uint16_t device_name = 0x1008;       // VISIBLE_STRING
inline constexpr std::uint16_t hardware_version = 0x1009;  // VISIBLE_STRING
inline constexpr std::uint16_t software_version = 0x100A;  // VISIBLE_STRING
inline constexpr std::uint16_t cob_id_emcy = 0x1014;
inline constexpr std::uint16_t inhibit_time_emcy = 0x1015;  // 100 µs units
inline constexpr std::uint16_t consumer_heartbeat_time = 0x1016;
inline constexpr std::uint16_t producer_heartbeat_time = 0x1017;  // ms
inline constexpr std::uint16_t identity = 0x1018;
inline constexpr std::uint16_t sync_counter_overflow = 0x1019;
inline constexpr std::uint16_t sdo_server_parameter = 0x1200;
inline constexpr std::uint16_t rpdo1_communication = 0x1400;
inline constexpr std::uint16_t rpdo1_mapping = 0x1600;
inline constexpr std::uint16_t tpdo1_communication = 0x1800;
inline constexpr std::uint16_t tpdo2_communication = 0x1801;
inline constexpr std::uint16_t tpdo1_mapping = 0x1A00;
inline constexpr std::uint16_t tpdo2_mapping = 0x1A01;
// Settle manufacturer-specific objects.
inline constexpr std::uint16_t load_position_actual = 0x2000;  // i32, counts: the simulator's load/tip
inline constexpr std::uint16_t communication_loss_periods = 0x2001;  // u8: SYNC/RPDO periods tolerated
// The last index of the manufacturer-specific area (CiA 301: 0x2000..0x5FFF).
inline constexpr std::uint16_t manufacturer_index_last = 0x5FFF;
// CiA 402.
inline constexpr std::uint16_t abort_connection_option = 0x6007;
inline constexpr std::uint16_t error_code = 0x603F;
inline constexpr std::uint16_t controlword = 0x6040;
inline constexpr std::uint16_t statusword = 0x6041;
inline constexpr std::uint16_t quick_stop_option = 0x605A;
inline constexpr std::uint16_t modes_of_operation = 0x6060;
inline constexpr std::uint16_t modes_of_operation_display = 0x6061;
inline constexpr std::uint16_t position_actual = 0x6064;
inline constexpr std::uint16_t following_error_window = 0x6065;
inline constexpr std::uint16_t following_error_timeout = 0x6066;  // ms
inline constexpr std::uint16_t velocity_actual = 0x606C;
inline constexpr std::uint16_t target_position = 0x607A;
inline constexpr std::uint16_t software_position_limit = 0x607D;
inline constexpr std::uint16_t max_profile_velocity = 0x607F;  // counts/s
inline constexpr std::uint16_t interpolation_data_record = 0x60C1;
inline constexpr std::uint16_t interpolation_time_period = 0x60C2;
inline constexpr std::uint16_t following_error_actual = 0x60F4;  // i32, counts
inline constexpr std::uint16_t supported_drive_modes = 0x6502;
}  // namespace obj

// 0x1000 for a CiA 402 servo drive: profile 402 (0x0192), type "servo drive" (0x0002).
inline constexpr std::uint32_t cia402_device_type = 0x0002'0192;

enum class OperationMode : std::int8_t {
  none = 0,
  profile_position = 1,
  interpolated_position = 7,
  cyclic_synchronous_position = 8,
};

// Controlword values a master sends (bits 0-3 and 7).
namespace controlword {
inline constexpr std::uint16_t shutdown = 0x0006;
inline constexpr std::uint16_t switch_on = 0x0007;
inline constexpr std::uint16_t disable_operation = 0x0007;
inline constexpr std::uint16_t enable_operation = 0x000F;
inline constexpr std::uint16_t disable_voltage = 0x0000;
inline constexpr std::uint16_t quick_stop = 0x0002;
inline constexpr std::uint16_t fault_reset = 0x0080;  // acts on the rising edge of bit 7
inline constexpr std::uint16_t enable_ip_mode = 0x0010;  // interpolated position: bit 4
}  // namespace controlword

// Statusword bits besides the state bits.
namespace statusword {
inline constexpr std::uint16_t voltage_enabled = 0x0010;
inline constexpr std::uint16_t quick_stop = 0x0020;  // set while NOT quick-stopping
inline constexpr std::uint16_t warning = 0x0080;
inline constexpr std::uint16_t remote = 0x0200;
inline constexpr std::uint16_t target_reached = 0x0400;
inline constexpr std::uint16_t internal_limit = 0x0800;
inline constexpr std::uint16_t mode_specific_12 = 0x1000;  // CSP: following the target; IP: ip mode active
inline constexpr std::uint16_t following_error = 0x2000;   // CSP/PP: following error
}  // namespace statusword

// Made from one list (enum_text.hpp): the enumerator and the name to_string() gives.
#define SETTLE_HAL_CIA402_STATES(X) \
  X(not_ready_to_switch_on, "not ready to switch on") \
  X(switch_on_disabled, "switch on disabled") \
  X(ready_to_switch_on, "ready to switch on") \
  X(switched_on, "switched on") \
  X(operation_enabled, "operation enabled") \
  X(quick_stop_active, "quick stop active") \
  X(fault_reaction_active, "fault reaction active") \
  X(fault, "fault")
enum class Cia402State : std::uint8_t { SETTLE_HAL_CIA402_STATES(SETTLE_ENUM_ENUMERATOR) };

// The state a statusword reports, by the standard masks (0x4F / 0x6F).
[[nodiscard]] Cia402State state_from_statusword(std::uint16_t sw) noexcept;
// state_from_statusword(sw) == operation_enabled, as one mask and compare (bits 0-3, 5, 6 =
// 0b0100111 with bit 6 clear): the test a master makes on every TPDO.
[[nodiscard]] constexpr bool is_operation_enabled(std::uint16_t sw) noexcept { return (sw & 0x006FU) == 0x0027U; }
// The state bits (0-3, 5, 6) a drive puts in its statusword for a state.
[[nodiscard]] std::uint16_t statusword_state_bits(Cia402State state) noexcept;
[[nodiscard]] const char* to_string(Cia402State state) noexcept;

enum class Cia402Command : std::uint8_t {
  none,  // bits that match no command (a drive keeps its state)
  shutdown,
  switch_on,
  enable_operation,  // "switch on + enable operation" from ready to switch on, "enable operation" otherwise
  disable_voltage,
  quick_stop,
  fault_reset,
};

// The command a controlword carries; a fault reset needs bit 7 to rise since the previous one.
[[nodiscard]] Cia402Command command_from_controlword(std::uint16_t cw, std::uint16_t previous_cw) noexcept;

// Quick-stop option code (0x605A): what the drive does after a quick stop.
[[nodiscard]] constexpr bool quick_stop_stays_active(std::int16_t option) noexcept { return option >= 5 && option <= 8; }

// Abort-connection option code (0x6007): what the drive does when it loses its master.
enum class AbortConnectionAction : std::int16_t { none = 0, fault = 1, disable_voltage = 2, quick_stop = 3 };

// The drive-side power state machine (CiA 402 figure "state machine"). It knows nothing of
// motion: when a quick stop or fault reaction needs the axis to decelerate, the drive
// application does that and then calls stop_complete().
class PowerStateMachine {
 public:
  // Transitions 0 and 1: power-on initialisation is instantaneous here.
  void reset() noexcept;

  // Applies a controlword. Returns true when the state changed.
  [[nodiscard]] bool on_controlword(std::uint16_t cw) noexcept;
  // Applies a command the drive gives itself (abort-connection option, 0x6007).
  [[nodiscard]] bool apply(Cia402Command command) noexcept;
  // Transition 13: a fault occurred (from any state but fault itself).
  [[nodiscard]] bool fault() noexcept;
  // The drive itself requests a quick stop (transition 11, only from operation enabled).
  [[nodiscard]] bool quick_stop() noexcept;
  // The axis has stopped: fault reaction -> fault (14), or quick stop -> switch on disabled
  // (12) for option codes that do not stay in quick stop active.
  [[nodiscard]] bool stop_complete() noexcept;

  void set_quick_stop_option(std::int16_t option) noexcept { quick_stop_option_ = option; }
  // The next controlword is taken as following a 0 (its bit 7, if set, is a rising edge): NMT
  // start, when the controlwords before the node stopped say nothing of the master's intent.
  void forget_controlword() noexcept { previous_cw_ = 0; }
  [[nodiscard]] Cia402State state() const noexcept { return state_; }
  // Operation enabled: the drive follows setpoints.
  [[nodiscard]] bool enabled() const noexcept { return state_ == Cia402State::operation_enabled; }
  // Quick stop or fault reaction: the application must bring the axis to rest.
  [[nodiscard]] bool stopping() const noexcept {
    return state_ == Cia402State::quick_stop_active || state_ == Cia402State::fault_reaction_active;
  }
  [[nodiscard]] std::uint16_t statusword_bits() const noexcept { return statusword_state_bits(state_); }

 private:
  Cia402State state_{Cia402State::switch_on_disabled};
  std::uint16_t previous_cw_{0};
  std::int16_t quick_stop_option_{2};
};

}  // namespace settle::hal::canopen
