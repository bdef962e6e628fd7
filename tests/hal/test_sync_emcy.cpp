// SPDX-License-Identifier: Apache-2.0
// SYNC with and without its counter, loss detection, and EMCY with its inhibit time.
#include <gtest/gtest.h>

#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/emcy.hpp"
#include "settle/hal/canopen/sync.hpp"

namespace settle::hal::canopen {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(Sync, FrameHasNoPayloadOrOneCounterByte) {
  EXPECT_EQ(encode_sync().id, 0x80U);
  EXPECT_EQ(encode_sync().len, 0U);
  EXPECT_EQ(test::bytes_of(encode_sync(17)), (Bytes{17}));
  EXPECT_EQ(decode_sync(encode_sync())->counter, 0);
  EXPECT_EQ(decode_sync(encode_sync(240))->counter, 240);
  CanFrame bad = encode_sync(1);
  bad.data[0] = 241;
  EXPECT_FALSE(decode_sync(bad)) << "counter above 240";
  bad.len = 2;
  EXPECT_FALSE(decode_sync(bad));
}

TEST(SyncProducer, CounterRunsFromOneToTheOverflowValue) {
  SyncProducer p{1000, 3};
  std::vector<int> counters;
  for (int i = 0; i < 7; ++i) {
    counters.push_back(p.next().data[0]);
  }
  EXPECT_EQ(counters, (std::vector<int>{1, 2, 3, 1, 2, 3, 1}));
  SyncProducer plain{1000};
  EXPECT_EQ(plain.next(), encode_sync(0));
  EXPECT_EQ(plain.next(), encode_sync(0));
}

TEST(SyncProducer, LateCallSendsOneSyncAndSkipsTheMissedPeriods) {
  SyncProducer p{1000};
  FrameBuffer<8> out;
  p.start(0);
  EXPECT_TRUE(p.poll(0, out));
  EXPECT_FALSE(p.poll(999, out));
  EXPECT_TRUE(p.poll(3500, out));
  EXPECT_EQ(p.skipped(), 2U);
  EXPECT_FALSE(p.poll(3999, out));
  EXPECT_TRUE(p.poll(4000, out));
  EXPECT_EQ(out.size(), 3U);
}

// CiA 301: with 0x1019 = 0 a SYNC carries no data. A counter byte means the producer and the
// consumer disagree on 0x1019: an unexpected length (CANopenNode: EMCY 0x8240), whatever its value.
TEST(SyncConsumer, ACounterWhileNoneIsConfiguredIsAnUnexpectedLength) {
  SyncConsumer c{1000, 3};
  std::uint64_t t = 0;
  EXPECT_EQ(c.on_sync({0}, t += 1000), SyncEvent::in_order);
  for (const std::uint8_t counter : {std::uint8_t{1}, std::uint8_t{2}, std::uint8_t{240}}) {
    EXPECT_EQ(c.on_sync({counter}, t += 1000), SyncEvent::unexpected_length) << int{counter};
  }
  EXPECT_EQ(c.on_sync({0}, t += 1000), SyncEvent::in_order);
  // With a counter configured the wrap is in order and a skipped counter is out of sequence.
  c.set_counter_overflow(3);
  for (const std::uint8_t counter : {std::uint8_t{1}, std::uint8_t{2}, std::uint8_t{3}, std::uint8_t{1}, std::uint8_t{2}}) {
    EXPECT_EQ(c.on_sync({counter}, t += 1000), SyncEvent::in_order) << int{counter};
  }
  EXPECT_EQ(c.on_sync({1}, t += 1000), SyncEvent::out_of_sequence);
}

TEST(SyncConsumer, LossIsDeclaredAfterMoreThanTheToleratedPeriods) {
  SyncConsumer c{1000, 3};  // up to three missing SYNCs are tolerated
  EXPECT_FALSE(c.check_loss(1'000'000)) << "nothing to lose before the first SYNC";
  (void)c.on_sync({0}, 10'000);
  EXPECT_FALSE(c.check_loss(14'499));
  EXPECT_TRUE(c.check_loss(14'500));
  EXPECT_FALSE(c.check_loss(20'000)) << "once per loss";
  (void)c.on_sync({0}, 21'000);
  EXPECT_FALSE(c.check_loss(22'000));
}

TEST(SyncConsumer, AConfiguredCounterMustStepByOne) {
  SyncConsumer c{1000, 3};
  c.set_counter_overflow(3);
  std::uint64_t t = 0;
  const auto next = [&](std::uint8_t counter) { return c.on_sync({counter}, t += 1000); };
  EXPECT_EQ(next(2), SyncEvent::in_order) << "the first counter is the reference";
  EXPECT_EQ(next(3), SyncEvent::in_order);
  EXPECT_EQ(next(1), SyncEvent::in_order) << "the wrap after 0x1019";
  EXPECT_EQ(next(1), SyncEvent::out_of_sequence) << "repeated";
  EXPECT_EQ(next(2), SyncEvent::in_order) << "the repeat became the reference: one error, not a run";
  EXPECT_EQ(next(1), SyncEvent::out_of_sequence) << "back";
  EXPECT_EQ(next(3), SyncEvent::out_of_sequence) << "skipped one";
  EXPECT_EQ(next(4), SyncEvent::out_of_range) << "beyond the overflow value";
  EXPECT_EQ(next(0), SyncEvent::unexpected_length) << "no counter at all";
  c.set_counter_overflow(1);  // 1 is no valid overflow (CiA 301 reserves it): no counter, as for 0
  EXPECT_EQ(next(0), SyncEvent::in_order);
  EXPECT_EQ(next(7), SyncEvent::unexpected_length);
}

TEST(SyncConsumer, TheRateAllowsTheLossPeriodsInExcessThenRefuses) {
  SyncConsumer c{1000, 3};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(c.on_sync({0}, 5'000), SyncEvent::in_order) << i;  // four at once: one + three extra
  }
  EXPECT_EQ(c.on_sync({0}, 5'000), SyncEvent::too_many);
  EXPECT_EQ(c.on_sync({0}, 5'999), SyncEvent::in_order) << "a period's credit (x 9/8) came back";
  EXPECT_EQ(c.on_sync({0}, 6'000), SyncEvent::too_many);
  // Receive time (rate) and owner's clock (loss) are separate: a SYNC read late but stamped on time.
  EXPECT_EQ(c.on_sync({0}, 50'000, 9'000), SyncEvent::in_order);
  EXPECT_FALSE(c.check_loss(54'499));
  // A receive clock that steps back restarts the bucket full instead of refusing.
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(c.on_sync({0}, 60'000, 100), SyncEvent::in_order) << i;
  }
  c.rearm_rate_check();
  EXPECT_EQ(c.on_sync({0}, 60'000, 100), SyncEvent::in_order) << "rearmed: full credit";
  // An absurd receive time (a corrupt or hostile timestamp) whose 9/8 would wrap 64 bits: full
  // credit, not a wrapped near-zero one.
  for (int i = 0; i < 3; ++i) {
    (void)c.on_sync({0}, 60'000, 100);
  }
  EXPECT_EQ(c.on_sync({0}, 60'000, 100 + 16'397'105'843'297'379'215ULL), SyncEvent::in_order);
  SyncConsumer off{0, 3};
  for (int i = 0; i < 100; ++i) {
    ASSERT_EQ(off.on_sync({0}, 1), SyncEvent::in_order) << "0x1006 = 0: no period to measure against";
  }
}

TEST(Emcy, FrameIsCodeRegisterAndFiveBytes) {
  const CanFrame f = encode_emcy(4, EmcyMessage{0x8611, 0x21, {1, 2, 3, 4, 5}});
  EXPECT_EQ(f.id, 0x84U);
  EXPECT_EQ(test::bytes_of(f), (Bytes{0x11, 0x86, 0x21, 1, 2, 3, 4, 5}));
  const auto e = decode_emcy(f);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->node, 4);
  EXPECT_EQ(e->message.error_code, 0x8611);
  CanFrame sync = f;
  sync.id = 0x80;
  EXPECT_FALSE(decode_emcy(sync)) << "0x80 is SYNC, not an EMCY of node 0";
  CanFrame short_frame = f;
  short_frame.len = 7;
  EXPECT_FALSE(decode_emcy(short_frame));
}

TEST(EmcyProducer, InhibitTimeHoldsTheNewestMessageBack) {
  EmcyProducer p{4, 1000};
  FrameBuffer<8> out;
  EXPECT_TRUE(p.emit({0x8100, 0x11, {}}, 0, out));
  EXPECT_FALSE(p.emit({0x8250, 0x11, {}}, 500, out));
  EXPECT_FALSE(p.emit({0x8611, 0x21, {}}, 600, out));
  EXPECT_TRUE(p.pending());
  EXPECT_FALSE(p.poll(999, out));
  EXPECT_TRUE(p.poll(1000, out));
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(decode_emcy(out[1])->message.error_code, 0x8611) << "the latest state wins";
}

TEST(EmcyConsumer, TracksTheNodesErrorStateUntilTheReset) {
  EmcyConsumer c{4};
  EXPECT_FALSE(c.on_frame(encode_emcy(5, {0x1000, 1, {}})));
  EXPECT_TRUE(c.on_frame(encode_emcy(4, {0x1000, 1, {}})));
  EXPECT_TRUE(c.in_error());
  EXPECT_TRUE(c.on_frame(encode_emcy(4, {0x0000, 0, {}})));
  EXPECT_FALSE(c.in_error());
  EXPECT_EQ(c.count(), 2U);
}

}  // namespace
}  // namespace settle::hal::canopen
