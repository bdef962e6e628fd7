// SPDX-License-Identifier: Apache-2.0
#pragma once
// Quintic and cubic Hermite coefficients on the unit interval from the end values p, p', p''
// (derivatives already in units of the interval). One template for the planning-time fit (double)
// and the cam table's tick path (int64 Q32.32, where halving is an arithmetic shift).
#include <array>
#include <cstdint>

namespace settle::core::fixed::hermite {

[[nodiscard]] constexpr double half(double x) noexcept { return 0.5 * x; }
[[nodiscard]] constexpr std::int64_t half(std::int64_t x) noexcept { return x >> 1; }

// p(x) = sum c_k x^k with p, p', p'' = (p0, v0, a0) at 0 and (p1, v1, a1) at 1.
template <typename T>
[[nodiscard]] constexpr std::array<T, 6> quintic(T p0, T v0, T a0, T p1, T v1, T a1) noexcept {
  const T d = p1 - p0;
  return {p0,
          v0,
          half(a0),
          10 * d - 6 * v0 - 4 * v1 - half(3 * a0 - a1),
          -15 * d + 8 * v0 + 7 * v1 + half(3 * a0 - 2 * a1),
          6 * d - 3 * (v0 + v1) - half(a0 - a1)};
}

// p(x) with p, p' = (p0, v0) at 0 and (p1, v1) at 1.
template <typename T>
[[nodiscard]] constexpr std::array<T, 6> cubic(T p0, T v0, T p1, T v1) noexcept {
  const T d = p1 - p0;
  return {p0, v0, 3 * d - 2 * v0 - v1, -2 * d + v0 + v1, T{}, T{}};
}

}  // namespace settle::core::fixed::hermite
