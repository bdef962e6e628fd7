// SPDX-License-Identifier: Apache-2.0
// The position plan and its stepper (the servo loop's per-tick fixed-point path) on chosen moves:
// the beam move at every tick, rest before the start and on target after the end, shaped tracks
// merged on their own boundaries, refusal without side effects, restart, and the two fallbacks
// (the 53-bit rotation constant for large sinusoids, intervals split for the drift budget).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "fixed_cases.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/position.hpp"

using namespace settle;
using core::ProfileKind;
using core::Status;
using core::fixed::Motion;
using core::fixed::PositionInterval;
using core::fixed::PositionPlan;
using core::fixed::PositionStepper;
using core::fixed::Scale;

using test::planned;

namespace {

// Every tick at which some track of `m` enters a segment or ends, below the move's end: where an
// interval must start, computed from the motion's own fields.
std::vector<std::int32_t> track_boundaries(const Motion& m) {
  std::vector<std::int32_t> out;
  for (unsigned t = 0; t < m.header().tracks; ++t) {
    const auto& tr = m.track(t);
    for (unsigned k = 0; k <= m.header().segments; ++k) {
      const std::int64_t edge = k < m.header().segments ? m.segment(k).start : m.header().end;
      const auto b = static_cast<std::int32_t>(tr.delay + ((edge + tr.frac + 0xFFFFFFFFLL) >> 32));
      if (b < m.end_tick()) out.push_back(b);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<std::int32_t> interval_starts(const PositionPlan& p) {
  std::vector<std::int32_t> out;
  for (unsigned k = 0; k < p.header().intervals; ++k) out.push_back(p.interval(k).first);
  return out;
}

}  // namespace

// Seed 000's beam move (the servo images' pinned move, 50 mm in 0.8 Tn): one interval per segment,
// every tick within one count of at_tick() and of the double evaluator (at_tick's half count plus
// the 1/16-count drift budget).
TEST(FixedPosition, BeamMoveAtEveryTick) {
  const auto m = planned(ProfileKind::scurve, 0.05, 0.8 * 6.283185307179586 / 22.04871, 22.04871);
  const Scale s{{1e6, 1000}, 16, 16};
  Motion fm{};
  ASSERT_EQ(fm.build(m, s), Status::ok);
  PositionPlan plan{};
  ASSERT_EQ(plan.build(fm), Status::ok);
  EXPECT_EQ(plan.header().intervals, fm.header().segments);  // unshaped: the segments themselves
  EXPECT_EQ(plan.end_tick(), fm.end_tick());
  EXPECT_EQ(plan.target(), fm.target());
  PositionStepper st{plan};
  int identical = 0;
  for (std::int32_t n = 0; n <= fm.end_tick() + 1; ++n) {
    const std::int32_t p = st.next(), a = fm.at_tick(n).p;
    EXPECT_LE(std::abs(p - a), 1) << n;
    identical += p == a ? 1 : 0;
    EXPECT_LE(std::fabs(p - m.at(n * 1e-3).p * 1e6), 0.5 + 1.0 / 16 + 1e-6) << n;
  }
  EXPECT_GE(identical, fm.end_tick() * 99 / 100);
}

TEST(FixedPosition, ZeroBeforeTheStartAndExactlyOnTargetAfterTheEnd) {
  const auto m = planned(ProfileKind::scurve_damped, -0.0421, 0.37, 30.0, 0.12, core::ShaperKind::zv);
  Motion fm{};
  ASSERT_EQ(fm.build(m, Scale{{1e6, 1000}, 16, 16}), Status::ok);
  PositionPlan plan{};
  ASSERT_EQ(plan.build(fm), Status::ok);
  ASSERT_EQ(plan.target(), -42100);
  PositionStepper st{plan};
  for (std::int32_t n : {plan.end_tick(), plan.end_tick() + 1, INT32_MAX}) {
    st.restart(n);
    EXPECT_EQ(st.next(), -42100) << n;
    EXPECT_EQ(st.next(), -42100) << n;
  }
  EXPECT_EQ(st.tick(), INT32_MAX);  // saturates instead of overflowing
  for (std::int32_t n : {-1, -1000, INT32_MIN}) {
    st.restart(n);
    EXPECT_EQ(st.next(), 0) << n;
  }
  st.restart(-5);  // walks from rest into the first interval
  for (std::int32_t n = -5; n <= 3; ++n) EXPECT_EQ(st.next(), fm.at_tick(n).p) << n;
}

// A ZVD-shaped move whose impulses fall between ticks: the intervals start exactly on the union of
// every track's boundaries, and there the stepper is at_tick() bit for bit (its state is the very
// sum at_tick() forms); restarting at any tick gives what the uninterrupted run gives.
TEST(FixedPosition, ShapedTracksMergeOnTheirBoundaries) {
  const double omega = 3.141592653589793 / (12.37e-3);
  const auto m = planned(ProfileKind::scurve_damped, 0.05, 0.2, omega * 1.3, 0.05, core::ShaperKind::zvd);
  Motion fm{};
  ASSERT_EQ(fm.build(m, Scale{{1e6, 1000}, 16, 16}), Status::ok);
  ASSERT_EQ(fm.header().tracks, 3U);
  PositionPlan plan{};
  ASSERT_EQ(plan.build(fm), Status::ok);
  const std::vector<std::int32_t> starts = interval_starts(plan);
  EXPECT_EQ(starts, track_boundaries(fm));
  EXPECT_LE(starts.size(), core::fixed::position_intervals_for(fm.header().segments, fm.header().tracks));

  std::vector<std::int32_t> run;
  PositionStepper st{plan, -2};
  for (std::int32_t n = -2; n <= plan.end_tick() + 2; ++n) run.push_back(st.next());
  for (std::int32_t n : starts) EXPECT_EQ(run[static_cast<std::size_t>(n + 2)], fm.at_tick(n).p) << n;
  for (std::int32_t n = -2; n <= plan.end_tick() + 2; ++n) {
    const std::int32_t at = fm.at_tick(n).p;
    EXPECT_LE(std::abs(run[static_cast<std::size_t>(n + 2)] - at), 1) << n;
    st.restart(n);
    EXPECT_EQ(st.next(), run[static_cast<std::size_t>(n + 2)]) << n;
  }
}

TEST(FixedPosition, RefusesWhatItCannotHoldAndChangesNothing) {
  const auto a = planned(ProfileKind::scurve, 0.05, 0.3, 22.0);
  const auto b = planned(ProfileKind::scurve, 0.05, 0.3, 22.0, 0.0, core::ShaperKind::zvd);
  Motion ma{}, mb{};
  ASSERT_EQ(ma.build(a, Scale{}), Status::ok);
  ASSERT_EQ(mb.build(b, Scale{}), Status::ok);
  core::fixed::BasicPositionPlan<8> plan{};
  ASSERT_EQ(plan.build(ma), Status::ok);
  ASSERT_GT(track_boundaries(mb).size(), 8U);
  const auto before = plan;
  EXPECT_EQ(plan.build(mb), Status::table_too_small);
  EXPECT_EQ(std::memcmp(&before, &plan, sizeof plan), 0);
}

// A sinusoid of 10^8 counts: rounding the recurrence's constant to 32 bits would drift by up to
// 2 pi |Z| 2^-33 ~ 0.07 count over a segment, over the 1/16 budget, so the builder keeps it to 53
// bits (two products per tick) there; every tick stays within one count of the double evaluator.
TEST(FixedPosition, LargeSinusoidsUseTheLongRotationConstant) {
  const auto m = planned(ProfileKind::ramp_versine, 1.0, 1.0, 20.0, 0.1);
  const Scale s{{5e8, 1000}, 0, 0};
  auto fm = std::make_unique<Motion>();
  ASSERT_EQ(fm->build(m, s), Status::ok);
  auto plan = std::make_unique<PositionPlan>();
  ASSERT_EQ(plan->build(*fm), Status::ok);
  bool precise = false;
  for (unsigned k = 0; k < plan->header().intervals; ++k) {
    precise = precise || (plan->interval(k).flags & PositionInterval::kPrecise) != 0;
  }
  EXPECT_TRUE(precise);
  PositionStepper st{*plan};
  for (std::int32_t n = 0; n <= fm->end_tick(); ++n) {
    const std::int32_t p = st.next();
    EXPECT_LE(std::abs(p - fm->at_tick(n).p), 1) << n;
    EXPECT_LE(std::fabs(p - m.at(n * 1e-3).p * 5e8), 1.0) << n;
  }
}

// 3.2e8 ticks in one piece: one floor of 2^-32 count per tick alone would add 0.075 count, over
// the 1/16 budget, so the builder splits the piece, each part anchored on at_tick() again. Every
// part is checked from its start for 2^16 ticks; the soak build steps the whole move (1.8 s on
// x86-64, too slow for the emulated unit suites).
#ifndef SETTLE_FIXED_WHOLE_LONG_MOVE
#define SETTLE_FIXED_WHOLE_LONG_MOVE 0
#endif
TEST(FixedPosition, LongPiecesAreSplitForTheDriftBudget) {
  const auto m = planned(ProfileKind::poly345, 1.0, 320.0);
  const Scale s{{1e6, 1}, 0, 0};  // 320 s at 1 us
  Motion fm{};
  ASSERT_EQ(fm.build(m, s), Status::ok);
  ASSERT_EQ(fm.header().segments, 1U);
  PositionPlan plan{};
  ASSERT_EQ(plan.build(fm), Status::ok);
  ASSERT_GE(plan.header().intervals, 2U);
  const std::vector<std::int32_t> starts = interval_starts(plan);
  auto off = [&](std::int32_t n, std::int32_t p) { return std::fabs(p - m.at(n * s.axis.period_s()).p * 1e6); };
  double worst = 0.0;
  PositionStepper st{plan};
  for (std::int32_t first : starts) {
    st.restart(first);
    for (std::int32_t n = first; n < first + 65536; ++n) {
      const std::int32_t p = st.next();
      if (n == first) {
        EXPECT_EQ(p, fm.at_tick(n).p) << n;
      }
      worst = std::max(worst, off(n, p));
    }
  }
  if (SETTLE_FIXED_WHOLE_LONG_MOVE != 0) {
    st.restart(0);
    for (std::int32_t n = 0; n <= plan.end_tick(); ++n) {
      const std::int32_t p = st.next();
      const bool edge = std::binary_search(starts.begin(), starts.end(), n) ||
                        std::binary_search(starts.begin(), starts.end(), n + 1) || n + 1 == plan.end_tick();
      if (edge || (n & 0xFFFF) == 0) worst = std::max(worst, off(n, p));
    }
  }
  EXPECT_LE(worst, 0.5 + 1.0 / 16 + 1e-3);
}
