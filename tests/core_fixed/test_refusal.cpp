// SPDX-License-Identifier: Apache-2.0
// Bad input: a move whose distance, speed or duration does not fit the fixed-point formats is
// refused by the builder with a specific code, and the object it would have replaced is unchanged.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "fixed_cases.hpp"
#include "settle/core/fixed/cam.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/planner.hpp"

using namespace settle;
using core::ProfileKind;
using core::Status;
using core::fixed::Motion;
using core::fixed::Scale;

using test::planned;

namespace {

// Builds `m` into a motion that already holds a good move; checks the code and that the motion
// still evaluates the good move.
template <typename M = Motion>
void expect_refused(const core::Move<double>& m, const Scale& s, Status want) {
  M fm{};
  const auto good = planned(ProfileKind::scurve, 0.01, 0.2);
  ASSERT_EQ(fm.build(good, Scale{}), Status::ok);
  const auto before = fm.at_tick(50);
  const auto end = fm.end_tick();
  EXPECT_EQ(fm.build(m, s), want) << core::to_string(want);
  EXPECT_EQ(fm.end_tick(), end);
  EXPECT_EQ(fm.at_tick(50).p, before.p);
  EXPECT_EQ(fm.at_tick(50).v, before.v);
}

}  // namespace

TEST(FixedRefusal, ScaleMustBeFinitePositiveWithSaneFractionBits) {
  const auto m = planned(ProfileKind::scurve, 0.1, 0.5);
  expect_refused(m, Scale{{0.0, 1000}, 16, 16}, Status::scale_invalid);
  expect_refused(m, Scale{{NAN, 1000}, 16, 16}, Status::scale_invalid);
  expect_refused(m, Scale{{1e6, 0}, 16, 16}, Status::scale_invalid);
  expect_refused(m, Scale{{INFINITY, 1000}, 16, 16}, Status::scale_invalid);
  expect_refused(m, Scale{{1e6, 1000}, 31, 16}, Status::scale_invalid);
  expect_refused(m, Scale{{1e6, 1000}, 16, -1}, Status::scale_invalid);
}

TEST(FixedRefusal, DistanceBeyondTheCountFormat) {
  // 2^31 counts: not a relative int32 position.
  expect_refused(planned(ProfileKind::scurve, 2147.483648, 5.0), Scale{{1e6, 1000}, 8, 8}, Status::distance_does_not_fit);
  // A trapezoid of 2^30 counts: the distance itself fits int32 but not the evaluator's headroom.
  expect_refused(planned(ProfileKind::trapezoid, 1073.741824, 50.0), Scale{{1e6, 1000}, 0, 0},
                 Status::distance_does_not_fit);
}

TEST(FixedRefusal, VelocityOrAccelerationBeyondTheirFormats) {
  // 2 m in 0.1 s at 1 um, 1 kHz: 1.875 D/T = 37500 counts/tick is over Q16.16's 2^15, not Q20.12's.
  const auto m = planned(ProfileKind::poly345, 2.0, 0.1);
  expect_refused(m, Scale{{1e6, 1000}, 16, 8}, Status::velocity_does_not_fit);
  Motion fm{};
  EXPECT_EQ(fm.build(m, Scale{{1e6, 1000}, 12, 8}), Status::ok);
  // Its peak acceleration, 5.77 D/T^2 = 1155 counts/tick^2, does not fit 22 fraction bits.
  expect_refused(m, Scale{{1e6, 1000}, 12, 22}, Status::acceleration_does_not_fit);
}

TEST(FixedRefusal, DurationBeyondTheTickFormat) {
  // 1100 s at 1 us ticks: 1.1e9 ticks, over 2^30.
  expect_refused(planned(ProfileKind::scurve, 0.1, 1100.0), Scale{{1e6, 1}, 0, 0}, Status::duration_does_not_fit);
}

TEST(FixedRefusal, TransitionShorterThanATick) {
  // tau = T/4 = 0.5 ms at a 1 ms tick.
  expect_refused(planned(ProfileKind::scurve, 1e-4, 2e-3, 2000.0), Scale{{1e6, 1000}, 16, 16},
                 Status::transition_shorter_than_tick);
}

TEST(FixedRefusal, PseudoPolyTooShortForItsDistance) {
  // 2^23 counts in 16 ticks: the non-smooth end needs pieces shorter than a tick.
  expect_refused<core::fixed::PolyMotion>(planned(ProfileKind::pseudopoly, 8.388608, 0.016), Scale{{1e6, 1000}, 0, 0},
                                          Status::precision_insufficient);
}

TEST(FixedRefusal, CapacityTooSmall) {
  // Non-integer exponents need more pieces than Motion's eight.
  expect_refused(planned(ProfileKind::pseudopoly, 0.5, 1.0), Scale{}, Status::table_too_small);
  // Nine impulses (ZVD * ZVD) into four tracks.
  core::Shaper<double> zvd{}, both{};
  ASSERT_EQ(core::design_shaper(core::ShaperKind::zvd, 20.0, 0.1, 0.05, zvd), Status::ok);
  ASSERT_EQ(core::compose(zvd, zvd, both), Status::ok);
  const auto p = planned(ProfileKind::scurve, 0.1, 0.5);
  expect_refused(core::Move<double>{p.profile(), both, p.peaks()}, Scale{}, Status::too_many_impulses);
  // A cam table of two knots cannot hold a 500-tick S-curve to one count.
  std::array<core::fixed::CamKnot, 2> knots{};
  core::fixed::CamTable t{};
  EXPECT_EQ(core::fixed::build_cam_table(p, Scale{}, core::fixed::CamOrder::quintic, knots, t), Status::table_too_small);
  EXPECT_EQ(t.knots(), 0U);
}

TEST(FixedRefusal, ImpulseAmplitudeWithoutAQ230Weight) {
  static constexpr double amp[2] = {2.5, -1.5}, time[2] = {0.0, 0.01};
  core::Shaper<double> s{};
  ASSERT_EQ(core::custom_shaper(amp, time, 2, s), Status::ok);
  const auto p = planned(ProfileKind::scurve, 0.1, 0.5);
  expect_refused(core::Move<double>{p.profile(), s, p.peaks()}, Scale{}, Status::impulse_does_not_fit);
}
