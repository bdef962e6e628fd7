// SPDX-License-Identifier: Apache-2.0
// The simulated drive's log is bounded and streamed (`settle plant` runs for hours at one record
// per SYNC), and the offline replica of a streamed move refuses sizes beyond limits.hpp before
// allocating. Allocations are counted by heap_counter.hpp.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>

#include "heap_counter.hpp"
#include "planned_moves.hpp"
#include "scratch.hpp"
#include "settle/core/planner.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/plant/limits.hpp"
#include "settle/testbed/plant_node.hpp"
#include "settle/testbed/stream_check.hpp"
#include "settle/testbed/sync_log.hpp"

namespace settle::testbed {
namespace {

class Discard final : public hal::FrameSink {
 public:
  [[nodiscard]] bool put(const hal::CanFrame&) noexcept override { return true; }
};

plant::ModalPlant beam() {
  plant::ModalPlant p;
  EXPECT_EQ(plant::ModalPlant::make_beam(plant::BeamOptions{}, p), plant::SimStatus::ok);
  return p;
}

using testing::poly345;

TEST(PlantNodeLog, ManySyncsAllocateNothingAndTheFileHoldsEveryRecord) {
  const std::string path = settle::test::scratch_path("plant_log.csv");
  DriveAxis axis;
  ASSERT_EQ(DriveAxis::make(DriveAxisConfig{}, beam(), 0, axis), plant::SimStatus::ok);
  hal::canopen::DriveNodeConfig dc{};
  dc.node = 1;
  dc.sync_period_us = 1000;
  constexpr std::size_t kCapacity = 64;
  PlantNode pn{dc, std::move(axis), kCapacity};
  SyncCsvLog log;
  ASSERT_TRUE(log.open(path, plant::PositionUnit::m));
  pn.set_sink(&log);
  Discard out;
  pn.start(0, out);
  hal::CanFrame sync{};
  sync.id = 0x80;
  // Warm-up: the plant's transition for this period is computed and cached on the first SYNC.
  constexpr std::uint64_t kWarm = 10, kSyncs = 200'000;  // three times what the old log reserved
  std::uint64_t t = 0;
  for (std::uint64_t i = 0; i < kWarm; ++i) ASSERT_TRUE(pn.on_frame(sync, t += 1000, out));
  const std::uint64_t before = g_allocations.load();
  bool all_syncs = true;
  for (std::uint64_t i = kWarm; i < kSyncs; ++i) all_syncs = pn.on_frame(sync, t += 1000, out) && all_syncs;
  const std::uint64_t allocated = g_allocations.load() - before;
  EXPECT_TRUE(all_syncs);
  EXPECT_EQ(allocated, 0u);
  EXPECT_EQ(pn.syncs(), kSyncs);
  EXPECT_EQ(pn.log().capacity(), kCapacity);
  ASSERT_EQ(pn.log().size(), kCapacity);
  EXPECT_EQ(pn.log().front().sync, kSyncs - kCapacity);  // the last kCapacity records, in order
  EXPECT_EQ(pn.log().back().sync, kSyncs - 1);
  EXPECT_EQ(log.records(), kSyncs);
  ASSERT_TRUE(log.close());

  // The file: the header, then one line per SYNC with its index, in order.
  std::ifstream f{path};
  std::string line;
  ASSERT_TRUE(std::getline(f, line));
  EXPECT_EQ(line, "sync_index,time_us,following_flag,target_counts,position_actual_counts,velocity_actual_counts_per_s,"
                  "load_position_counts,load_m,base_m");
  std::uint64_t n = 0;
  while (std::getline(f, line)) {
    const std::string expected_prefix = std::to_string(n) + "," + std::to_string((n + 1) * 1000) + ",";
    if (line.rfind(expected_prefix, 0) != 0) {
      ADD_FAILURE() << "line " << n << ": " << line;
      break;
    }
    ++n;
  }
  EXPECT_EQ(n, kSyncs);
  std::filesystem::remove(path);
}

// settle plant's axis advances one period per SYNC: a replay that catches up with a burst of
// SYNC + RPDO pairs, all received at one instant and moving twice the drive's step limit in all,
// has every setpoint applied as sent (tests/cross/servo-replay checks exactly that). A drive in
// processing time would hold this burst to one step limit (DriveSafety, step window).
TEST(PlantNode, ABurstOfPairsAtOneInstantIsAppliedSetpointBySetpoint) {
  namespace co = hal::canopen;
  DriveAxis axis;
  ASSERT_EQ(DriveAxis::make(DriveAxisConfig{}, beam(), 0, axis), plant::SimStatus::ok);
  co::DriveNodeConfig dc{};
  dc.node = 1;
  dc.heartbeat_period_ms = 0;
  PlantNode pn{dc, std::move(axis), 1024};
  Discard out;
  pn.start(0, out);
  std::uint64_t t = 0;
  const auto pair = [&](std::uint16_t cw, std::int32_t target, std::uint64_t at) {
    hal::CanFrame rpdo = co::encode_rpdo1(1, co::Rpdo1{cw, target});
    hal::CanFrame sync = co::encode_sync();
    rpdo.timestamp_us = sync.timestamp_us = at;
    (void)pn.on_frame(rpdo, at, out);
    return pn.on_frame(sync, at, out);
  };
  (void)pn.on_frame(co::encode_nmt(co::NmtCommand::start, 1), t, out);
  for (const std::uint16_t cw : {co::controlword::shutdown, co::controlword::switch_on, co::controlword::enable_operation}) {
    ASSERT_TRUE(pair(cw, 0, t += 1000));
  }
  const std::int64_t limit = pn.node().step_limit_counts();
  const auto step = static_cast<std::int32_t>(limit / 10);
  t += 1000;
  for (std::int32_t k = 1; k <= 20; ++k) {
    ASSERT_TRUE(pair(co::controlword::enable_operation, step * k, t)) << k;  // one instant
    ASSERT_EQ(pn.log().back().target, step * k) << k;
  }
  EXPECT_EQ(pn.node().counters().steps_bounded, 0U);
}

TEST(PlantNodeLog, UnwritableLogIsRefusedAtOpen) {
  SyncCsvLog log;
  EXPECT_FALSE(log.open("/nonexistent-dir/settle/log.csv", plant::PositionUnit::m));
  EXPECT_FALSE(log.close());
}

TEST(StreamCheck, SetpointsEndOnTheTargetAndAreCountedExactly) {
  // 0.5 s at 1 ms: ticks 0 .. 500, the last one exactly on D = 0.1 m = 100 000 counts.
  std::vector<std::int32_t> sp;
  ASSERT_EQ(stream_setpoints(poly345(0.1, 0.5), {1e6, 1000}, 7, sp), plant::SimStatus::ok);
  ASSERT_EQ(sp.size(), 501u);
  EXPECT_EQ(sp.front(), 7);
  EXPECT_EQ(sp.back(), 100'007);
}

TEST(StreamCheck, SizesAreCheckedBeforeAllocating) {
  std::vector<std::int32_t> sp;
  // 11 s at 1 us: 1.1e7 setpoints.
  EXPECT_EQ(stream_setpoints(poly345(0.1, 11.0), {1e6, 1}, 0, sp), plant::SimStatus::too_many_samples);
  EXPECT_EQ(stream_setpoints(poly345(0.1, 0.5), {1e6, 0}, 0, sp), plant::SimStatus::non_positive_step);
  EXPECT_EQ(stream_setpoints(poly345(0.1, 0.5), {0.0, 1000}, 0, sp), plant::SimStatus::non_positive_scale);
  EXPECT_TRUE(sp.empty());

  const plant::ModalPlant p = beam();
  const std::vector<std::int32_t> few = {0, 10, 20};
  Replay r;
  const std::uint64_t before = g_allocations.load();
  const plant::SimStatus refused = replay_stream(DriveAxisConfig{}, p, 0, few, plant::kMaxSamples, r);
  const std::uint64_t allocated = g_allocations.load() - before;
  EXPECT_EQ(refused, plant::SimStatus::too_many_samples);
  EXPECT_EQ(allocated, 0u);  // refused before the axis or the replay was made
  // Within the bound: three setpoint periods, then the window's other four.
  ASSERT_EQ(replay_stream(DriveAxisConfig{}, p, 0, few, 5, r), plant::SimStatus::ok);
  EXPECT_EQ(r.feedback.size(), 3u + 4u);

  // The fit's matrix: samples x 2 per mode (the beam's three modes are all below Nyquist at 1 ms).
  const std::vector<std::int32_t> loads(plant::kMaxFitEntries / 6 + 1, 0);
  SampledResidual s;
  EXPECT_EQ(fitted_residual(loads, 1e6, 0.0, 1e-3, p, 1.0, s), plant::SimStatus::too_many_samples);
  EXPECT_EQ(fitted_residual(std::span<const std::int32_t>{loads}.first(1000), 1e6, 0.0, 1e-3, p, 1.0, s),
            plant::SimStatus::ok);
  EXPECT_EQ(s.amplitude, 0.0);  // at rest
}

}  // namespace
}  // namespace settle::testbed
