// SocketCAN backend behaviour that needs no CAN interface: clear statuses instead of crashes
// on hosts without CAN (this machine's kernel has none; the vcan suites cover the rest).
#include <gtest/gtest.h>

#include "frame_helpers.hpp"
#include "settle/hal/socketcan_bus.hpp"

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
  ASSERT_TRUE(lo.exists());
  EXPECT_FALSE(lo.has_controller());
  std::uint32_t bitrate = 0;
  EXPECT_EQ(lo.bitrate(bitrate), ControlStatus::not_supported);
  EXPECT_EQ(lo.set_bitrate(500'000), ControlStatus::not_supported);
  EXPECT_EQ(lo.restart(), ControlStatus::not_supported);
  CanErrorCounters counters{};
  EXPECT_EQ(lo.error_counters(counters), ControlStatus::not_supported);
}

}  // namespace
}  // namespace settle::hal
