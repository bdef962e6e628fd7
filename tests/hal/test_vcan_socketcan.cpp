// SPDX-License-Identifier: Apache-2.0
// The SocketCAN backend on a real (virtual) CAN interface: frames, filters, FD, timestamps,
// back-pressure reported as busy, kernel drops counted, and link control through libsocketcan
// saying "not supported" for what a vcan has not got.
#include <gtest/gtest.h>

#include <array>
#include <thread>

#include "frame_helpers.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "socketcan_expectations.hpp"
#include "vcan_support.hpp"

namespace settle::hal {
namespace {

class VcanSocketCan : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::vcan_present()) {
      GTEST_SKIP() << test::vcan_missing;
    }
  }
};

TEST_F(VcanSocketCan, FramesTravelBetweenSocketsWithKernelTimestamps) {
  SocketCanBus a;
  SocketCanBus b;
  ASSERT_EQ(a.open(test::vcan_interface), OpenStatus::ok);
  ASSERT_EQ(b.open(test::vcan_interface), OpenStatus::ok);
  CanFrame ext = test::frame(0x1234567, {9, 8, 7});
  ext.flags = can_flag::extended;
  CanFrame rtr{};
  rtr.id = 0x7FF;
  rtr.flags = can_flag::rtr;
  rtr.len = 2;
  for (const CanFrame& f : {test::frame(0x123, {1, 2, 3, 4, 5, 6, 7, 8}), ext, rtr, test::frame(0x0, {})}) {
    ASSERT_EQ(a.send(f), SendStatus::sent);
    CanFrame got{};
    ASSERT_EQ(b.receive(got, 1'000'000), ReceiveStatus::received);
    EXPECT_EQ(got, f);
    EXPECT_GT(got.timestamp_us, 0U) << "SO_TIMESTAMP";
  }
  CanFrame none{};
  EXPECT_EQ(a.receive(none), ReceiveStatus::empty) << "a socket does not hear itself by default";
  EXPECT_EQ(b.receive(none, 10'000), ReceiveStatus::empty) << "timeout elapses";
}

TEST_F(VcanSocketCan, FiltersAreAppliedInTheKernel) {
  SocketCanBus tx;
  SocketCanBus rx;
  ASSERT_EQ(tx.open(test::vcan_interface), OpenStatus::ok);
  ASSERT_EQ(rx.open(test::vcan_interface), OpenStatus::ok);
  const std::array filters{CanFilter{0x180, 0x780, FrameFormat::standard}, CanFilter{0x80, 0x7FF, FrameFormat::standard}};
  ASSERT_EQ(rx.set_filters(filters), BusStatus::ok);
  CanFrame ext = test::frame(0x181, {});
  ext.flags = can_flag::extended;
  for (const CanFrame& f : {test::frame(0x201, {}), ext, test::frame(0x181, {1}), test::frame(0x80, {})}) {
    ASSERT_EQ(tx.send(f), SendStatus::sent);
  }
  CanFrame got{};
  ASSERT_EQ(rx.receive(got, 1'000'000), ReceiveStatus::received);
  EXPECT_EQ(got, test::frame(0x181, {1}));
  ASSERT_EQ(rx.receive(got, 1'000'000), ReceiveStatus::received);
  EXPECT_EQ(got, test::frame(0x80, {}));
  EXPECT_EQ(rx.receive(got, 10'000), ReceiveStatus::empty);
}

TEST_F(VcanSocketCan, FdFramesNeedTheFdOption) {
  SocketCanBus classic;
  SocketCanBus fd;
  ASSERT_EQ(classic.open(test::vcan_interface), OpenStatus::ok);
  SocketCanOptions options{};
  options.fd_frames = true;
  const OpenStatus status = fd.open(test::vcan_interface, options);
  if (status == OpenStatus::fd_not_supported) {
    GTEST_SKIP() << "vcan0 has a classic MTU (ip link set vcan0 mtu 72 enables FD)";
  }
  ASSERT_EQ(status, OpenStatus::ok);
  CanFrame big = make_frame(0x100, std::array<std::uint8_t, 64>{1, 2, 3});
  big.flags |= can_flag::brs;
  EXPECT_EQ(classic.send(big), SendStatus::error) << "FD on a classic socket";
  SocketCanBus fd_rx;
  ASSERT_EQ(fd_rx.open(test::vcan_interface, options), OpenStatus::ok);
  ASSERT_EQ(fd.send(big), SendStatus::sent);
  CanFrame got{};
  ASSERT_EQ(fd_rx.receive(got, 1'000'000), ReceiveStatus::received);
  EXPECT_EQ(got, big);
  EXPECT_EQ(classic.receive(got, 10'000), ReceiveStatus::empty) << "classic sockets never see FD frames";
}

TEST_F(VcanSocketCan, EveryFrameIsSentBusyOrCountedAsDroppedNeverLostSilently) {
  SocketCanOptions small{};
  small.send_buffer_bytes = 1;     // the kernel rounds up to its minimum
  small.receive_buffer_bytes = 1;  // likewise: a tiny queue that must overflow
  SocketCanBus tx;
  SocketCanBus rx;
  ASSERT_EQ(tx.open(test::vcan_interface, small), OpenStatus::ok);
  ASSERT_EQ(rx.open(test::vcan_interface, small), OpenStatus::ok);
  constexpr int attempts = 20'000;
  for (int i = 0; i < attempts; ++i) {
    const SendStatus s = tx.send(test::frame(0x55, {static_cast<std::uint8_t>(i)}));
    ASSERT_NE(s, SendStatus::error);
  }
  EXPECT_EQ(tx.counters().sent + tx.counters().tx_busy, static_cast<std::uint64_t>(attempts));
  CanFrame got{};
  while (rx.receive(got, 50'000) == ReceiveStatus::received) {
  }
  EXPECT_GT(rx.counters().rx_overflow_drops, 0U) << "the receiver never read while 20000 frames came";
  EXPECT_EQ(rx.counters().received + rx.counters().rx_overflow_drops, tx.counters().sent);
  std::printf("[ vcan ] %d sends: %llu sent, %llu busy; receiver got %llu, kernel dropped %llu\n", attempts,
              static_cast<unsigned long long>(tx.counters().sent), static_cast<unsigned long long>(tx.counters().tx_busy),
              static_cast<unsigned long long>(rx.counters().received),
              static_cast<unsigned long long>(rx.counters().rx_overflow_drops));
}

TEST_F(VcanSocketCan, LinkControlAppliesAndControllerSettingsAreNotSupported) {
  CanInterface vcan{test::vcan_interface};
  test::expect_controller_settings_not_supported(vcan);

  const ControlStatus down = vcan.link_down();
  if (down == ControlStatus::permission_denied) {
    GTEST_SKIP() << "link up/down needs CAP_NET_ADMIN";
  }
  ASSERT_EQ(down, ControlStatus::ok);
  SocketCanBus bus;
  ASSERT_EQ(bus.open(test::vcan_interface), OpenStatus::ok);
  EXPECT_EQ(bus.send(test::frame(0x1, {})), SendStatus::error) << "the link is down";
  ASSERT_EQ(vcan.link_up(), ControlStatus::ok);
  EXPECT_EQ(bus.send(test::frame(0x1, {})), SendStatus::sent);
}

}  // namespace
}  // namespace settle::hal
