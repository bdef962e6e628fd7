// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <array>

#include "frame_helpers.hpp"
#include "settle/hal/loopback_bus.hpp"

namespace settle::hal {
namespace {

TEST(LoopbackBus, DeliversToEveryOtherPortInOrderButNotToTheSender) {
  LoopbackHub hub;
  LoopbackBus<8> a{hub};
  LoopbackBus<8> b{hub};
  LoopbackBus<8> c{hub};
  ASSERT_EQ(a.send(test::frame(0x100, {1})), SendStatus::sent);
  ASSERT_EQ(a.send(test::frame(0x101, {2})), SendStatus::sent);
  CanFrame f{};
  for (CanBus* port : {static_cast<CanBus*>(&b), static_cast<CanBus*>(&c)}) {
    ASSERT_EQ(port->receive(f), ReceiveStatus::received);
    EXPECT_EQ(f, test::frame(0x100, {1}));
    ASSERT_EQ(port->receive(f), ReceiveStatus::received);
    EXPECT_EQ(f, test::frame(0x101, {2}));
    EXPECT_EQ(port->receive(f), ReceiveStatus::empty);
  }
  EXPECT_EQ(a.receive(f), ReceiveStatus::empty);
  EXPECT_EQ(a.counters().sent, 2U);
  EXPECT_EQ(b.counters().received, 2U);
}

TEST(LoopbackBus, ReceiveOwnIsOptIn) {
  LoopbackHub hub;
  LoopbackBus<4> a{hub, LoopbackOptions{true}};
  ASSERT_EQ(a.send(test::frame(0x1, {})), SendStatus::sent);
  CanFrame f{};
  EXPECT_EQ(a.receive(f), ReceiveStatus::received);
}

TEST(LoopbackBus, StampsFramesWithTheHubsVirtualTime) {
  LoopbackHub hub;
  LoopbackBus<4> a{hub};
  LoopbackBus<4> b{hub};
  hub.set_time_us(1234);
  ASSERT_EQ(a.send(test::frame(0x1, {})), SendStatus::sent);
  CanFrame f{};
  ASSERT_EQ(b.receive(f, 1000), ReceiveStatus::received);
  EXPECT_EQ(f.timestamp_us, 1234U);
}

TEST(LoopbackBus, FullQueueDropsAndCountsForThatPortOnly) {
  LoopbackHub hub;
  LoopbackBus<2> small{hub};
  LoopbackBus<8> large{hub};
  LoopbackBus<1> sender{hub};
  for (std::uint8_t i = 0; i < 5; ++i) {
    ASSERT_EQ(sender.send(test::frame(0x10, {i})), SendStatus::sent);
  }
  EXPECT_EQ(small.counters().rx_overflow_drops, 3U);
  EXPECT_EQ(large.counters().rx_overflow_drops, 0U);
  EXPECT_EQ(small.pending(), 2U);
  CanFrame f{};
  ASSERT_EQ(small.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f.data[0], 0) << "the oldest frames are kept, later ones dropped";
}

TEST(LoopbackBus, FiltersSelectByIdMaskAndFormat) {
  LoopbackHub hub;
  LoopbackBus<8> tx{hub};
  LoopbackBus<8> rx{hub};
  const std::array filters{CanFilter{0x180, 0x780, FrameFormat::standard}};  // every TPDO1
  ASSERT_EQ(rx.set_filters(filters), BusStatus::ok);
  ASSERT_EQ(tx.send(test::frame(0x181, {1})), SendStatus::sent);
  ASSERT_EQ(tx.send(test::frame(0x201, {2})), SendStatus::sent);
  CanFrame ext = test::frame(0x181, {3});
  ext.flags = can_flag::extended;
  ASSERT_EQ(tx.send(ext), SendStatus::sent);
  CanFrame f{};
  ASSERT_EQ(rx.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f.id, 0x181U);
  EXPECT_FALSE(f.is_extended());
  EXPECT_EQ(rx.receive(f), ReceiveStatus::empty);

  ASSERT_EQ(rx.set_filters({}), BusStatus::ok);  // no filters: everything again
  ASSERT_EQ(tx.send(test::frame(0x201, {2})), SendStatus::sent);
  EXPECT_EQ(rx.receive(f), ReceiveStatus::received);

  std::array<CanFilter, max_can_filters + 1> too_many{};
  EXPECT_EQ(rx.set_filters(too_many), BusStatus::too_many_filters);
}

TEST(LoopbackBus, InvalidFramesAreErrorsAndNeverDelivered) {
  LoopbackHub hub;
  LoopbackBus<4> a{hub};
  LoopbackBus<4> b{hub};
  CanFrame bad{};
  bad.id = 0x800;
  EXPECT_EQ(a.send(bad), SendStatus::error);
  EXPECT_EQ(a.counters().tx_errors, 1U);
  EXPECT_EQ(b.pending(), 0U);
}

TEST(LoopbackBus, APortLeavesTheHubWhenDestroyed) {
  LoopbackHub hub;
  LoopbackBus<4> a{hub};
  {
    LoopbackBus<4> temporary{hub};
  }
  LoopbackBus<4> b{hub};
  ASSERT_EQ(a.send(test::frame(0x1, {})), SendStatus::sent);
  EXPECT_EQ(b.pending(), 1U);
}

TEST(LoopbackBus, WorksAsAFrameSink) {
  LoopbackHub hub;
  LoopbackBus<4> a{hub};
  LoopbackBus<4> b{hub};
  FrameSink& sink = a;
  EXPECT_TRUE(sink.put(test::frame(0x5, {5})));
  EXPECT_EQ(b.pending(), 1U);
}

}  // namespace
}  // namespace settle::hal
