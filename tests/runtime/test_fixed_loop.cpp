// SPDX-License-Identifier: Apache-2.0
// The servo loop with fixed-point evaluation (integer-only per tick, for cores without an FPU):
// against the double loop on the same moves it streams the same targets to within one count, ends
// exactly on target, and refuses at submit what its formats cannot hold, changing nothing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "settle/runtime/servo_loop.hpp"
#include "settle/hal/testing/ideal_drive.hpp"

using namespace settle;

namespace {

template <typename Loop>
std::vector<std::int32_t> stream_once(const core::Move<double>& m, runtime::LoopStatus& st, core::Status& why) {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  hal::testing::IdealDrive<> drive{hub, hal::canopen::DriveNodeConfig{}};
  std::vector<std::int32_t> record(1 << 16);
  drive.record_applied(record);
  Loop loop{master, 1000};
  runtime::AxisConfig a{};
  a.vmax = 5.0;
  EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::ok);
  std::uint64_t now = 0;
  drive.start(now);
  loop.start(now);
  auto tick = [&] {
    now += 1000;
    hub.set_time_us(now);
    loop.tick(now);
    drive.process(now);
  };
  for (int i = 0; i < 2000 && !loop.ready(0); ++i) tick();
  EXPECT_TRUE(loop.ready(0));
  drive.clear_applied();
  st = loop.submit(0, m, &why);
  const auto n = static_cast<int>(m.duration() * 1000) + 20;
  for (int i = 0; i < n; ++i) tick();
  EXPECT_FALSE(drive.applied_truncated());
  return {drive.applied().begin(), drive.applied().end()};
}

core::Move<double> plan(core::ProfileKind k, double d, double t, core::ShaperKind s = core::ShaperKind::none,
                        double omega = 22.04871) {
  core::MoveRequest r{};
  r.profile = k;
  r.distance = d;
  r.time = t;
  r.set_mode(omega);
  r.shaper = s;
  core::Move<double> m{};
  EXPECT_EQ(core::plan(r, m), core::Status::ok);
  return m;
}

using DoubleLoop = runtime::ServoLoop<double, 1, 2>;
using FixedLoop = runtime::ServoLoop<double, 1, 2, runtime::FixedEvaluation>;

TEST(FixedLoop, StreamsTheDoubleLoopsTargetsWithinOneCount) {
  for (const auto& m : {plan(core::ProfileKind::scurve, 0.07, 0.228), plan(core::ProfileKind::scurve_damped, -0.3, 0.9),
                        plan(core::ProfileKind::poly345, 0.5, 0.4),
                        plan(core::ProfileKind::scurve, 0.2, 0.5, core::ShaperKind::zvd)}) {
    runtime::LoopStatus sd{}, sf{};
    core::Status wd{}, wf{};
    const auto d = stream_once<DoubleLoop>(m, sd, wd);
    const auto f = stream_once<FixedLoop>(m, sf, wf);
    ASSERT_EQ(sd, runtime::LoopStatus::ok);
    ASSERT_EQ(sf, runtime::LoopStatus::ok) << core::to_string(wf);
    ASSERT_EQ(d.size(), f.size());
    int worst = 0;
    for (std::size_t i = 0; i < d.size(); ++i) worst = std::max(worst, std::abs(d[i] - f[i]));
    EXPECT_LE(worst, 1) << core::to_string(m.profile().kind());
    const auto target = static_cast<std::int32_t>(std::llround(m.distance() * 1e6));
    EXPECT_EQ(f.back(), target);
    EXPECT_EQ(d.back(), target);
  }
}

TEST(FixedLoop, RefusesAtSubmitWhatItsFormatsCannotHold) {
  // Transitions shorter than one tick cannot be represented on the tick grid. (A stiff 1 kHz mode
  // keeps this 3 ms move's peaks modest, so it is the evaluator that refuses, not the velocity check.)
  const core::Move<double> m = plan(core::ProfileKind::scurve, 0.001, 0.003, core::ShaperKind::none, 6000.0);
  ASSERT_LT(m.peaks().v, 5.0);
  runtime::LoopStatus st{};
  core::Status why{};
  const auto applied = stream_once<FixedLoop>(m, st, why);
  EXPECT_EQ(st, runtime::LoopStatus::evaluation_refused);
  EXPECT_EQ(why, core::Status::transition_shorter_than_tick);
  // the axis held where it was, every period of the run
  EXPECT_EQ(applied.size(), static_cast<std::size_t>(m.duration() * 1000) + 20);
  for (const auto a : applied) EXPECT_EQ(a, 0);
}

// The loop's fixed-point slot holds a position plan of 24 intervals: a four-impulse shaper on a
// seven-segment jerk-limited move needs up to 4 x 8 - 1 = 31, so it is refused at submit (nothing
// streamed), and a loop built with room for any Motion (35) streams it like the double loop.
TEST(FixedLoop, RefusesAMoveBeyondItsPlanAndALargerPlanStreamsIt) {
  core::MoveRequest r{};
  r.profile = core::ProfileKind::jerk_limited;
  r.distance = 0.2;
  r.limits.vmax = 0.5;
  r.limits.amax = 2.0;
  r.limits.jmax = 20.0;
  r.set_mode(22.04871);
  r.shaper = core::ShaperKind::zvdd;
  core::Move<double> m{};
  ASSERT_EQ(core::plan(r, m), core::Status::ok);
  ASSERT_EQ(m.shaper().count, 4U);
  runtime::LoopStatus st{};
  core::Status why{};
  const auto refused = stream_once<FixedLoop>(m, st, why);
  EXPECT_EQ(st, runtime::LoopStatus::evaluation_refused);
  EXPECT_EQ(why, core::Status::table_too_small);
  EXPECT_EQ(refused.size(), static_cast<std::size_t>(m.duration() * 1000) + 20);
  for (const auto a : refused) EXPECT_EQ(a, 0);

  using RoomyLoop = runtime::ServoLoop<double, 1, 2, runtime::BasicFixedEvaluation<35>>;
  runtime::LoopStatus sd{}, sf{};
  const auto d = stream_once<DoubleLoop>(m, sd, why);
  const auto f = stream_once<RoomyLoop>(m, sf, why);
  ASSERT_EQ(sd, runtime::LoopStatus::ok);
  ASSERT_EQ(sf, runtime::LoopStatus::ok) << core::to_string(why);
  ASSERT_EQ(d.size(), f.size());
  int worst = 0;
  for (std::size_t i = 0; i < d.size(); ++i) worst = std::max(worst, std::abs(d[i] - f[i]));
  EXPECT_LE(worst, 1);
  EXPECT_EQ(f.back(), 200000);
}

}  // namespace
