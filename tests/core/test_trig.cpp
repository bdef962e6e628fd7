// SPDX-License-Identifier: Apache-2.0
// core::sin_cos in float (core/trig.hpp) against std::sin/std::cos in double, independently: over
// the phases the profiles evaluate, over its whole documented domain, and outside it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "settle/core/trig.hpp"

using settle::core::kFloatTrigDomain;
using settle::core::sin_cos;

namespace {

// Error in float ulps of the exact value (ulp of max(|exact|, 2^-126), so that near a zero of
// sin the error is measured against the float spacing there).
double ulps(float got, double exact) {
  const double mag = std::fmax(std::fabs(exact), static_cast<double>(std::numeric_limits<float>::min()));
  const double ulp = std::ldexp(1.0, std::ilogb(mag) - 23);
  return std::fabs(static_cast<double>(got) - exact) / ulp;
}

struct Worst {
  double abs{0};
  double ulp{0};
  void add(float got, double exact) {
    abs = std::fmax(abs, std::fabs(static_cast<double>(got) - exact));
    ulp = std::fmax(ulp, ulps(got, exact));
  }
};

}  // namespace

TEST(SinCosFloat, WithinTwoUlpOverEveryPhaseAProfileEvaluates) {
  // [-2 pi, 4 pi] densely: every float in [0, 2 pi] near the quadrant boundaries is in here.
  Worst s, c;
  const int n = 2'000'000;
  for (int i = 0; i <= n; ++i) {
    const float x = static_cast<float>(-6.283185307179586 + 18.84955592153876 * i / n);
    const auto r = sin_cos(x);
    s.add(r.sin, std::sin(static_cast<double>(x)));
    c.add(r.cos, std::cos(static_cast<double>(x)));
  }
  EXPECT_LE(s.abs, 1.2e-7);
  EXPECT_LE(c.abs, 1.2e-7);
  // Relative to the value itself away from the zeros (near a zero the absolute bound is the one
  // that matters to a position: the phase's own rounding is larger).
  Worst sr, cr;
  for (int i = 0; i <= 200'000; ++i) {
    const float x = static_cast<float>(1e-6 + 0.7 * i / 200'000.0);  // (0, 0.7]: sin small, cos near 1
    sr.add(sin_cos(x).sin, std::sin(static_cast<double>(x)));
    cr.add(sin_cos(x).cos, std::cos(static_cast<double>(x)));
  }
  EXPECT_LE(sr.ulp, 2.0);
  EXPECT_LE(cr.ulp, 2.0);
}

TEST(SinCosFloat, AccurateOverTheWholeDomain) {
  Worst s, c;
  const int n = 1'000'000;
  for (int i = -n; i <= n; ++i) {
    const float x = kFloatTrigDomain * static_cast<float>(i) / static_cast<float>(n);
    const auto r = sin_cos(x);
    s.add(r.sin, std::sin(static_cast<double>(x)));
    c.add(r.cos, std::cos(static_cast<double>(x)));
  }
  // The reduction is exact for |k| < 2^12: the error stays that of the polynomials.
  EXPECT_LE(s.abs, 1.2e-7);
  EXPECT_LE(c.abs, 1.2e-7);
}

TEST(SinCosFloat, QuadrantsAndSymmetry) {
  const float q = 1.57079632679489662F;  // the float nearest pi/2
  for (int k = -8; k <= 8; ++k) {
    const double x = static_cast<double>(static_cast<float>(k) * q);
    const auto r = sin_cos(static_cast<float>(k) * q);
    EXPECT_NEAR(r.sin, std::sin(x), 1e-7) << k;
    EXPECT_NEAR(r.cos, std::cos(x), 1e-7) << k;
  }
  for (const float x : {0.1F, 1.0F, 2.5F, 4.0F, 6.0F, 100.0F, 6000.0F}) {
    EXPECT_EQ(sin_cos(-x).sin, -sin_cos(x).sin) << x;  // odd and even, exactly
    EXPECT_EQ(sin_cos(-x).cos, sin_cos(x).cos) << x;
  }
  EXPECT_EQ(sin_cos(0.0F).sin, 0.0F);
  EXPECT_EQ(sin_cos(0.0F).cos, 1.0F);
}

TEST(SinCosFloat, OutsideTheDomainBoundedOrNaNNeverGarbage) {
  for (const float x : {6500.0F, -1e4F, 1e10F, -3e38F, std::numeric_limits<float>::max()}) {
    const auto r = sin_cos(x);
    EXPECT_EQ(r.sin, 0.0F) << x;
    EXPECT_EQ(r.cos, 1.0F) << x;
  }
  for (const float x : {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                        std::numeric_limits<float>::quiet_NaN()}) {
    const auto r = sin_cos(x);
    EXPECT_TRUE(std::isnan(r.sin)) << x;
    EXPECT_TRUE(std::isnan(r.cos)) << x;
  }
}

TEST(SinCosDouble, IsTheLibrarys) {
  for (const double x : {-7.0, -1e-300, 0.0, 0.3, 3.0, 1e6}) {
    EXPECT_EQ(sin_cos(x).sin, std::sin(x));
    EXPECT_EQ(sin_cos(x).cos, std::cos(x));
  }
}
