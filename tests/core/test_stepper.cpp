// SPDX-License-Identifier: Apache-2.0
// The stepping evaluator must give the same setpoints as random access (to rounding), for
// plain and shaped moves, in double and float, across many segment boundaries and re-anchors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "settle/core/stepper.hpp"
#include "test_helpers.hpp"

using namespace settle;
using core::ProfileKind;

namespace {

template <typename T>
void expect_stepping_matches(const core::Move<double>& md, double dt, double tol_rel) {
  const core::Move<T> m{md};
  core::MoveStepper<T> st{m, static_cast<T>(dt)};
  const long n = static_cast<long>(std::ceil(md.duration() / dt)) + 5;
  double worst = 0;
  for (long i = 0; i < n; ++i) {
    const auto s = st.step();
    const auto r = m.at(static_cast<T>(i) * static_cast<T>(dt));
    worst = std::max(worst, static_cast<double>(std::fabs(s.p - r.p)));
    ASSERT_NEAR(s.v, r.v, tol_rel * md.peaks().v) << i;
    ASSERT_NEAR(s.a, r.a, tol_rel * md.peaks().a) << i;
  }
  EXPECT_LE(worst, tol_rel * std::fabs(md.distance()));
}

TEST(Stepper, MatchesRandomAccessForTheScurve) {
  auto r = test::timed(ProfileKind::scurve_damped, 0.1, 0.61, 22.0, 0.05);
  r.limits.vmax = 0.25;
  const auto m = test::must_plan(r);
  expect_stepping_matches<double>(m, 1e-4, 1e-12);
  expect_stepping_matches<float>(m, 1e-3, 2e-5);
}

TEST(Stepper, MatchesRandomAccessForShapedMoves) {
  auto r = test::timed(ProfileKind::scurve, 0.2, 0.4, 15.0);
  r.shaper = core::ShaperKind::zvd;
  r.set_mode(40.0);
  const auto m = test::must_plan(r);
  expect_stepping_matches<double>(m, 2.5e-4, 1e-12);
  r.profile = ProfileKind::poly345;  // random-access fallback
  expect_stepping_matches<double>(test::must_plan(r), 1e-3, 0.0);
}

// PiecewiseJerk::at_forward (the stepper's evaluation of piecewise moves) finds the segment at()
// finds, so it returns at()'s result bitwise: over a seeded grid of random tables (1 to 7
// segments, a third of them of zero length, jerks and accelerations of either sign) and random
// non-decreasing times (repeats, times before the start and past the end among them), in double
// and float. at() is the reference: its search runs from the last segment backwards.
template <typename T>
void expect_forward_is_at(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u01{0.0, 1.0};
  core::PiecewiseJerkParams table{};
  table.count = 1 + static_cast<std::size_t>(u01(rng) * 7.0);
  for (std::size_t i = 0; i < table.count; ++i) {
    table.durations[i] = u01(rng) < 1.0 / 3.0 ? 0.0 : 0.01 + u01(rng);
    table.accel0[i] = 4.0 * u01(rng) - 2.0;
    table.jerk[i] = 40.0 * u01(rng) - 20.0;
  }
  table.distance = 1.0;
  const core::PiecewiseJerk<T> pj{table};
  std::size_t k = 0;
  T t = static_cast<T>(-0.05);
  int differ = 0;
  for (int i = 0; i < 400; ++i) {
    const core::Sample<T> got = pj.at_forward(t, k), ref = pj.at(t);
    differ += got.p != ref.p || got.v != ref.v || got.a != ref.a || got.j != ref.j;
    const double r = u01(rng);
    if (r > 0.2) t += static_cast<T>(r * 1.3 * static_cast<double>(pj.duration()) / 100.0);  // else a repeat
  }
  EXPECT_EQ(differ, 0) << "table of " << table.count << " segments";
}

TEST(Stepper, ForwardSegmentSearchIsRandomAccessBitwise) {
  std::mt19937_64 rng{20261206};
  for (int i = 0; i < 300; ++i) {
    expect_forward_is_at<double>(rng);
    expect_forward_is_at<float>(rng);
  }
}

// The stepper steps an unshaped piecewise move (trapezoid, jerk-limited) by its own evaluator
// and gives Move::at's setpoints bitwise at every tick, over a seeded grid of random distances
// (either sign), limits and periods, in double and float, to past the end.
template <typename T>
int stepping_differs(const core::Move<double>& md, double dt) {
  const core::Move<T> m{md};
  core::MoveStepper<T> st{m, static_cast<T>(dt)};
  const long n = static_cast<long>(std::ceil(md.duration() / dt)) + 3;
  int differ = 0;
  for (long i = 0; i < n; ++i) {
    const core::Sample<T> a = st.step(), b = m.at(static_cast<T>(i) * static_cast<T>(dt));
    differ += a.p != b.p || a.v != b.v || a.a != b.a || a.j != b.j;
  }
  return differ;
}

TEST(Stepper, PiecewiseMovesStepAsRandomAccessBitwise) {
  std::mt19937_64 rng{1206};
  std::uniform_real_distribution<double> u01{0.0, 1.0};
  int planned = 0;
  for (int i = 0; i < 200; ++i) {
    core::MoveRequest r{};
    r.profile = i % 2 == 0 ? ProfileKind::jerk_limited : ProfileKind::trapezoid;
    r.distance = (u01(rng) < 0.5 ? -1.0 : 1.0) * (0.001 + u01(rng));
    r.limits.vmax = 0.05 + u01(rng);
    r.limits.amax = 0.5 + 10.0 * u01(rng);
    if (r.profile == ProfileKind::jerk_limited) r.limits.jmax = 5.0 + 200.0 * u01(rng);  // trapezoid: none
    core::Move<double> md{};
    if (core::plan(r, md) != core::Status::ok) continue;
    ++planned;
    ASSERT_TRUE(md.unshaped());
    const double dt = i % 3 == 0 ? 1e-3 : 1e-4 + 2e-3 * u01(rng);
    EXPECT_EQ(stepping_differs<double>(md, dt), 0) << i;
    EXPECT_EQ(stepping_differs<float>(md, dt), 0) << i;
  }
  EXPECT_GE(planned, 150);
}

}  // namespace
