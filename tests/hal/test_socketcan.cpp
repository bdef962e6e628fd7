// SPDX-License-Identifier: Apache-2.0
// SocketCAN backend behaviour that needs no CAN interface: clear statuses instead of crashes
// on hosts without CAN (this machine's kernel has none; the vcan suites cover the rest).
#include <gtest/gtest.h>

#include <array>
#include <set>
#include <string>

#include "frame_helpers.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "socketcan_expectations.hpp"

namespace settle::hal {
namespace {

#define COUNT_ONE(name, text) +1

// One distinct sentence per enumerator of the list, and "?" past it.
template <typename E> void expect_distinct_sentences(int count) {
  std::set<std::string> texts;
  for (int i = 0; i < count; ++i) {
    EXPECT_TRUE(texts.insert(to_string(static_cast<E>(i))).second) << i;
  }
  EXPECT_STREQ(to_string(static_cast<E>(count)), "?");
}

// Both statuses' sentences come from one list each.
TEST(SocketCanBus, StatusSentencesComeFromOneList) {
  expect_distinct_sentences<OpenStatus>(0 SETTLE_HAL_OPEN_STATUSES(COUNT_ONE));
  expect_distinct_sentences<ControlStatus>(0 SETTLE_HAL_CONTROL_STATUSES(COUNT_ONE));
  EXPECT_STREQ(to_string(OpenStatus::fd_not_supported), "CAN FD not supported by the interface (MTU 16)");
  EXPECT_STREQ(to_string(ControlStatus::not_supported), "not supported by this interface");
}

TEST(SocketCanBus, MissingInterfaceIsReportedAsSuch) {
  SocketCanBus bus;
  EXPECT_EQ(bus.open("settle-none0"), OpenStatus::no_such_interface);
  EXPECT_FALSE(bus.is_open());
  EXPECT_EQ(bus.open("this-name-is-longer-than-ifnamsiz"), OpenStatus::no_such_interface);
  EXPECT_EQ(bus.open(nullptr), OpenStatus::no_such_interface);
}

TEST(SocketCanBus, NonCanInterfaceIsRefused) {
  SocketCanBus bus;
  EXPECT_EQ(bus.open("lo"), OpenStatus::not_can_interface);
}

TEST(SocketCanBus, ClosedBusReportsErrorsAndCountsThem) {
  SocketCanBus bus;
  EXPECT_EQ(bus.send(test::frame(0x1, {1})), SendStatus::error);
  CanFrame f{};
  EXPECT_EQ(bus.receive(f), ReceiveStatus::error);
  EXPECT_EQ(bus.receive(f, 1000), ReceiveStatus::error);
  EXPECT_EQ(bus.counters().tx_errors, 1U);
  EXPECT_EQ(bus.counters().rx_errors, 2U);
  EXPECT_EQ(bus.set_filters({}), BusStatus::error);
}

TEST(CanInterface, ControlOfAMissingInterfaceSaysSo) {
  CanInterface iface{"settle-none0"};
  EXPECT_FALSE(iface.exists());
  EXPECT_EQ(iface.link_up(), ControlStatus::no_such_interface);
  CanControllerState state{};
  EXPECT_EQ(iface.state(state), ControlStatus::no_such_interface);
}

TEST(CanInterface, ControllerSettingsOnANonCanInterfaceAreNotSupported) {
  CanInterface lo{"lo"};
  test::expect_controller_settings_not_supported(lo);
}

// The kernel's error-frame encoding (linux/can/error.h), written out as numbers so that the test
// does not share the implementation's constants: CAN_ERR_FLAG 0x20000000, CAN_ERR_CRTL 0x4,
// CAN_ERR_BUSOFF 0x40, CAN_ERR_RESTARTED 0x100; data[1] (controller problems) RX_WARNING 0x04,
// TX_WARNING 0x08, RX_PASSIVE 0x10, TX_PASSIVE 0x20, ACTIVE 0x40.
TEST(SocketCanErrorFrames, EachControllerReportMapsToItsState) {
  const auto state = [](std::uint32_t id, std::uint8_t crtl, BusState before) {
    const std::array<std::uint8_t, 8> data{0, crtl, 0, 0, 0, 0, 0, 0};
    return bus_state_from_error_frame(0x2000'0000U | id, data, before);
  };
  EXPECT_EQ(state(0x40, 0, BusState::error_passive), BusState::bus_off);
  EXPECT_EQ(state(0x100, 0, BusState::bus_off), BusState::error_active);
  EXPECT_EQ(state(0x4, 0x04, BusState::error_active), BusState::error_warning);
  EXPECT_EQ(state(0x4, 0x08, BusState::error_active), BusState::error_warning);
  EXPECT_EQ(state(0x4, 0x10, BusState::error_warning), BusState::error_passive);
  EXPECT_EQ(state(0x4, 0x20, BusState::error_active), BusState::error_passive);
  EXPECT_EQ(state(0x4, 0x40, BusState::error_passive), BusState::error_active);
  // a report that says nothing about the state (a transmit timeout, an overflow) keeps it
  EXPECT_EQ(state(0x1, 0, BusState::error_passive), BusState::error_passive);
  EXPECT_EQ(state(0x4, 0x01, BusState::error_warning), BusState::error_warning);
  // a truncated report cannot say warning or passive
  EXPECT_EQ(bus_state_from_error_frame(0x2000'0004U, std::span<const std::uint8_t>{}, BusState::error_active),
            BusState::error_active);
}

TEST(SocketCanBus, AClosedBusCannotRestartAndStartsErrorActive) {
  SocketCanBus bus;
  EXPECT_EQ(bus.bus_state(), BusState::error_active);
  EXPECT_EQ(bus.restart(), BusStatus::error);
}

}  // namespace
}  // namespace settle::hal
