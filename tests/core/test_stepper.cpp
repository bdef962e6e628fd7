// SPDX-License-Identifier: Apache-2.0
// The stepping evaluator must give the same setpoints as random access (to rounding), for
// plain and shaped moves, in double and float, across many segment boundaries and re-anchors.
#include <gtest/gtest.h>

#include <cmath>

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
  r.vmax = 0.25;
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

}  // namespace
