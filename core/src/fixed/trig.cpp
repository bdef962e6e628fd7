// SPDX-License-Identifier: Apache-2.0
#include "settle/core/fixed/trig.hpp"

#include <array>
#include <cstdint>

#include "settle/core/fixed/qmath.hpp"

namespace settle::core::fixed {

namespace {

using i64 = std::int64_t;

constexpr double kPi = 3.14159265358979323846264338327950;

// sin x for 0 <= x <= pi/2 by its Taylor series, at compile time: the compiler folds double
// arithmetic exactly as IEEE prescribes, so host and cross builds get the same table. The series
// is summed far enough (x^27/27! < 1e-28) that the rounding below is decided by double precision.
constexpr double taylor_sin(double x) noexcept {
  double term = x, sum = x;
  for (int k = 1; k < 14; ++k) {
    term *= -x * x / ((2.0 * k) * (2.0 * k + 1.0));
    sum += term;
  }
  return sum;
}

// sin(i pi/512) in Q0.31, i = 0..256: one quarter turn; cos is read backwards.
constexpr std::array<std::uint32_t, 257> make_quarter() noexcept {
  std::array<std::uint32_t, 257> t{};
  for (int i = 0; i <= 256; ++i) {
    t[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(taylor_sin(i * (kPi / 512.0)) * 2147483648.0 + 0.5);
  }
  return t;
}
constexpr std::array<std::uint32_t, 257> kQuarter = make_quarter();

constexpr std::uint32_t kPiQ30 = 3373259426U;  // round(pi 2^30) = round(pi/2 2^31)
constexpr std::uint32_t kSixth = 0x2AAAAAABU;   // ceil(2^32 / 6)

// The quarter-turn rotation: sin and cos of (q pi/2 + phi) from those of phi.
constexpr SinCos rotate_quarters(std::uint32_t q, std::int32_t sn, std::int32_t cs) noexcept {
  switch (q & 3U) {
    case 1: return {cs, -sn};
    case 2: return {-sn, -cs};
    case 3: return {-cs, sn};
    default: return {sn, cs};
  }
}

// Q2.31 (as int64) to Q2.30, rounded.
constexpr std::int32_t q31_to_q30(i64 x) noexcept { return static_cast<std::int32_t>((x + 1) >> 1); }

}  // namespace

SinCos sincos(std::uint32_t turn) noexcept {
  // Nearest of 256 steps per quarter turn, then sin/cos(a + b) = S cos b + C sin b, C cos b - S sin b
  // with |b| <= pi/1024: sin b = b - b^3/6 and 1 - cos b = b^2/2 are exact to 2^-38. Every product
  // is 32x32 -> 64 (mul_wide).
  const std::uint32_t x = turn & 0x3FFFFFFFU;  // Q0.30 of a quarter turn
  const std::uint32_t i = (x + (1U << 21)) >> 22;
  const auto r = static_cast<std::int32_t>(x - (i << 22));                 // [-2^21, 2^21]
  const auto b = static_cast<std::int32_t>(mul_wide(r, kPiQ30) >> 25);    // radians, Q36, |b| < 2^28
  const auto bb = static_cast<std::int32_t>(mul_wide(b, b) >> 36);        // b^2, Q36
  const std::int32_t h = bb >> 1;                                          // 1 - cos b
  const auto bb6 = static_cast<std::int32_t>(mul_wide(bb, kSixth) >> 32);  // b^2/6, no division
  const auto g = static_cast<std::int32_t>(b - (mul_wide(b, bb6) >> 36));       // sin b
  const std::uint32_t s = kQuarter[i];
  const std::uint32_t c = kQuarter[256U - i];
  const i64 s37 = (static_cast<i64>(s) << 6) - (mul_wide(h, s) >> 30) + (mul_wide(g, c) >> 30);
  const i64 c37 = (static_cast<i64>(c) << 6) - (mul_wide(h, c) >> 30) - (mul_wide(g, s) >> 30);
  return rotate_quarters(turn >> 30, static_cast<std::int32_t>((s37 + 64) >> 7),
                         static_cast<std::int32_t>((c37 + 64) >> 7));
}

SinCos sincos_poly(std::uint32_t turn) noexcept {
  // Nearest quarter turn, |y| <= pi/4: sin y = y - y z (1/3! - z/5! + ...), cos y = 1 - z (1/2! - ...),
  // z = y^2, each tail by Horner in Q0.31 up to the term below 2^-36.
  static constexpr std::int32_t kSinTail[5] = {54, -5918, 426088, -17895697, 357913941};
  static constexpr std::int32_t kCosTail[6] = {-4, 592, -53261, 2982616, -89478485, 1073741824};
  const std::uint32_t q = (turn + (1U << 29)) >> 30;
  const auto y = static_cast<std::int32_t>(turn - (q << 30));               // [-2^29, 2^29)
  const auto yr = static_cast<std::int32_t>(mul_wide(y, kPiQ30) >> 30);     // radians, Q31
  const auto z = static_cast<std::int32_t>(mul_wide(yr, yr) >> 31);
  std::int32_t ts = kSinTail[0];
  for (int k = 1; k < 5; ++k) ts = kSinTail[k] + static_cast<std::int32_t>(mul_wide(ts, z) >> 31);
  std::int32_t tc = kCosTail[0];
  for (int k = 1; k < 6; ++k) tc = kCosTail[k] + static_cast<std::int32_t>(mul_wide(tc, z) >> 31);
  const i64 sn = yr - (mul_wide(yr, static_cast<std::int32_t>(mul_wide(z, ts) >> 31)) >> 31);
  const i64 cs = (i64{1} << 31) - (mul_wide(z, tc) >> 31);
  return rotate_quarters(q, q31_to_q30(sn), q31_to_q30(cs));
}

}  // namespace settle::core::fixed
