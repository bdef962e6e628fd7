// SPDX-License-Identifier: Apache-2.0
// The setpoint stream's own rounding helpers (core/setpoints.hpp), which replace libm's ceil and
// llround on the servo loop's path, against libm over seeded random grids and their edge cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "settle/core/setpoints.hpp"

using namespace settle;

namespace {

// The reference: what stream_ticks computed with std::ceil before.
std::int64_t ceil_reference(double q) {
  const double t = std::ceil(q);
  return t >= 0.0 && t <= static_cast<double>(core::kMaxStreamTicks) ? static_cast<std::int64_t>(t)
                                                                       : core::kMaxStreamTicks + 1;
}

TEST(Setpoints, TicksCeilIsLibmCeilWhereATickCountFits) {
  const double k = static_cast<double>(core::kMaxStreamTicks);
  std::vector<double> qs{0.0, -0.0, -0.5, -1.0, -1.0 + 1e-16, -2.0, 1.0, 1.5, 2.0 - 1e-16, k, k - 0.5, std::nextafter(k, 0.0),
                         std::nextafter(k, 2.0 * k), k + 0.5, k + 1.0, 1e300, -1e300,
                         std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                         std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::denorm_min()};
  std::mt19937_64 rng{1206};
  std::uniform_real_distribution<double> u{-2.0, 1.2 * k}, e{-40.0, 40.0};
  std::uniform_int_distribution<std::int64_t> n{-3, core::kMaxStreamTicks + 3};
  for (int i = 0; i < 20000; ++i) {
    qs.push_back(u(rng));
    qs.push_back(std::pow(2.0, e(rng)));
    const double whole = static_cast<double>(n(rng));
    qs.push_back(whole);
    qs.push_back(std::nextafter(whole, -1e9));
    qs.push_back(std::nextafter(whole, 1e18));
  }
  int differ = 0;
  for (const double q : qs) differ += core::ticks_ceil(q) != ceil_reference(q);
  EXPECT_EQ(differ, 0);
}

TEST(Setpoints, RoundHalfAwayIsLlroundBelowTwoTo52) {
  std::vector<double> xs{0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994,
                         std::nextafter(0.5, 1.0), 4503599627370495.5, -4503599627370495.5, 1073741823.5};
  std::mt19937_64 rng{36};
  std::uniform_real_distribution<double> u{-2e9, 2e9}, e{-30.0, 51.0};
  std::uniform_int_distribution<std::int64_t> n{-(std::int64_t{1} << 40), std::int64_t{1} << 40};
  for (int i = 0; i < 20000; ++i) {
    xs.push_back(u(rng));
    xs.push_back((i % 2 == 0 ? 1.0 : -1.0) * std::pow(2.0, e(rng)));
    const double half = static_cast<double>(n(rng)) + 0.5;
    xs.push_back(half);
    xs.push_back(std::nextafter(half, 0.0));
    xs.push_back(std::nextafter(half, half * 2.0));
  }
  int differ = 0;
  for (const double x : xs) differ += core::round_half_away(x) != std::llround(x);
  EXPECT_EQ(differ, 0);
}

}  // namespace
