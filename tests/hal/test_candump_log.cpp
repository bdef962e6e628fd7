// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <string_view>
#include <utility>

#include "frame_helpers.hpp"
#include "settle/hal/candump_log.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/recording_bus.hpp"
#include "settle/hal/testing/fault_injecting_bus.hpp"

namespace settle::hal {
namespace {

std::string format(const CanFrame& f, const char* iface = "vcan0") {
  std::array<char, candump_line_max> buf{};
  const std::size_t n = format_candump_line(f, iface, buf);
  return {buf.data(), n};
}

std::optional<CandumpRecord> parse(std::string_view line) { return parse_candump_line({line.data(), line.size()}); }

TEST(CandumpLog, FormatsLikeCandumpMinusL) {
  CanFrame f = test::frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF});
  f.timestamp_us = 1'700'000'000'123'456ULL;
  EXPECT_EQ(format(f), "(1700000000.123456) vcan0 123#DEADBEEF");
  CanFrame ext = test::frame(0x1234567, {0x01});
  ext.flags = can_flag::extended;
  ext.timestamp_us = 5;
  EXPECT_EQ(format(ext), "(0000000000.000005) vcan0 01234567#01");
  CanFrame rtr{};
  rtr.id = 0x7FF;
  rtr.flags = can_flag::rtr;
  EXPECT_EQ(format(rtr, "can1"), "(0000000000.000000) can1 7FF#R");
  rtr.len = 4;
  EXPECT_EQ(format(rtr, "can1"), "(0000000000.000000) can1 7FF#R4");
  CanFrame fd = test::frame(0x80, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12});
  fd.flags = can_flag::fd | can_flag::brs;
  EXPECT_EQ(format(fd), "(0000000000.000000) vcan0 080##10102030405060708090A0B0C");
  EXPECT_EQ(format(test::frame(0x000, {}), ""), "") << "an interface name is required";
}

TEST(CandumpLog, ParsesWhatItFormats) {
  for (const std::string line : {"(1700000000.123456) vcan0 123#DEADBEEF", "(0000000001.000000) vcan0 701#05",
                                 "(0000000001.000000) can0 080#", "(0000000000.000005) vcan0 01234567#01",
                                 "(0000000000.000000) can1 7FF#R4", "(0000000000.000000) vcan0 080##30102030405060708090A0B0C"}) {
    const auto rec = parse(line);
    ASSERT_TRUE(rec) << line;
    EXPECT_EQ(format(rec->frame, rec->iface.data()), line);
  }
  const auto rec = parse("(1.000001) vcan0 181#0102\n");
  ASSERT_TRUE(rec);
  EXPECT_EQ(rec->frame.timestamp_us, 1'000'001U);
  EXPECT_EQ(rec->frame, test::frame(0x181, {1, 2}));
  EXPECT_STREQ(rec->iface.data(), "vcan0");
}

TEST(CandumpLog, RejectsMalformedLines) {
  for (const std::string line :
       {"", "garbage", "(1.5) vcan0 123#00", "(1.000000) vcan0 12#00", "(1.000000) vcan0 123#0",
        "(1.000000) vcan0 123#000102030405060708", "(1.000000) vcan0 123 00", "(1.000000) vcan0 800#00",
        "(1.000000) vcan0 20000000#00", "(1.000000) vcan0 123#00 trailing", "(1.000000)vcan0 123#00",
        "(1.000000) averyveryverylongifname 123#00"}) {
    EXPECT_FALSE(parse(line)) << '"' << line << '"';
  }
}

std::uint64_t fixed_clock() noexcept { return 42'000'001; }

// A log written from a RecordingBus holds exactly the frames its counters count: each sent frame
// (busy and refused ones never reached the wire), each received frame, in the order they passed.
TEST(RecordingBus, RecordsEverySentAndReceivedFrameInOrderAndNothingElse) {
  LoopbackHub hub;
  LoopbackBus<16> wire{hub};
  LoopbackBus<16> peer{hub};
  testing::FaultInjectingBus faulty{wire};
  RecordingBus<8> bus{faulty, fixed_clock};
  hub.set_time_us(7);
  ASSERT_EQ(bus.send(test::frame(0x080, {})), SendStatus::sent);
  faulty.fail_sends(1, SendStatus::busy);
  ASSERT_EQ(bus.send(test::frame(0x201, {1})), SendStatus::busy);
  faulty.fail_sends(1, SendStatus::error);
  ASSERT_EQ(bus.send(test::frame(0x201, {2})), SendStatus::error);
  ASSERT_EQ(bus.send(test::frame(0x201, {3})), SendStatus::sent);
  ASSERT_EQ(peer.send(test::frame(0x181, {4, 5})), SendStatus::sent);
  CanFrame got{};
  ASSERT_EQ(bus.receive(got), ReceiveStatus::received);
  ASSERT_EQ(bus.receive(got), ReceiveStatus::empty);

  EXPECT_EQ(bus.counters().sent, 2U);
  EXPECT_EQ(bus.counters().received, 1U);
  EXPECT_EQ(bus.recorded(), 3U);
  EXPECT_EQ(bus.overflows(), 0U);
  const std::array<std::pair<CanFrame, FrameDirection>, 3> expected{{{test::frame(0x080, {}), FrameDirection::sent},
                                                                     {test::frame(0x201, {3}), FrameDirection::sent},
                                                                     {test::frame(0x181, {4, 5}), FrameDirection::received}}};
  for (const auto& [frame, direction] : expected) {
    RecordedFrame r{};
    ASSERT_TRUE(bus.take(r));
    EXPECT_EQ(r.frame, frame);
    EXPECT_EQ(r.direction, direction);
    // Sent frames carry the given clock's time, received ones the backend's receive time.
    EXPECT_EQ(r.frame.timestamp_us, direction == FrameDirection::sent ? 42'000'001U : 7U);
  }
  RecordedFrame r{};
  EXPECT_FALSE(bus.take(r));
}

TEST(RecordingBus, AFullRingIsCountedAndTheFrameStillPasses) {
  LoopbackHub hub;
  LoopbackBus<16> wire{hub};
  LoopbackBus<16> peer{hub};
  RecordingBus<2> bus{wire};
  for (std::uint8_t i = 0; i < 3; ++i) ASSERT_EQ(bus.send(test::frame(0x201, {i})), SendStatus::sent);
  EXPECT_EQ(bus.recorded(), 2U);
  EXPECT_EQ(bus.overflows(), 1U);
  CanFrame got{};
  for (std::uint8_t i = 0; i < 3; ++i) {
    ASSERT_EQ(peer.receive(got), ReceiveStatus::received);
    EXPECT_EQ(got, test::frame(0x201, {i})) << "the unrecorded frame was sent all the same";
  }
  RecordedFrame r{};
  ASSERT_TRUE(bus.take(r));
  EXPECT_EQ(r.frame.timestamp_us, 0U) << "no clock given";
  ASSERT_TRUE(bus.take(r));
  EXPECT_EQ(r.frame, test::frame(0x201, {1}));
  EXPECT_FALSE(bus.take(r));
  ASSERT_EQ(bus.send(test::frame(0x201, {9})), SendStatus::sent);
  EXPECT_EQ(bus.recorded(), 3U) << "room again once taken";
}

}  // namespace
}  // namespace settle::hal
