// SocketCAN backend behaviour that needs no CAN interface: clear statuses instead of crashes
// on hosts without CAN (this machine's kernel has none; the vcan suites cover the rest).
#include <gtest/gtest.h>

#include "frame_helpers.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "socketcan_expectations.hpp"

namespace settle::hal {
namespace {

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

}  // namespace
}  // namespace settle::hal
