// SPDX-License-Identifier: Apache-2.0
#pragma once
// Planning-time helpers shared by the fixed-point builders. They run in double but only with
// + - * / and exact functions (frexp, ldexp, nearbyint), never libm approximations, so the host and
// the Cortex-M images quantise the same plan to the same integers (sources built -ffp-contract=off).
#include <array>
#include <cmath>
#include <algorithm>
#include <cstdint>

#include "settle/core/fixed/format.hpp"
#include "settle/core/fixed/qmath.hpp"
#include "settle/core/status.hpp"

namespace settle::core::fixed::build {

inline constexpr double kTwoPi = 6.283185307179586476925286766559;
inline constexpr double kTwo30 = 1073741824.0;

// The scale, validated, with the output formats as factors.
struct Ctx {
  double cpu{0.0};      // counts per unit
  double dt{0.0};       // seconds per tick
  int vf{16}, af{16};
  [[nodiscard]] double v_lsb() const noexcept { return std::ldexp(1.0, -vf); }
  [[nodiscard]] double a_lsb() const noexcept { return std::ldexp(1.0, -af); }
};

[[nodiscard]] inline Status make_ctx(const Scale& s, Ctx& out) noexcept {
  if (!s.axis.valid() || s.velocity_frac_bits < 0 || s.velocity_frac_bits > 30 || s.accel_frac_bits < 0 ||
      s.accel_frac_bits > 30) {
    return Status::scale_invalid;
  }
  out = Ctx{s.axis.counts_per_unit, s.axis.period_s(), s.velocity_frac_bits, s.accel_frac_bits};
  return Status::ok;
}

// x 2^32 rounded; |x| < 2^31 is the caller's to check.
[[nodiscard]] inline std::int64_t q32(double x) noexcept {
  return static_cast<std::int64_t>(std::nearbyint(std::ldexp(x, 32)));
}

// A positive real as a 32-bit mantissa in [2^31, 2^32) and a shift (0 stays 0).
[[nodiscard]] inline Factor factor(double x) noexcept {
  if (!(x > 0.0)) return {};
  int e = 0;
  const double m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
  double mant = std::nearbyint(std::ldexp(m, 32));
  if (mant >= 4294967296.0) {
    mant = 2147483648.0;
    ++e;
  }
  return {static_cast<std::uint32_t>(mant), static_cast<std::int16_t>(32 - e)};
}

[[nodiscard]] inline double value(Factor f) noexcept { return std::ldexp(static_cast<double>(f.mant), -f.exp); }

// Exponent e with 2^(e-1) <= x < 2^e (x > 0).
[[nodiscard]] inline int exponent(double x) noexcept {
  int e = 0;
  (void)std::frexp(x, &e);
  return e;
}

// sin(2 pi x) for 0 <= x <= 1/2 by its series on [0, pi/2]: deterministic where libm is not.
[[nodiscard]] inline double sin_turns(double x) noexcept {
  const double y = kTwoPi * (x <= 0.25 ? x : 0.5 - x);
  double term = y, sum = y;
  for (int k = 1; k < 14; ++k) {
    term *= -y * y / ((2.0 * k) * (2.0 * k + 1.0));
    sum += term;
  }
  return sum;
}

// w^e for w >= 0: repeated squaring when e is a whole number (exact and libm-free), else pow.
[[nodiscard]] inline double power(double w, double e) noexcept {
  if (w <= 0.0) return e == 0.0 ? 1.0 : 0.0;
  if (e == std::nearbyint(e) && e >= 0.0 && e < 64.0) {
    double r = 1.0, b = w;
    for (auto n = static_cast<unsigned>(e); n != 0U; n >>= 1U) {
      if ((n & 1U) != 0U) r *= b;
      b *= b;
    }
    return r;
  }
  return std::pow(w, e);
}

// Binomial coefficient as a double (for error bounds over up to 2^30 ticks).
[[nodiscard]] inline double choose(double n, int k) noexcept {
  double r = 1.0;
  for (int i = 0; i < k; ++i) r *= (n - i) / (i + 1);
  return r < 0.0 ? 0.0 : r;
}

// Delta^i of j^k at j = 0 (i! S(k, i)), as poly.cpp's chains use them.
inline constexpr double kDiff[6][6] = {{1, 0, 0, 0, 0, 0},  {0, 1, 0, 0, 0, 0},    {0, 1, 2, 0, 0, 0},
                                       {0, 1, 6, 6, 0, 0},  {0, 1, 14, 36, 24, 0}, {0, 1, 30, 150, 240, 120}};

[[nodiscard]] inline double falling(int n, int r) noexcept {
  double f = 1.0;
  for (int k = 0; k < r; ++k) f *= n - k;
  return f;
}

// Bound on the sum chains_init forms for order i of derivative chain r, given bounds on the
// Taylor coefficients b_k in tick units; weight(m) scales the term of b_{m+r} (e.g. its shift).
template <typename Weight>
[[nodiscard]] double chain_sum_bound(const std::array<double, 6>& bmax, int degree, int r, int i,
                                     Weight&& weight) noexcept {
  double s = 0.0;
  for (int m = i; m + r <= degree; ++m) {
    s += kDiff[m][i] * falling(m + r, r) * bmax[static_cast<std::size_t>(m + r)] * weight(m);
  }
  return s;
}

// Magnitudes met when poly.cpp's taylor_shift runs on P = sum c_k s^k for s in [0, s_max]: the
// Taylor coefficients |T_k| = |P^(k)/k!| and every intermediate. Coefficient sums would be far too
// pessimistic for alternating polynomials (10 s^3 - 15 s^4 + 6 s^5 sums to 512 at s = 2), so the
// shift is run in double on 65 phases. Between grid points (1/64 apart) a polynomial of degree
// n <= 5 moves by at most (1/128) 2 n^2 sup|P| (Markov's inequality), so sup|P| <= max/(1 - 0.39):
// kSweepMargin covers it.
struct Sweep {
  std::array<double, 6> t{};  // sup |T_k|
  double inter{0.0};          // sup of every value the shift forms
};
inline constexpr double kSweepMargin = 1.7;

[[nodiscard]] inline Sweep sweep(const std::array<double, 6>& c, int degree, double s_max) noexcept {
  Sweep w{};
  for (int g = 0; g <= 64; ++g) {
    const double s = s_max * g / 64.0;
    std::array<double, 6> q = c;
    for (int k = 0; k < degree; ++k) {
      for (int i = degree - 1; i >= k; --i) {
        q[static_cast<std::size_t>(i)] += q[static_cast<std::size_t>(i + 1)] * s;
        w.inter = std::max(w.inter, std::fabs(q[static_cast<std::size_t>(i)]));
      }
    }
    for (std::size_t k = 0; k < 6; ++k) {
      w.t[k] = std::max(w.t[k], std::fabs(q[k]));
      w.inter = std::max(w.inter, std::fabs(q[k]));
    }
  }
  for (double& x : w.t) x *= kSweepMargin;
  w.inter *= kSweepMargin;
  return w;
}

}  // namespace settle::core::fixed::build
