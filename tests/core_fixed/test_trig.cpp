// SPDX-License-Identifier: Apache-2.0
// The fixed-point sine and cosine against std::sin/cos over their input codes: every code in the
// soak build (2^32), every 256th code (with a random low byte) in the unit build. Both
// implementations are measured; the table one is what the evaluators use.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

#include "settle/core/fixed/trig.hpp"

#ifndef SETTLE_TRIG_STRIDE  // 1: exhaustive
#define SETTLE_TRIG_STRIDE 256
#endif

using namespace settle::core::fixed;

namespace {

struct TrigError {
  double worst{0.0};
  double sum{0.0};
  std::uint64_t n{0};
  std::uint32_t at{0};
};

template <typename F>
TrigError measure(F&& f) {
  TrigError e{};
  std::mt19937 rng{5};
  constexpr double kTurn = 6.283185307179586476925286766559 / 4294967296.0;
  constexpr double kOne = 1073741824.0;
  for (std::uint64_t base = 0; base < (std::uint64_t{1} << 32); base += SETTLE_TRIG_STRIDE) {
    const auto code = static_cast<std::uint32_t>(base + (SETTLE_TRIG_STRIDE > 1 ? rng() % SETTLE_TRIG_STRIDE : 0));
    const SinCos sc = f(code);
    // Reduce to [-pi/4, pi/4] exactly (integers) so that the reference itself is exact to 1e-16.
    const std::uint32_t q = (code + (1U << 29)) >> 30;
    const double y = static_cast<double>(static_cast<std::int32_t>(code - (q << 30))) * kTurn;
    double s = std::sin(y), c = std::cos(y);
    for (std::uint32_t k = 0; k < (q & 3U); ++k) {
      const double t = s;
      s = c;
      c = -t;
    }
    const double err = std::fmax(std::fabs(sc.sin - s * kOne), std::fabs(sc.cos - c * kOne));
    e.sum += err;
    ++e.n;
    if (err > e.worst) {
      e.worst = err;
      e.at = code;
    }
  }
  return e;
}

}  // namespace

TEST(FixedTrig, TableSineWithinOneLsbOverItsInputCodes) {
  const TrigError e = measure([](std::uint32_t c) { return sincos(c); });
  std::printf("table sincos: %llu codes, max |error| %.3f LSB (Q2.30) at 0x%08x, mean %.3f\n",
              static_cast<unsigned long long>(e.n), e.worst, e.at, e.sum / static_cast<double>(e.n));
  EXPECT_LT(e.worst, 0.8);
}

TEST(FixedTrig, PolynomialSineWithinThreeLsbOverItsInputCodes) {
  const TrigError e = measure([](std::uint32_t c) { return sincos_poly(c); });
  std::printf("polynomial sincos: %llu codes, max |error| %.3f LSB (Q2.30) at 0x%08x, mean %.3f\n",
              static_cast<unsigned long long>(e.n), e.worst, e.at, e.sum / static_cast<double>(e.n));
  EXPECT_LT(e.worst, 3.0);
}

TEST(FixedTrig, QuadrantsAreExact) {
  for (std::uint32_t q = 0; q < 4; ++q) {
    const SinCos sc = sincos(q << 30);
    const std::int32_t one = 1 << kTrigBits;
    const std::int32_t s[4] = {0, one, 0, -one}, c[4] = {one, 0, -one, 0};
    EXPECT_EQ(sc.sin, s[q]) << q;
    EXPECT_EQ(sc.cos, c[q]) << q;
  }
}
