// SPDX-License-Identifier: Apache-2.0
// The one limits type and its optional form: peaks against plain limits name the first limit
// exceeded (what the planner, the online blends and `settle identify` refuse by), and an optional
// triple resolves against fallbacks and scales limit by limit.
#include <gtest/gtest.h>

#include <cmath>

#include "settle/core/limits.hpp"

using namespace settle;
using core::Status;

namespace {

TEST(Limits, CheckLimitsNamesTheFirstLimitExceeded) {
  const core::Peaks<double> pk{1.0, 10.0, 100.0};
  EXPECT_EQ(core::check_limits(core::Limits{1.0, 10.0, 100.0}, pk), Status::ok);
  EXPECT_EQ(core::check_limits(core::Limits{1.0 - 1e-12, 10.0, 100.0}, pk), Status::ok);  // within the slack
  EXPECT_EQ(core::check_limits(core::Limits{1.0, 10.0, 99.0}, pk), Status::jerk_limit_exceeded);
  EXPECT_EQ(core::check_limits(core::Limits{1.0, 9.0, 99.0}, pk), Status::acceleration_limit_exceeded);
  EXPECT_EQ(core::check_limits(core::Limits{0.5, 9.0, 99.0}, pk), Status::velocity_limit_exceeded);
  const core::Peaks<double> nan_a{1.0, std::nan(""), 100.0};
  EXPECT_EQ(core::check_limits(core::Limits{1.0, 10.0, 100.0}, nan_a), Status::acceleration_limit_exceeded);
  // within_limits is the same test.
  EXPECT_TRUE(core::within_limits(pk, core::Limits{1.0, 10.0, 100.0}));
  EXPECT_FALSE(core::within_limits(pk, core::Limits{1.0, 10.0, 99.0}));
  EXPECT_FALSE(core::within_limits(nan_a, core::Limits{1.0, 10.0, 100.0}));
}

// What plan() refuses a move for (and the tuner a shaped candidate): each absent limit does not
// bind, the slack admits a plan that touches a limit, the first exceeded is named (velocity,
// acceleration, jerk), and a NaN peak is refused where its limit is given.
TEST(Limits, OptionalLimitsCheckOnlyTheGivenOnes) {
  core::OptionalLimits l{};
  const core::Peaks<double> pk{1.0, 10.0, 100.0};
  EXPECT_EQ(core::check_limits(l, pk), Status::ok);
  l = {.vmax = 1.0, .amax = 10.0, .jmax = 100.0};
  EXPECT_EQ(core::check_limits(l, pk), Status::ok);
  l.jmax = 99.0;
  EXPECT_EQ(core::check_limits(l, pk), Status::jerk_limit_exceeded);
  l.amax = 9.0;
  EXPECT_EQ(core::check_limits(l, pk), Status::acceleration_limit_exceeded);
  l.vmax = 0.5;
  EXPECT_EQ(core::check_limits(l, pk), Status::velocity_limit_exceeded);
  l.vmax = 1.0 - 1e-12;  // within the slack
  l.amax.reset();
  l.jmax.reset();
  EXPECT_EQ(core::check_limits(l, pk), Status::ok);
  const core::Peaks<double> nan_v{std::nan(""), 10.0, 100.0};
  EXPECT_EQ(core::check_limits(l, nan_v), Status::velocity_limit_exceeded);
  l.vmax.reset();
  l.amax = 10.0;
  EXPECT_EQ(core::check_limits(l, nan_v), Status::ok);
}

TEST(Limits, OptionalLimitsResolveScaleAndConvert) {
  const core::OptionalLimits some{.vmax = 2.0, .amax = {}, .jmax = 300.0};
  const core::Limits r = some.value_or(core::Limits{1.0, 10.0, 100.0});
  EXPECT_EQ(r.vmax, 2.0);
  EXPECT_EQ(r.amax, 10.0);
  EXPECT_EQ(r.jmax, 300.0);
  EXPECT_TRUE(some.any());
  EXPECT_TRUE((core::OptionalLimits{.vmax = {}, .amax = 1.0, .jmax = {}}.any()));
  EXPECT_FALSE(core::OptionalLimits{}.any());
  const core::OptionalLimits half = some.scaled(0.5);
  EXPECT_EQ(half.vmax, 1.0);
  EXPECT_FALSE(half.amax);
  EXPECT_EQ(half.jmax, 150.0);
  const core::OptionalLimits all = core::as_optional(core::Limits{1.0, 10.0, 100.0});
  EXPECT_EQ(all.vmax, 1.0);
  EXPECT_EQ(all.amax, 10.0);
  EXPECT_EQ(all.jmax, 100.0);
}

}  // namespace
