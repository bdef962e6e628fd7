// SPDX-License-Identifier: Apache-2.0
// Commands as the simulator samples them: exact one-sided values where the motion is not smooth
// (seed 001's velocity steps, a trapezoid's acceleration steps), breakpoints that include every
// shaper delay, and the inverse-dynamics command satisfying its own differential equation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "settle/core/planner.hpp"
#include "settle/plant/command.hpp"

namespace settle::plant {
namespace {

core::Move<double> plan(core::MoveRequest r) {
  core::Move<double> m;
  EXPECT_EQ(core::plan(r, m), core::Status::ok);
  return m;
}

// Seed 001's family with given Y / L: L = 1 in 0.167 s.
core::MoveRequest ramp_versine(std::array<double, 3> y) {
  core::MoveRequest r;
  r.profile = core::ProfileKind::ramp_versine;
  r.distance = 1.0;
  r.time = 0.167;
  r.y_fractions = y;
  return r;
}

TEST(Commands, ScaledCommandIsItsBaseTimesTheScaleOnBothSidesOfEveryBreak) {
  // One axis of a path-synchronised move: D_i s(t) (docs/multi_axis.md); seed 001's command steps
  // in velocity, so both one-sided values are checked.
  const MoveCommand base{plan(ramp_versine({0.5, 0.25, 0.25}))};
  const ScaledCommand c{base, -0.2};
  EXPECT_EQ(c.duration(), base.duration());
  EXPECT_EQ(c.final_position(), -0.2 * base.final_position());
  std::vector<double> b0, b1;
  base.breakpoints(b0);
  c.breakpoints(b1);
  EXPECT_EQ(b0, b1);
  for (double t : {0.0, 0.05, 0.1, 0.167, 0.2}) {
    EXPECT_EQ(c.at(t).p, -0.2 * base.at(t).p) << t;
    EXPECT_EQ(c.at(t).v, -0.2 * base.at(t).v) << t;
    EXPECT_EQ(c.at_left(t).v, -0.2 * base.at_left(t).v) << t;
    EXPECT_EQ(c.at_left(t).a, -0.2 * base.at_left(t).a) << t;
  }
}

TEST(Commands, RampVersineVelocityStepsAreOneSided) {
  const MoveCommand c{plan(ramp_versine({0.5, 0.25, 0.25}))};
  const double rate = 2.0 * M_PI / 0.167;
  // y' = (R/2pi)(L - Y2 cos Rt + Y3 sin Rt): at both ends (R/2pi)(L - Y2).
  const double v_end = rate / (2.0 * M_PI) * (1.0 - 0.25);
  EXPECT_DOUBLE_EQ(c.at_left(0.0).v, 0.0);
  EXPECT_NEAR(c.at(0.0).v, v_end, 1e-12);
  EXPECT_NEAR(c.at_left(0.167).v, v_end, 1e-9);
  EXPECT_NEAR(c.at_left(0.167).p, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.at(0.167).v, 0.0);
  EXPECT_DOUBLE_EQ(c.at(0.167).p, 1.0);
}

TEST(Commands, TrapezoidAccelerationStepsAreOneSided) {
  core::MoveRequest r;
  r.profile = core::ProfileKind::trapezoid;
  r.distance = 2.0;
  r.limits.vmax = 1.0;
  r.limits.amax = 4.0;
  const MoveCommand c{plan(r)};
  std::vector<double> bp;
  c.breakpoints(bp);
  std::sort(bp.begin(), bp.end());
  const double t1 = 0.25;  // vmax / amax
  ASSERT_TRUE(std::any_of(bp.begin(), bp.end(), [&](double t) { return std::fabs(t - t1) < 1e-12; }));
  EXPECT_NEAR(c.at_left(t1).a, 4.0, 1e-12);
  EXPECT_NEAR(c.at(t1).a, 0.0, 1e-12);
  EXPECT_NEAR(c.at_left(t1).v, c.at(t1).v, 1e-12);
  EXPECT_NEAR(c.at(0.0).a, 4.0, 1e-12);  // the right limit at the start, not the rest before it
  EXPECT_DOUBLE_EQ(c.at_left(0.0).a, 0.0);
}

TEST(Commands, ScurveIsContinuousAtItsSegmentBoundaries) {
  core::MoveRequest r;
  r.profile = core::ProfileKind::scurve;
  r.distance = 0.07;
  r.time = 0.4;
  r.limits.vmax = 0.3;
  r.set_mode(22.0);
  const MoveCommand c{plan(r)};
  std::vector<double> bp;
  c.breakpoints(bp);
  for (double t : bp) {
    if (t <= 0.0 || t >= c.duration()) continue;
    EXPECT_NEAR(c.at_left(t).p, c.at(t).p, 1e-13);
    EXPECT_NEAR(c.at_left(t).v, c.at(t).v, 1e-12);
    EXPECT_NEAR(c.at_left(t).a, c.at(t).a, 1e-9);
  }
}

TEST(Commands, ShapedMoveSumsDelayedCopiesAndListsTheirBreakpoints) {
  core::MoveRequest r;
  r.profile = core::ProfileKind::poly345;
  r.distance = 1.0;
  r.time = 0.3;
  r.set_mode(20.0);
  r.shaper = core::ShaperKind::zvd;
  const core::Move<double> m = plan(r);
  const MoveCommand c{m};
  for (double t : {0.01, 0.1, 0.2, 0.35, 0.5, 0.6}) {
    EXPECT_NEAR(c.at(t).p, m.at(t).p, 1e-13);
    EXPECT_NEAR(c.at(t).a, m.at(t).a, 1e-9);
  }
  std::vector<double> bp;
  c.breakpoints(bp);
  for (std::size_t i = 0; i < m.shaper().count; ++i) {
    const double t = m.shaper().time[i] + 0.3;
    EXPECT_TRUE(std::any_of(bp.begin(), bp.end(), [&](double b) { return std::fabs(b - t) < 1e-12; }));
  }
}

TEST(Commands, TwoExponentPseudoPolyStartsWithAnAccelerationStep) {
  core::MoveRequest r;
  r.profile = core::ProfileKind::pseudopoly;
  r.distance = 1.0;
  r.time = 1.0;
  r.gammas[0] = 3.0;
  r.gammas[1] = 4.0;
  r.gamma_count = 2;
  const MoveCommand c{plan(r)};
  // phi = 1 - 4 w^3 + 3 w^4: phi''(0+) = -(12*2*(-4)/... ) = 12 (12 w^2 ... ) -> 12 at w = 1.
  EXPECT_NEAR(c.at(0.0).a, 12.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.at_left(0.0).a, 0.0);
}

// A shaped ramp's velocity drops by A_i L / tau where impulse i's copy ends, at t_i + tau: both
// one-sided limits there, though t_i + tau - t_i need not round back to tau.
TEST(Commands, ShapedRampKeepsEveryVelocityStepOneSided) {
  core::MoveRequest r = ramp_versine({1.0, 0.0, 0.0});
  r.set_mode(33.375, 0.1559);
  r.shaper = core::ShaperKind::zvd;
  const MoveCommand c{plan(r)};
  const auto& sh = c.move().shaper();
  ASSERT_EQ(sh.count, 3u);
  for (std::size_t i = 0; i < sh.count; ++i) {
    const double t = sh.time[i] + 0.167;
    EXPECT_NEAR(c.at_left(t).v - c.at(t).v, sh.amp[i] / 0.167, 1e-9) << i;
  }
}

TEST(Commands, StepsCommandJumpsAtItsImpulses) {
  core::Shaper<double> s;
  ASSERT_EQ(core::design_shaper(core::ShaperKind::zv, 10.0, 0.0, 0.05, s), core::Status::ok);
  const StepsCommand c{2.0, s};
  EXPECT_NEAR(c.at(0.0).p, 1.0, 1e-15);
  EXPECT_DOUBLE_EQ(c.at_left(0.0).p, 0.0);
  EXPECT_NEAR(c.at_left(s.time[1]).p, 1.0, 1e-15);
  EXPECT_NEAR(c.at(s.time[1]).p, 2.0, 1e-15);
  EXPECT_DOUBLE_EQ(c.final_position(), 2.0);
}

class InverseDynamics : public ::testing::TestWithParam<int> {};

TEST_P(InverseDynamics, CommandSatisfiesTheNominalInverse) {
  const int degree = GetParam();
  const double d = 1.0, tt = 0.167, w = 28.28, z = 0.159;
  const InverseDynamicsCommand c{d, tt, w, z, degree};
  auto x = [&](int k, double t) {
    const double s = t / tt;
    if (degree == 3) {
      const double v[3] = {s * s * (3 - 2 * s), 6 * s * (1 - s), 6 - 12 * s};
      return d * v[k] / std::pow(tt, k);
    }
    const double v[3] = {s * s * s * (10 - 15 * s + 6 * s * s), 30 * s * s * (1 - s) * (1 - s),
                         60 * s * (1 - 3 * s + 2 * s * s)};
    return d * v[k] / std::pow(tt, k);
  };
  for (double t : {0.001, 0.05, 0.1, 0.166}) {
    const BaseState y = c.at(t);
    const double wv = y.p - x(0, t), wd = y.v - x(1, t);
    EXPECT_NEAR(2 * z * w * wd + w * w * wv, x(2, t), 1e-9 * (1 + std::fabs(x(2, t)))) << t;
  }
  // After T the output is at rest at D, so w'' ... w = y - D decays: 2 z w w' + w^2 w = 0.
  const BaseState y = c.at(0.2);
  EXPECT_NEAR(2 * z * w * y.v + w * w * (y.p - d), 0.0, 1e-9);
  EXPECT_NEAR(c.at_left(tt).p, c.at(tt).p, 1e-14);
  EXPECT_DOUBLE_EQ(c.at(c.duration()).p, d);
  EXPECT_DOUBLE_EQ(c.at_left(0.0).p, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Degrees, InverseDynamics, ::testing::Values(3, 5));

}  // namespace
}  // namespace settle::plant
