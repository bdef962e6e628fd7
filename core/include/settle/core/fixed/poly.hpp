#pragma once
// Polynomial machinery shared by the fixed-point evaluators (segments and cam tables): Taylor
// coefficients at a phase by repeated synthetic division (whose first pass is Horner's rule), and
// forward-difference chains that then advance p, v and a by one tick with additions only.
#include <array>
#include <cstdint>

#include "settle/core/fixed/format.hpp"

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
void taylor_shift(Coeffs& c, int degree, std::uint32_t s31, int passes) noexcept;
// First-order correction for the phase bits below s31 (lo in units of 2^-63): T_k += (k+1) T_{k+1} lo,
// k < count. Makes the result exact to second order in 2^-31 instead of first.
void taylor_refine(Coeffs& t, int degree, std::uint32_t lo, int count) noexcept;
// Chains for the polynomial sum_k b_k j^k in the tick count j (b_k at scale F_k).
void chains_init(const Coeffs& b, int degree, const Shifts& sh, Chains& out) noexcept;
void chains_step(Chains& ch, int degree, const Shifts& sh) noexcept;
// p, v, a of the chains' current tick, in Q32.32.
[[nodiscard]] Wide chains_value(const Chains& ch, int degree, const Shifts& sh) noexcept;

}  // namespace settle::core::fixed
