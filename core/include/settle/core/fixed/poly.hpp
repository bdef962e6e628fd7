// SPDX-License-Identifier: Apache-2.0
#pragma once
// Polynomial machinery shared by the fixed-point evaluators (segments and cam tables): Taylor
// coefficients at a phase by repeated synthetic division (whose first pass is Horner's rule), and
// forward-difference chains that then advance p, v and a by one tick with additions only.
#include <array>
#include <cstdint>

#include "settle/core/fixed/format.hpp"
#include "settle/core/fixed/qmath.hpp"

namespace settle::core::fixed {

inline constexpr int kMaxDegree = 5;
using Coeffs = std::array<std::int64_t, kMaxDegree + 1>;  // Q32.32 counts per power of the phase
using Shifts = std::array<std::uint8_t, kMaxDegree + 1>;  // sh[i] = F_i - F_{i-1}, sh[0] unused

// Forward differences of p (order i at scale 2^-F_i), of v (order i at F_{i+1}) and of a (F_{i+2}),
// F_0 = 32: higher orders are tiny in long segments and keep ~60 significant bits at their own scale.
struct Chains {
  std::array<std::int64_t, kMaxDegree + 1> p{};
  std::array<std::int64_t, kMaxDegree> v{};
  std::array<std::int64_t, kMaxDegree - 1> a{};
};

// c[0..degree] becomes the Taylor coefficients T_k = P^(k)(s)/k! for k < passes (and T_degree).
inline void taylor_shift(Coeffs& c, int degree, std::uint32_t s31, int passes) noexcept {
  for (int k = 0; k < passes; ++k) {
    for (int i = degree - 1; i >= k; --i) {
      c[static_cast<unsigned>(i)] += mul_shr(c[static_cast<unsigned>(i + 1)], s31, 31U);
    }
  }
}

// First-order correction for the phase bits below s31 (lo in units of 2^-63): T_k += (k+1) T_{k+1} lo,
// k < count. Makes the result exact to second order in 2^-31 instead of first.
inline void taylor_refine(Coeffs& t, int degree, std::uint32_t lo, int count) noexcept {
  for (int k = 0; k < count && k < degree; ++k) {
    const std::int64_t d = mul_shr(t[static_cast<unsigned>(k + 1)], lo, 63U);
    for (int j = 0; j <= k; ++j) t[static_cast<unsigned>(k)] += d;  // (k + 1) d without a 64-bit multiply
  }
}

// Chains for the polynomial sum_k b_k j^k in the tick count j (b_k at scale F_k).
void chains_init(const Coeffs& b, int degree, const Shifts& sh, Chains& out) noexcept;

// One tick: every difference takes the next order's (already at its own scale, sh <= 62).
template <unsigned D>
inline void chains_step_degree(Chains& ch, const Shifts& sh) noexcept {
  for (unsigned i = 0; i < D; ++i) ch.p[i] += ch.p[i + 1] >> sh[i + 1];
  for (unsigned i = 0; i + 1 < D; ++i) ch.v[i] += ch.v[i + 1] >> sh[i + 2];
  for (unsigned i = 0; i + 2 < D; ++i) ch.a[i] += ch.a[i + 1] >> sh[i + 3];
}

// Dispatched on the degree so that each loop is unrolled: on a Cortex-M0 that halves the cost.
inline void chains_step(Chains& ch, int degree, const Shifts& sh) noexcept {
  switch (degree) {
    case 1: chains_step_degree<1>(ch, sh); break;
    case 2: chains_step_degree<2>(ch, sh); break;
    case 3: chains_step_degree<3>(ch, sh); break;
    case 4: chains_step_degree<4>(ch, sh); break;
    case 5: chains_step_degree<5>(ch, sh); break;
    default: break;
  }
}

// p, v, a of the chains' current tick, in Q32.32.
[[nodiscard]] inline Wide chains_value(const Chains& ch, int degree, const Shifts& sh) noexcept {
  Wide w{ch.p[0], 0, 0};
  if (degree >= 1) w.v = ch.v[0] >> sh[1];
  if (degree >= 2) w.a = shift(ch.a[0], sh[1] + sh[2]);
  return w;
}

}  // namespace settle::core::fixed
