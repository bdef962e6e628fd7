// SPDX-License-Identifier: Apache-2.0
// MailboxBus: the controller-buffer backend the servo loop runs on in firmware.
#include <gtest/gtest.h>

#include <array>

#include "frame_helpers.hpp"
#include "settle/hal/mailbox_bus.hpp"

namespace settle::hal {
namespace {

TEST(MailboxBus, FramesLeaveInTheOrderSentAndBusyWhenEveryMailboxIsPending) {
  MailboxBus<3, 4> bus;
  for (std::uint8_t i = 0; i < 3; ++i) {
    ASSERT_EQ(bus.send(test::frame(0x200U + i, {i, 2, 3, 4, 5, 6, 7, 8})), SendStatus::sent);
  }
  EXPECT_EQ(bus.send(test::frame(0x203, {9})), SendStatus::busy) << "three mailboxes, three pending";
  EXPECT_EQ(bus.counters().tx_busy, 1U);
  CanFrame f{};
  ASSERT_TRUE(bus.take_sent(f));
  EXPECT_EQ(f, test::frame(0x200, {0, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(bus.send(test::frame(0x203, {9})), SendStatus::sent) << "a mailbox is free again";
  for (std::uint32_t id : {0x201U, 0x202U, 0x203U}) {
    ASSERT_TRUE(bus.take_sent(f));
    EXPECT_EQ(f.id, id);
  }
  EXPECT_FALSE(bus.take_sent(f));
  EXPECT_EQ(bus.counters().sent, 4U);
}

TEST(MailboxBus, ReceiveFifoKeepsOrderTimestampsAndCountsOverrun) {
  MailboxBus<1, 2> bus;
  CanFrame a = test::frame(0x181, {1, 2, 3, 4, 5, 6});
  a.timestamp_us = 1000;
  CanFrame b = test::frame(0x281, {8, 7, 6, 5, 4, 3, 2, 1});
  b.timestamp_us = 1001;
  ASSERT_TRUE(bus.put_received(a));
  ASSERT_TRUE(bus.put_received(b));
  EXPECT_FALSE(bus.put_received(test::frame(0x701, {5}))) << "FIFO full: the new frame is lost";
  EXPECT_EQ(bus.counters().rx_overflow_drops, 1U);
  CanFrame f{};
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f, a);
  EXPECT_EQ(f.timestamp_us, 1000U);
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f, b);
  EXPECT_EQ(f.timestamp_us, 1001U);
  EXPECT_EQ(bus.receive(f), ReceiveStatus::empty);
  EXPECT_EQ(bus.counters().received, 2U);
}

TEST(MailboxBus, ReceivedRecordsAreReadInPlaceThenConsumedAndCounted) {
  MailboxBus<1, 3> bus;
  CanFrame f{};
  // Move the FIFO's head so that the records read below wrap around its storage.
  ASSERT_TRUE(bus.put_received(test::frame(0x701, {5})));
  ASSERT_TRUE(bus.put_received(test::frame(0x702, {5})));
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  CanFrame a = test::frame(0x181, {1, 2, 3, 4, 5, 6});
  a.timestamp_us = 7;
  CanFrame b = test::frame(0x281, {8, 7, 6, 5, 4, 3, 2, 1});
  b.timestamp_us = 8;
  CanFrame c = test::frame(0x1ABCDEF0, {9});
  c.flags = can_flag::extended;
  ASSERT_TRUE(bus.put_received(a));
  ASSERT_TRUE(bus.put_received(b));
  ASSERT_TRUE(bus.put_received(c));
  ASSERT_EQ(bus.pending_rx(), 3U);
  EXPECT_EQ(bus.received(0).id, 0x181U);
  EXPECT_EQ(bus.received(0).len, 6U);
  EXPECT_EQ(bus.received(0).data[5], 6U);
  EXPECT_EQ(bus.received(1).id, 0x281U) << "the record after the end of the storage";
  EXPECT_EQ(bus.received(1).data[7], 1U);
  EXPECT_FALSE(bus.received(1).is_extended());
  EXPECT_TRUE(bus.received(2).is_extended());
  bus.received_frame(1, f);
  EXPECT_EQ(f, b) << "copied out as receive() would";
  EXPECT_EQ(f.timestamp_us, 8U);
  EXPECT_EQ(bus.pending_rx(), 3U) << "reading takes nothing";
  EXPECT_EQ(bus.counters().received, 2U);
  bus.consume_received(2);
  EXPECT_EQ(bus.counters().received, 4U) << "as two calls of receive()";
  ASSERT_EQ(bus.pending_rx(), 1U);
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f, c);
  EXPECT_EQ(bus.receive(f), ReceiveStatus::empty);
}

TEST(MailboxBus, ClassicControllerRefusesFdAndFiltersOnReceive) {
  MailboxBus<> bus;
  std::array<std::uint8_t, 12> twelve{};
  const CanFrame fd = make_frame(0x100, twelve);
  ASSERT_TRUE(fd.is_fd());
  EXPECT_EQ(bus.send(fd), SendStatus::error);
  EXPECT_EQ(bus.pending_tx(), 0U) << "nothing queued on an error";
  EXPECT_FALSE(bus.put_received(fd));
  CanFrame bad = test::frame(0x100, {});
  bad.len = 9;
  EXPECT_EQ(bus.send(bad), SendStatus::error) << "an invalid frame never reaches a mailbox";

  const std::array<CanFilter, 1> only_node_1{CanFilter{0x001, 0x07F, FrameFormat::standard}};
  ASSERT_EQ(bus.set_filters(only_node_1), BusStatus::ok);
  EXPECT_TRUE(bus.put_received(test::frame(0x181, {1})));
  EXPECT_FALSE(bus.put_received(test::frame(0x182, {1}))) << "acceptance filter";
  EXPECT_EQ(bus.pending_rx(), 1U);
  EXPECT_EQ(bus.counters().rx_overflow_drops, 0U) << "a filtered frame is not an overrun";
}

TEST(MailboxBus, ReceivingWritesOnlyTheClassicPartOfTheCallersFrame) {
  MailboxBus<> bus;
  ASSERT_TRUE(bus.put_received(test::frame(0x181, {1, 2})));
  CanFrame f{};
  f.data[20] = 0xAB;  // beyond any classic frame: a receive must not cost a 64-byte copy
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f, test::frame(0x181, {1, 2}));
  EXPECT_EQ(f.data[20], 0xAB);
}

TEST(MailboxBus, ItsOwnCallsAndTheCanBusCallsDoTheSame) {
  // The servo loop of firmware holds the controller by its own type (direct calls); everything
  // else holds a CanBus&. Same frames, same statuses, same counters, either way.
  MailboxBus<2, 2> own;
  MailboxBus<2, 2> base_side;
  CanBus& base = base_side;
  CanFrame bad = test::frame(0x100, {});
  bad.len = 9;
  const CanFrame frames[] = {test::frame(0x201, {1, 2, 3, 4, 5, 6}), bad, test::frame(0x80, {}),
                             test::frame(0x202, {7})};
  for (const CanFrame& f : frames) EXPECT_EQ(own.send(f), base.send(f));
  EXPECT_EQ(own.counters().sent, 2U);
  EXPECT_EQ(own.counters().tx_busy, 1U);
  EXPECT_EQ(own.counters().tx_errors, 1U);
  EXPECT_EQ(base_side.counters().sent, own.counters().sent);
  EXPECT_EQ(base_side.counters().tx_busy, own.counters().tx_busy);
  EXPECT_EQ(base_side.counters().tx_errors, own.counters().tx_errors);
  for (auto* bus : {&own, &base_side}) {
    ASSERT_TRUE(bus->put_received(test::frame(0x181, {9, 8, 7, 6, 5, 4})));
  }
  CanFrame a{};
  CanFrame b{};
  EXPECT_EQ(own.receive(a), ReceiveStatus::received);
  EXPECT_EQ(base.receive(b), ReceiveStatus::received);
  EXPECT_EQ(a, b);
  EXPECT_EQ(own.receive(a), ReceiveStatus::empty);
  EXPECT_EQ(base.receive(b), ReceiveStatus::empty);
  EXPECT_EQ(own.counters().received, 1U);
  EXPECT_EQ(base_side.counters().received, 1U);
}

}  // namespace
}  // namespace settle::hal
