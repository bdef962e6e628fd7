// SPDX-License-Identifier: Apache-2.0
// The axis scale's one conversion of its period, and what it accepts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "settle/core/axis_scale.hpp"

namespace settle::core {
namespace {

// Within one rounding of the exact quotient, and exact for the periods the golden list uses.
TEST(AxisScale, ThePeriodInSecondsIsItsMicroseconds) {
  static_assert(AxisScale{}.period_s() == 1e-3);  // usable at compile time (the images' constants)
  static_assert(AxisScale{1e6, 250}.period_s() == 2.5e-4 && AxisScale{1e6, 500}.period_s() == 5e-4 &&
                AxisScale{1e6, 2000}.period_s() == 2e-3);
  for (const std::uint32_t us : {1U, 3U, 100U, 125U, 999U, 100000U, 4294967295U}) {
    const double exact = us / 1e6;
    const AxisScale scale{1e6, us};
    EXPECT_NEAR(scale.period_s(), exact, exact * 2.3e-16) << us;
  }
}

TEST(AxisScale, ValidNeedsAPeriodAndAPositiveFiniteScale) {
  EXPECT_TRUE((AxisScale{1e6, 1000}.valid()));
  EXPECT_TRUE((AxisScale{1e-3, 1}.valid()));
  EXPECT_FALSE((AxisScale{1e6, 0}.valid()));
  EXPECT_FALSE((AxisScale{0.0, 1000}.valid()));
  EXPECT_FALSE((AxisScale{-1.0, 1000}.valid()));
  EXPECT_FALSE((AxisScale{NAN, 1000}.valid()));
  EXPECT_FALSE((AxisScale{std::numeric_limits<double>::infinity(), 1000}.valid()));
}

}  // namespace
}  // namespace settle::core
