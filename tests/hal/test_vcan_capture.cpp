// SPDX-License-Identifier: Apache-2.0
// BusCapture on a real (virtual) CAN interface: every frame any socket sends, in the kernel's
// order with its timestamps never stepping back; a queue that overflows counted, never silent.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "settle/hal/bus_capture.hpp"
#include "settle/hal/candump_log.hpp"
#include "vcan_support.hpp"

namespace settle::hal {
namespace {

class VcanCapture : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::vcan_present()) GTEST_SKIP() << test::vcan_missing;
  }
  static std::string path(const char* name) { return std::string{SETTLE_HAL_TEST_OUTPUT_DIR} + "/" + name; }
  static std::vector<CanFrame> read_log(const std::string& file) {
    std::vector<CanFrame> frames;
    std::ifstream in{file};
    for (std::string line; std::getline(in, line);) {
      const auto r = parse_candump_line(std::span<const char>{line.data(), line.size()});
      EXPECT_TRUE(r.has_value()) << "not a candump line: " << line;
      if (r) frames.push_back(r->frame);
    }
    return frames;
  }
};

TEST_F(VcanCapture, HoldsEveryFrameOfEverySocketInOrderWithKernelTimestamps) {
  const std::string log = path("capture-order.log");
  BusCapture capture;
  ASSERT_EQ(capture.start(test::vcan_interface, log), "");
  // Two senders (two nodes, say), interleaved in a known order, a few thousand frames: more than
  // one drain interval's worth on any host.
  SocketCanBus a;
  SocketCanBus b;
  ASSERT_EQ(a.open(test::vcan_interface), OpenStatus::ok);
  ASSERT_EQ(b.open(test::vcan_interface), OpenStatus::ok);
  std::vector<std::pair<std::uint32_t, std::uint64_t>> sent;
  for (std::uint64_t n = 0; n < 3000; ++n) {
    SocketCanBus& bus = n % 3 == 0 ? b : a;
    const std::uint32_t id = n % 3 == 0 ? 0x701 : 0x181;
    SendStatus s = bus.send(test::counted_frame(id, n));
    while (s == SendStatus::busy) s = bus.send(test::counted_frame(id, n));
    ASSERT_EQ(s, SendStatus::sent);
    sent.emplace_back(id, n);
  }
  const BusCaptureResult r = capture.stop();
  EXPECT_TRUE(r.complete()) << r.error << ", " << r.kernel_drops << " dropped";
  EXPECT_EQ(r.frames, sent.size());
  EXPECT_EQ(r.steps_back, 0U);
  const std::vector<CanFrame> got = read_log(log);
  ASSERT_EQ(got.size(), sent.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].id, sent[i].first) << "frame " << i;
    ASSERT_EQ(test::count_of(got[i]), sent[i].second) << "frame " << i;
    if (i > 0) {
      ASSERT_GE(got[i].timestamp_us, got[i - 1].timestamp_us) << "frame " << i << " steps back";
    }
  }
  EXPECT_EQ(got.front().timestamp_us, r.first_us);
  EXPECT_EQ(got.back().timestamp_us, r.last_us);
  EXPECT_EQ(capture.stop().frames, r.frames) << "stop() once; later calls give the same result";
}

TEST_F(VcanCapture, AQueueThatOverflowsIsCountedNotSilent) {
  // The smallest queue the kernel allows, and a drain that comes only at stop(): frames must be
  // dropped, and every frame sent is either in the log or counted as dropped.
  BusCaptureOptions slow{};
  slow.receive_buffer_bytes = 1;
  slow.drain_interval_ms = 10'000;
  const std::string log = path("capture-overflow.log");
  BusCapture capture;
  ASSERT_EQ(capture.start(test::vcan_interface, log, slow), "");
  SocketCanBus tx;
  ASSERT_EQ(tx.open(test::vcan_interface), OpenStatus::ok);
  for (std::uint64_t n = 0; n < 5000; ++n) ASSERT_NE(tx.send(test::counted_frame(0x55, n)), SendStatus::error);
  const BusCaptureResult r = capture.stop();
  EXPECT_FALSE(r.complete());
  EXPECT_GT(r.kernel_drops, 0U);
  EXPECT_EQ(r.frames + r.kernel_drops, tx.counters().sent);
  EXPECT_EQ(read_log(log).size(), r.frames);
  std::printf("[ vcan ] %llu sent, %llu captured, %llu dropped and counted\n",
              static_cast<unsigned long long>(tx.counters().sent), static_cast<unsigned long long>(r.frames),
              static_cast<unsigned long long>(r.kernel_drops));
}

TEST_F(VcanCapture, RefusesWhatItCannotCaptureSayingWhy) {
  BusCapture capture;
  EXPECT_EQ(capture.start("settle-no-such-can0", path("capture-none.log")),
            "cannot open settle-no-such-can0: " + std::string{to_string(OpenStatus::no_such_interface)});
  EXPECT_FALSE(capture.running());
  BusCaptureOptions bad{};
  bad.drain_interval_ms = 0;
  EXPECT_EQ(capture.start(test::vcan_interface, path("capture-none.log"), bad), "the drain interval must be 1..10000 ms");
  EXPECT_EQ(capture.start(test::vcan_interface, path("no-such-dir/capture.log")),
            "cannot write " + path("no-such-dir/capture.log"));
  EXPECT_FALSE(capture.running());
}

}  // namespace
}  // namespace settle::hal
