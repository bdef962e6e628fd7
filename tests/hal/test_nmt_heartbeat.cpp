// SPDX-License-Identifier: Apache-2.0
// NMT commands and states, and heartbeat production and consumption on a virtual clock.
#include <gtest/gtest.h>

#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/nmt.hpp"

namespace settle::hal::canopen {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(Nmt, CommandFramesAreTwoBytesOnIdZero) {
  const CanFrame start = encode_nmt(NmtCommand::start, 5);
  EXPECT_EQ(start.id, 0U);
  EXPECT_EQ(test::bytes_of(start), (Bytes{0x01, 0x05}));
  EXPECT_EQ(test::bytes_of(encode_nmt(NmtCommand::reset_node, 0)), (Bytes{0x81, 0x00}));
  const auto m = decode_nmt(encode_nmt(NmtCommand::enter_pre_operational, 9));
  ASSERT_TRUE(m);
  EXPECT_EQ(m->command, NmtCommand::enter_pre_operational);
  EXPECT_EQ(m->node, 9);
}

TEST(NmtSlave, BootsToPreOperationalAndAnnouncesItWithBootUp) {
  NmtSlave slave{7};
  FrameBuffer<4> out;
  slave.boot(out);
  EXPECT_EQ(slave.state(), NmtState::pre_operational);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].id, 0x707U);
  EXPECT_EQ(test::bytes_of(out[0]), (Bytes{0x00}));
}

TEST(NmtSlave, FollowsCommandsForItselfAndForAllNodes) {
  NmtSlave slave{7};
  FrameBuffer<4> out;
  slave.boot(out);
  EXPECT_EQ(slave.on_message({NmtCommand::start, 8}, out), NmtEvent::none);
  EXPECT_EQ(slave.state(), NmtState::pre_operational);
  EXPECT_EQ(slave.on_message({NmtCommand::start, 7}, out), NmtEvent::state_changed);
  EXPECT_EQ(slave.state(), NmtState::operational);
  EXPECT_TRUE(slave.pdo_allowed());
  EXPECT_EQ(slave.on_message({NmtCommand::stop, 0}, out), NmtEvent::state_changed);
  EXPECT_EQ(slave.state(), NmtState::stopped);
  EXPECT_FALSE(slave.sdo_allowed());
  EXPECT_EQ(slave.on_message({NmtCommand::stop, 0}, out), NmtEvent::none);
  out.clear();
  EXPECT_EQ(slave.on_message({NmtCommand::reset_communication, 7}, out), NmtEvent::reset_communication);
  EXPECT_EQ(slave.state(), NmtState::pre_operational);
  EXPECT_EQ(out.size(), 1U) << "a reset ends with a new boot-up";
  EXPECT_EQ(slave.on_message({NmtCommand::reset_node, 0}, out), NmtEvent::reset_application);
}

TEST(Heartbeat, FrameCarriesTheNmtState) {
  const CanFrame hb = encode_heartbeat(0x7F, NmtState::operational);
  EXPECT_EQ(hb.id, 0x77FU);
  EXPECT_EQ(test::bytes_of(hb), (Bytes{0x05}));
  const auto decoded = decode_heartbeat(hb);
  ASSERT_TRUE(decoded);
  EXPECT_EQ(decoded->node, 0x7F);
  EXPECT_EQ(decoded->state, NmtState::operational);
}

TEST(HeartbeatProducer, SendsEveryPeriodWithoutCatchingUp) {
  HeartbeatProducer p{3, 100};
  FrameBuffer<16> out;
  p.start(100'000);
  EXPECT_FALSE(p.poll(99'999, NmtState::operational, out));
  EXPECT_TRUE(p.poll(100'000, NmtState::operational, out));
  EXPECT_FALSE(p.poll(150'000, NmtState::operational, out));
  EXPECT_TRUE(p.poll(455'000, NmtState::operational, out)) << "late: one heartbeat, not three";
  EXPECT_FALSE(p.poll(499'999, NmtState::operational, out));
  EXPECT_TRUE(p.poll(500'000, NmtState::operational, out));
  EXPECT_EQ(out.size(), 3U);
}

TEST(HeartbeatConsumer, TimesOutExactlyOnceAtTheDeadline) {
  HeartbeatConsumer c{3, 150};
  EXPECT_EQ(c.poll(10'000'000), HeartbeatEvent::none) << "monitoring starts with the first heartbeat";
  EXPECT_EQ(c.on_frame(encode_heartbeat(3, NmtState::pre_operational), 1'000), HeartbeatEvent::alive);
  EXPECT_EQ(c.on_frame(encode_heartbeat(3, NmtState::operational), 100'000), HeartbeatEvent::state_changed);
  EXPECT_EQ(c.poll(249'999), HeartbeatEvent::none);
  EXPECT_EQ(c.poll(250'000), HeartbeatEvent::lost);
  EXPECT_FALSE(c.alive());
  EXPECT_EQ(c.poll(900'000), HeartbeatEvent::none) << "reported once";
  EXPECT_EQ(c.on_frame(encode_heartbeat(3, NmtState::operational), 950'000), HeartbeatEvent::alive);
  EXPECT_EQ(c.on_frame(encode_heartbeat(3, NmtState::initialising), 960'000), HeartbeatEvent::boot_up);
}

TEST(HeartbeatConsumer, TheLongestTimeoutIsKeptWholeInMicroseconds) {
  // 0x1016's largest timeout, 65 535 ms, is 65 535 000 us: held in 32 bits (as the consumer keeps
  // it, converted when configured), it neither wraps nor loses its top bits. Also after configure().
  HeartbeatConsumer c{3, 1};
  c.configure(3, 65'535);
  constexpr std::uint64_t t0 = 5'000'000'000ULL;  // far past 2^32 us: the deadline is 64-bit
  EXPECT_EQ(c.on_state(NmtState::operational, t0), HeartbeatEvent::alive);
  EXPECT_EQ(c.poll(t0 + 65'534'999), HeartbeatEvent::none);
  EXPECT_EQ(c.poll(t0 + 65'535'000), HeartbeatEvent::lost);
  HeartbeatConsumer d{3, 65'535};
  EXPECT_EQ(d.on_state(NmtState::operational, t0), HeartbeatEvent::alive);
  EXPECT_EQ(d.poll(t0 + 65'534'999), HeartbeatEvent::none);
  EXPECT_EQ(d.poll(t0 + 65'535'000), HeartbeatEvent::lost);
}

TEST(HeartbeatConsumer, AStateFromAMatchedFrameCountsAsTheFrameWould) {
  // Two consumers fed the same heartbeats, one through on_frame and one through on_state (what a
  // master that matched the identifier itself calls): the same events, the same liveness.
  HeartbeatConsumer by_frame{3, 150};
  HeartbeatConsumer by_state{3, 150};
  const std::pair<std::uint64_t, NmtState> seq[] = {{1'000, NmtState::pre_operational},
                                                    {50'000, NmtState::pre_operational},
                                                    {100'000, NmtState::operational},
                                                    {400'000, NmtState::operational},
                                                    {410'000, NmtState::initialising}};
  for (const auto& [t, st] : seq) {
    EXPECT_EQ(by_frame.poll(t), by_state.poll(t)) << t;
    EXPECT_EQ(by_frame.on_frame(encode_heartbeat(3, st), t), by_state.on_state(st, t)) << t;
    EXPECT_EQ(by_frame.alive(), by_state.alive()) << t;
    EXPECT_EQ(by_frame.state(), by_state.state()) << t;
  }
}

TEST(HeartbeatConsumer, IgnoresOtherNodesAndMalformedFrames) {
  HeartbeatConsumer c{3, 150};
  EXPECT_EQ(c.on_frame(encode_heartbeat(4, NmtState::operational), 0), HeartbeatEvent::none);
  CanFrame bad = encode_heartbeat(3, NmtState::operational);
  bad.data[0] = 0x85;  // toggle bit: node guarding, not heartbeat
  EXPECT_EQ(c.on_frame(bad, 0), HeartbeatEvent::none);
  bad.data[0] = 0x06;  // no such state
  EXPECT_EQ(c.on_frame(bad, 0), HeartbeatEvent::none);
  bad = encode_heartbeat(3, NmtState::operational);
  bad.len = 2;
  EXPECT_EQ(c.on_frame(bad, 0), HeartbeatEvent::none);
  EXPECT_FALSE(c.state());
}

}  // namespace
}  // namespace settle::hal::canopen
