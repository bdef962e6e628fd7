// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/cia402.hpp"

namespace settle::hal::canopen {

Cia402State state_from_statusword(std::uint16_t sw) noexcept {
  switch (sw & 0x004FU) {
    case 0x0000: return Cia402State::not_ready_to_switch_on;
    case 0x0040: return Cia402State::switch_on_disabled;
    case 0x000F: return Cia402State::fault_reaction_active;
    case 0x0008: return Cia402State::fault;
    default: break;
  }
  switch (sw & 0x006FU) {
    case 0x0021: return Cia402State::ready_to_switch_on;
    case 0x0023: return Cia402State::switched_on;
    case 0x0027: return Cia402State::operation_enabled;
    case 0x0007: return Cia402State::quick_stop_active;
    default: break;
  }
  // Bit patterns the profile does not define: treat like "not ready", never as enabled.
  return Cia402State::not_ready_to_switch_on;
}

std::uint16_t statusword_state_bits(Cia402State state) noexcept {
  switch (state) {
    case Cia402State::not_ready_to_switch_on: return 0x0000;
    case Cia402State::switch_on_disabled: return 0x0040;
    case Cia402State::ready_to_switch_on: return 0x0021;
    case Cia402State::switched_on: return 0x0023 | statusword::voltage_enabled;
    case Cia402State::operation_enabled: return 0x0027 | statusword::voltage_enabled;
    case Cia402State::quick_stop_active: return 0x0007 | statusword::voltage_enabled;
    case Cia402State::fault_reaction_active: return 0x000F;
    case Cia402State::fault: return 0x0008;
  }
  return 0;
}

namespace {
constexpr const char* kStateNames[] = {SETTLE_HAL_CIA402_STATES(SETTLE_ENUM_TEXT)};
}  // namespace

const char* to_string(Cia402State state) noexcept { return enum_text(kStateNames, state, "?"); }

Cia402Command command_from_controlword(std::uint16_t cw, std::uint16_t previous_cw) noexcept {
  if ((cw & 0x0080U) != 0) {
    // While bit 7 is set no other command is taken; only its rising edge resets a fault.
    return (previous_cw & 0x0080U) == 0 ? Cia402Command::fault_reset : Cia402Command::none;
  }
  if ((cw & 0x0002U) == 0) {
    return Cia402Command::disable_voltage;  // 0xxx xx0x
  }
  if ((cw & 0x0006U) == 0x0002U) {
    return Cia402Command::quick_stop;  // 0xxx x01x
  }
  if ((cw & 0x0007U) == 0x0006U) {
    return Cia402Command::shutdown;  // 0xxx x110
  }
  // Remaining: 0xxx x111.
  return (cw & 0x0008U) != 0 ? Cia402Command::enable_operation : Cia402Command::switch_on;
}

void PowerStateMachine::reset() noexcept {
  state_ = Cia402State::switch_on_disabled;
  previous_cw_ = 0;
}

bool PowerStateMachine::on_controlword(std::uint16_t cw) noexcept {
  const Cia402Command command = command_from_controlword(cw, previous_cw_);
  previous_cw_ = cw;
  return apply(command);
}

bool PowerStateMachine::apply(Cia402Command command) noexcept {
  const Cia402State before = state_;
  using S = Cia402State;
  using C = Cia402Command;
  switch (state_) {
    case S::not_ready_to_switch_on:
    case S::fault_reaction_active:
      break;  // automatic transitions only
    case S::switch_on_disabled:
      if (command == C::shutdown) {
        state_ = S::ready_to_switch_on;  // 2
      }
      break;
    case S::ready_to_switch_on:
      if (command == C::switch_on) {
        state_ = S::switched_on;  // 3
      } else if (command == C::enable_operation) {
        state_ = S::operation_enabled;  // 3 then 4, as "switch on + enable operation" asks
      } else if (command == C::disable_voltage || command == C::quick_stop) {
        state_ = S::switch_on_disabled;  // 7
      }
      break;
    case S::switched_on:
      if (command == C::enable_operation) {
        state_ = S::operation_enabled;  // 4
      } else if (command == C::shutdown) {
        state_ = S::ready_to_switch_on;  // 6
      } else if (command == C::disable_voltage || command == C::quick_stop) {
        state_ = S::switch_on_disabled;  // 10
      }
      break;
    case S::operation_enabled:
      if (command == C::switch_on) {
        state_ = S::switched_on;  // 5 (disable operation)
      } else if (command == C::shutdown) {
        state_ = S::ready_to_switch_on;  // 8
      } else if (command == C::disable_voltage) {
        state_ = S::switch_on_disabled;  // 9
      } else if (command == C::quick_stop) {
        (void)quick_stop();  // 11
      }
      break;
    case S::quick_stop_active:
      if (command == C::disable_voltage) {
        state_ = S::switch_on_disabled;  // 12
      } else if (command == C::enable_operation && quick_stop_stays_active(quick_stop_option_)) {
        state_ = S::operation_enabled;  // 16
      }
      break;
    case S::fault:
      if (command == C::fault_reset) {
        state_ = S::switch_on_disabled;  // 15
      }
      break;
  }
  return state_ != before;
}

bool PowerStateMachine::fault() noexcept {
  if (state_ == Cia402State::fault || state_ == Cia402State::fault_reaction_active) {
    return false;
  }
  state_ = Cia402State::fault_reaction_active;  // 13
  return true;
}

bool PowerStateMachine::quick_stop() noexcept {
  if (state_ != Cia402State::operation_enabled) {
    return false;
  }
  // Option 0 removes power at once: there is no deceleration for the application to run.
  state_ = quick_stop_option_ == 0 ? Cia402State::switch_on_disabled : Cia402State::quick_stop_active;
  return true;
}

bool PowerStateMachine::stop_complete() noexcept {
  if (state_ == Cia402State::fault_reaction_active) {
    state_ = Cia402State::fault;  // 14
    return true;
  }
  if (state_ == Cia402State::quick_stop_active && !quick_stop_stays_active(quick_stop_option_)) {
    state_ = Cia402State::switch_on_disabled;  // 12
    return true;
  }
  return false;
}

}  // namespace settle::hal::canopen
