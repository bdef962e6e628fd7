// SPDX-License-Identifier: Apache-2.0
// Properties of the fixed-point motion on chosen moves: the seed-000 beam move at every tick, rest
// exactly on target, nothing before the start, shaper impulses between ticks, wrap-around of
// absolute positions, and the stepper re-anchoring exactly wherever it is restarted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>

#include "fixed_cases.hpp"
#include "settle/core/fixed/motion.hpp"

using namespace settle;
using core::ProfileKind;
using core::Status;
using core::fixed::Motion;
using core::fixed::Sample;
using core::fixed::Scale;

using test::planned;

namespace {

// Largest |fixed - double| over every tick of the move.
test::Errors worst_over(const Motion& fm, const core::Move<double>& m, const Scale& s) {
  test::Errors w{};
  for (std::int32_t n = 0; n <= fm.end_tick() + 1; ++n) {
    const test::Errors e = test::errors_at(m, s, n, fm.at_tick(n));
    w.p = std::max(w.p, e.p);
    w.v = std::max(w.v, e.v);
    w.a = std::max(w.a, e.a);
  }
  return w;
}

}  // namespace

// Seed 000's beam (Tn = 0.285 s) moved 100 mm in 0.8 Tn, 1 um counts, 1 kHz.
TEST(FixedMotion, BeamMoveWithinHalfACountAtEveryTick) {
  const auto m = planned(ProfileKind::scurve, 0.1, 0.8 * 6.283185307179586 / 22.04871, 22.04871);
  const Scale s{{1e6, 1000}, 16, 16};
  Motion fm{};
  ASSERT_EQ(fm.build(m, s), Status::ok);
  EXPECT_EQ(fm.end_tick(), static_cast<std::int32_t>(std::ceil(m.duration() / 1e-3)));
  const test::Errors w = worst_over(fm, m, s);
  EXPECT_LE(w.p, 0.5 + 1e-6);
  EXPECT_LE(w.v, 0.52);
  EXPECT_LE(w.a, 0.52);
}

TEST(FixedMotion, RestsExactlyOnTargetAndIsZeroBeforeTheStart) {
  const auto m = planned(ProfileKind::scurve_damped, -0.0421, 0.37, 30.0, 0.12);
  Motion fm{};
  ASSERT_EQ(fm.build(m, Scale{{1e6, 1000}, 16, 16}), Status::ok);
  EXPECT_EQ(fm.target(), -42100);
  for (std::int32_t n : {fm.end_tick(), fm.end_tick() + 1, INT32_MAX}) {
    const Sample s = fm.at_tick(n);
    EXPECT_EQ(s.p, -42100);
    EXPECT_EQ(s.v, 0);
    EXPECT_EQ(s.a, 0);
  }
  for (std::int32_t n : {-1, -1000, INT32_MIN}) {
    const Sample s = fm.at_tick(n);
    EXPECT_EQ(s.p, 0);
    EXPECT_EQ(s.v, 0);
    EXPECT_EQ(s.a, 0);
  }
  EXPECT_EQ(fm.at_tick(0).p, 0);
}

TEST(FixedMotion, ZeroDistanceIsAtRest) {
  const auto m = planned(ProfileKind::scurve, 0.0, 0.5, 20.0);
  Motion fm{};
  ASSERT_EQ(fm.build(m, Scale{}), Status::ok);
  for (std::int32_t n : {-1, 0, 1, 100}) EXPECT_EQ(fm.at_tick(n).p, 0);
}

// A ZV shaper whose second impulse falls 0.37 of a tick after a whole tick: evaluated exactly.
TEST(FixedMotion, ShaperImpulsesBetweenTicksAreExact) {
  const double dt = 1e-3, half = 12.37 * dt;  // pi / omega
  const double omega = 3.141592653589793 / half;
  const auto m = planned(ProfileKind::scurve_damped, 0.05, 0.2, omega * 1.3, 0.05, core::ShaperKind::zv);
  const Scale s{{1e6, 1000}, 16, 16};
  Motion fm{};
  ASSERT_EQ(fm.build(m, s), Status::ok);
  ASSERT_EQ(fm.header().tracks, 2U);
  EXPECT_EQ(fm.track(1).delay, static_cast<std::int32_t>(std::floor(m.shaper().time[1] / dt)));
  EXPECT_NE(fm.track(1).frac, 0U);
  const test::Errors w = worst_over(fm, m, s);
  EXPECT_LE(w.p, 0.5 + 1e-6);
  EXPECT_LE(w.v, 0.6);
  EXPECT_LE(w.a, 0.6);
}

// A move that starts just below INT32_MAX crosses the drive's wrap and lands where modulo
// arithmetic says, with every step as small as the profile's.
TEST(FixedMotion, AbsolutePositionsWrapAcrossTheInt32Boundary) {
  const auto m = planned(ProfileKind::poly345, 0.5, 0.4);
  Motion fm{};
  ASSERT_EQ(fm.build(m, Scale{{1e6, 1000}, 16, 16}), Status::ok);
  const std::int32_t start = INT32_MAX - 200000;
  std::int32_t prev = start;
  for (std::int32_t n = 0; n <= fm.end_tick(); ++n) {
    const std::int32_t now = core::fixed::absolute(start, fm.at_tick(n).p);
    const auto step = static_cast<std::int32_t>(static_cast<std::uint32_t>(now) - static_cast<std::uint32_t>(prev));
    EXPECT_GE(step, 0);
    EXPECT_LE(step, 2400);  // peak velocity 1.875 D/T = 2344 counts/tick
    prev = now;
  }
  EXPECT_EQ(prev, static_cast<std::int32_t>(static_cast<std::uint32_t>(start) + 500000U));
}

// Wherever the stepper is (re)started it anchors on the random-access values, bit for bit.
TEST(FixedMotion, StepperAnchorsOnRandomAccessWhereverRestarted) {
  test::FixedCaseGen gen{std::mt19937_64{3}, test::Kinds::all};
  std::mt19937_64 rng{4};
  auto fm = std::make_unique<core::fixed::PolyMotion>();
  int checked = 0;
  while (checked < 300) {
    test::FixedCase c{};
    if (!gen.next(c) || fm->build(c.move, c.scale) != Status::ok) continue;
    core::fixed::MotionStepper<4> st{*fm};
    for (int k = 0; k < 20; ++k) {
      const auto n = static_cast<std::int32_t>(rng() % static_cast<std::uint64_t>(fm->end_tick() + 1));
      st.restart(n);
      const Sample a = fm->at_tick(n), b = st.next();
      if (fm->header().unit_weight) {  // with weights the stepper folds them in a different order
        EXPECT_EQ(a.p, b.p);
        EXPECT_EQ(a.v, b.v);
        EXPECT_EQ(a.a, b.a);
      }
      EXPECT_EQ(st.tick(), n + 1);
    }
    ++checked;
  }
}

TEST(FixedMotion, BuildingIsDeterministic) {
  const auto m = planned(ProfileKind::scurve_damped, 0.3, 0.6, 25.0, 0.1, core::ShaperKind::zvd);
  Motion a{}, b{};
  ASSERT_EQ(a.build(m, Scale{}), Status::ok);
  ASSERT_EQ(b.build(m, Scale{}), Status::ok);
  for (std::int32_t n = -1; n <= a.end_tick(); ++n) {
    EXPECT_EQ(a.at_tick(n).p, b.at_tick(n).p);
    EXPECT_EQ(a.at_tick(n).a, b.at_tick(n).a);
  }
}
