// SPDX-License-Identifier: Apache-2.0
// The CiA 402 power state machine as tables: every transition by controlword, the statusword
// each state reports (decoded with the standard masks), and the master's enable sequence.
#include <gtest/gtest.h>

#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/remote_drive.hpp"

namespace settle::hal::canopen {
namespace {

using S = Cia402State;

// Puts a machine in a state through legal transitions only.
PowerStateMachine machine_in(S state, std::int16_t quick_stop_option = 2) {
  PowerStateMachine m;
  m.set_quick_stop_option(quick_stop_option);
  m.reset();
  const auto cw = [&m](std::uint16_t value) { (void)m.on_controlword(value); };
  switch (state) {
    case S::switch_on_disabled: break;
    case S::ready_to_switch_on: cw(0x06); break;
    case S::switched_on: cw(0x06); cw(0x07); break;
    case S::operation_enabled: cw(0x06); cw(0x07); cw(0x0F); break;
    case S::quick_stop_active: cw(0x06); cw(0x07); cw(0x0F); cw(0x02); break;
    case S::fault_reaction_active: (void)m.fault(); break;
    case S::fault: (void)m.fault(); (void)m.stop_complete(); break;
    case S::not_ready_to_switch_on: break;
  }
  EXPECT_EQ(m.state(), state);
  return m;
}

struct Transition {
  S from;
  std::uint16_t controlword;
  S to;
  const char* name;
};

class PowerStateMachineTransitions : public ::testing::TestWithParam<Transition> {};

TEST_P(PowerStateMachineTransitions, ControlwordMovesTheStateAsCia402Specifies) {
  const Transition t = GetParam();
  PowerStateMachine m = machine_in(t.from);
  (void)m.on_controlword(t.controlword);
  EXPECT_EQ(m.state(), t.to) << t.name << ": " << to_string(t.from) << " + 0x" << std::hex << t.controlword
                             << " gave " << to_string(m.state());
}

INSTANTIATE_TEST_SUITE_P(
    Table, PowerStateMachineTransitions,
    ::testing::Values(
        Transition{S::switch_on_disabled, 0x06, S::ready_to_switch_on, "2 shutdown"},
        Transition{S::ready_to_switch_on, 0x07, S::switched_on, "3 switch on"},
        Transition{S::ready_to_switch_on, 0x0F, S::operation_enabled, "3+4 switch on + enable"},
        Transition{S::switched_on, 0x0F, S::operation_enabled, "4 enable operation"},
        Transition{S::operation_enabled, 0x07, S::switched_on, "5 disable operation"},
        Transition{S::switched_on, 0x06, S::ready_to_switch_on, "6 shutdown"},
        Transition{S::ready_to_switch_on, 0x00, S::switch_on_disabled, "7 disable voltage"},
        Transition{S::ready_to_switch_on, 0x02, S::switch_on_disabled, "7 quick stop"},
        Transition{S::operation_enabled, 0x06, S::ready_to_switch_on, "8 shutdown"},
        Transition{S::operation_enabled, 0x00, S::switch_on_disabled, "9 disable voltage"},
        Transition{S::switched_on, 0x00, S::switch_on_disabled, "10 disable voltage"},
        Transition{S::switched_on, 0x02, S::switch_on_disabled, "10 quick stop"},
        Transition{S::operation_enabled, 0x02, S::quick_stop_active, "11 quick stop"},
        Transition{S::quick_stop_active, 0x00, S::switch_on_disabled, "12 disable voltage"},
        Transition{S::fault, 0x80, S::switch_on_disabled, "15 fault reset"},
        // Commands that do not apply leave the state alone.
        Transition{S::switch_on_disabled, 0x07, S::switch_on_disabled, "switch on needs shutdown first"},
        Transition{S::switch_on_disabled, 0x0F, S::switch_on_disabled, "enable needs shutdown first"},
        Transition{S::quick_stop_active, 0x0F, S::quick_stop_active, "16 only for options 5..8"},
        Transition{S::fault, 0x06, S::fault, "a fault needs a reset"},
        Transition{S::fault_reaction_active, 0x80, S::fault_reaction_active, "reaction runs to its end"},
        Transition{S::operation_enabled, 0x8F, S::operation_enabled, "bit 7 set: no command"},
        // Bits outside 0-3 and 7 do not matter.
        Transition{S::switch_on_disabled, 0x0076, S::ready_to_switch_on, "shutdown with other bits"}));

TEST(PowerStateMachine, QuickStopStaysActiveOnlyForOptions5To8) {
  for (std::int16_t option = 1; option <= 8; ++option) {
    PowerStateMachine m = machine_in(S::quick_stop_active, option);
    EXPECT_TRUE(m.stopping());
    (void)m.stop_complete();
    const bool stays = option >= 5;
    EXPECT_EQ(m.state(), stays ? S::quick_stop_active : S::switch_on_disabled) << "option " << option;
    if (stays) {
      (void)m.on_controlword(0x0F);
      EXPECT_EQ(m.state(), S::operation_enabled) << "transition 16, option " << option;
    }
  }
  PowerStateMachine zero = machine_in(S::operation_enabled, 0);
  (void)zero.on_controlword(0x02);
  EXPECT_EQ(zero.state(), S::switch_on_disabled) << "option 0 disables the drive function at once";
}

TEST(PowerStateMachine, FaultResetActsOnTheRisingEdgeOnly) {
  PowerStateMachine m = machine_in(S::fault);
  (void)m.on_controlword(0x80);
  EXPECT_EQ(m.state(), S::switch_on_disabled);
  (void)m.fault();
  (void)m.stop_complete();
  (void)m.on_controlword(0x80);
  EXPECT_EQ(m.state(), S::fault) << "bit 7 was already high";
  (void)m.on_controlword(0x00);
  (void)m.on_controlword(0x80);
  EXPECT_EQ(m.state(), S::switch_on_disabled);
}

TEST(PowerStateMachine, FaultFromAnyStateGoesThroughFaultReaction) {
  for (const S s : {S::switch_on_disabled, S::ready_to_switch_on, S::switched_on, S::operation_enabled,
                    S::quick_stop_active}) {
    PowerStateMachine m = machine_in(s);
    EXPECT_TRUE(m.fault());
    EXPECT_EQ(m.state(), S::fault_reaction_active);
    EXPECT_TRUE(m.stop_complete());
    EXPECT_EQ(m.state(), S::fault);
    EXPECT_FALSE(m.fault()) << "already in fault";
  }
}

TEST(Statusword, EveryStateRoundTripsThroughTheStandardMasks) {
  for (const S s : {S::not_ready_to_switch_on, S::switch_on_disabled, S::ready_to_switch_on, S::switched_on,
                    S::operation_enabled, S::quick_stop_active, S::fault_reaction_active, S::fault}) {
    const std::uint16_t sw = statusword_state_bits(s);
    EXPECT_EQ(state_from_statusword(sw), s) << to_string(s);
    // Bits outside the masks (remote, target reached, mode-specific, ...) must not matter.
    EXPECT_EQ(state_from_statusword(static_cast<std::uint16_t>(sw | 0xFF80U)), s) << to_string(s);
  }
  EXPECT_EQ(state_from_statusword(0x0237), S::operation_enabled);
  EXPECT_EQ(state_from_statusword(0x0250), S::switch_on_disabled);
  EXPECT_EQ(state_from_statusword(0x0218), S::fault);
}

TEST(Statusword, TheInlineEnabledTestAgreesWithTheStateOnEveryStatusword) {
  // Exhaustive: the master's per-TPDO mask-and-compare against the full decode.
  for (std::uint32_t sw = 0; sw <= 0xFFFFU; ++sw) {
    const auto w = static_cast<std::uint16_t>(sw);
    ASSERT_EQ(is_operation_enabled(w), state_from_statusword(w) == S::operation_enabled) << sw;
  }
}

TEST(Controlword, CommandsDecodeByTheirMasks) {
  EXPECT_EQ(command_from_controlword(0x06, 0), Cia402Command::shutdown);
  EXPECT_EQ(command_from_controlword(0x07, 0), Cia402Command::switch_on);
  EXPECT_EQ(command_from_controlword(0x0F, 0), Cia402Command::enable_operation);
  EXPECT_EQ(command_from_controlword(0x00, 0), Cia402Command::disable_voltage);
  EXPECT_EQ(command_from_controlword(0x0D, 0), Cia402Command::disable_voltage) << "bit 1 clear";
  EXPECT_EQ(command_from_controlword(0x02, 0), Cia402Command::quick_stop);
  EXPECT_EQ(command_from_controlword(0x0B, 0), Cia402Command::quick_stop);
  EXPECT_EQ(command_from_controlword(0x80, 0x00), Cia402Command::fault_reset);
  EXPECT_EQ(command_from_controlword(0x80, 0x80), Cia402Command::none);
}

TEST(EnableSequence, WalksShutdownSwitchOnEnableAndResetsFaultsOnARisingEdge) {
  EnableSequence seq;
  EXPECT_EQ(seq.next(statusword_state_bits(S::switch_on_disabled)), 0x06);
  EXPECT_EQ(seq.next(statusword_state_bits(S::ready_to_switch_on)), 0x07);
  EXPECT_EQ(seq.next(statusword_state_bits(S::switched_on)), 0x0F);
  EXPECT_EQ(seq.next(statusword_state_bits(S::operation_enabled)), 0x0F);
  EXPECT_TRUE(EnableSequence::done(statusword_state_bits(S::operation_enabled)));
  EXPECT_EQ(seq.next(statusword_state_bits(S::fault)), 0x80);
  EXPECT_EQ(seq.next(statusword_state_bits(S::fault)), 0x00) << "drop bit 7 so it can rise again";
  EXPECT_EQ(seq.next(statusword_state_bits(S::fault)), 0x80);
  EXPECT_EQ(seq.next(statusword_state_bits(S::quick_stop_active)), 0x00);
}

TEST(EnableSequence, DrivesTheDriveSideMachineToOperationEnabledFromAnyState) {
  for (const S s : {S::switch_on_disabled, S::ready_to_switch_on, S::switched_on, S::operation_enabled,
                    S::quick_stop_active, S::fault}) {
    PowerStateMachine m = machine_in(s);
    EnableSequence seq;
    int steps = 0;
    while (!m.enabled() && steps < 10) {
      (void)m.on_controlword(seq.next(m.statusword_bits()));
      ++steps;
    }
    EXPECT_TRUE(m.enabled()) << "from " << to_string(s);
    EXPECT_LE(steps, 5);
  }
}

TEST(InterpolationPeriod, PicksAnExactValueAndIndex) {
  const auto ms = interpolation_period_from_us(1000);
  ASSERT_TRUE(ms);
  EXPECT_EQ(ms->value, 1);
  EXPECT_EQ(ms->index, -3);
  const auto quarter = interpolation_period_from_us(250);
  ASSERT_TRUE(quarter);
  EXPECT_EQ(quarter->value, 25);
  EXPECT_EQ(quarter->index, -5);
  EXPECT_FALSE(interpolation_period_from_us(257)) << "needs a value above 255 at µs resolution";
  EXPECT_FALSE(interpolation_period_from_us(0));
}

}  // namespace
}  // namespace settle::hal::canopen
