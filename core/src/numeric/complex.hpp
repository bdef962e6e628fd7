// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one complex type of core's private numerics (core keeps to <cmath>: no <complex>, which
// pulls in streams). The mode algebra of the planners needs only these operations: a mode's pole,
// exponentials along it, and the moduli the residual checks read.

#include <cmath>
// Packed (below) is a two-double vector where doubles are computed in SSE2 registers anyway (x86-64:
// __SSE2_MATH__; not where the x87 unit would round the scalar code differently).
#if defined(__SSE2__) && defined(__SSE2_MATH__)
#define SETTLE_PACKED_VECTOR 1
#include <emmintrin.h>
#else
#define SETTLE_PACKED_VECTOR 0
#endif

namespace settle::core::numeric {

struct Cx {
  double re{0.0}, im{0.0};
};
constexpr Cx operator+(Cx a, Cx b) noexcept { return {a.re + b.re, a.im + b.im}; }
constexpr Cx operator-(Cx a, Cx b) noexcept { return {a.re - b.re, a.im - b.im}; }
constexpr Cx operator*(Cx a, Cx b) noexcept { return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re}; }
constexpr Cx operator*(double s, Cx a) noexcept { return {s * a.re, s * a.im}; }
inline Cx operator/(Cx a, Cx b) noexcept {
  const double d = b.re * b.re + b.im * b.im;
  return {(a.re * b.re + a.im * b.im) / d, (a.im * b.re - a.re * b.im) / d};
}
constexpr Cx conj(Cx a) noexcept { return {a.re, -a.im}; }

// The modulus.
inline double cabs(Cx a) noexcept { return std::hypot(a.re, a.im); }
// The larger of |re| and |im|: within a factor sqrt(2) of the modulus, and without hypot's cost.
inline double cabs_max(Cx a) noexcept { return std::fmax(std::fabs(a.re), std::fabs(a.im)); }

// (An undamped mode's real part is +-0: exp(+-0) is 1 exactly, so it is not called.)
inline Cx cexp(Cx a) noexcept {
  const double e = a.re == 0.0 ? 1.0 : std::exp(a.re);
  return {e * std::cos(a.im), e * std::sin(a.im)};
}
// e^{-p t}. (An undamped mode's real part is 0: exp(+-0) is 1 exactly, so it is not called.)
inline Cx cexp_neg(Cx p, double t) noexcept {
  const double x = -p.re * t;
  const double m = x == 0.0 ? 1.0 : std::exp(x);
  return {m * std::cos(p.im * t), -m * std::sin(p.im * t)};
}
// e^{z} - 1, accurate for small |z| (a short segment's two exponentials nearly cancel). With
// z.re = +-0 (an undamped mode) expm1 is z.re and exp 1, exactly: neither is called.
inline Cx cexpm1(Cx z) noexcept {
  const double sh = std::sin(0.5 * z.im);
  const bool undamped = z.re == 0.0;
  const double em1 = undamped ? z.re : std::expm1(z.re), e = undamped ? 1.0 : std::exp(z.re);
  return {em1 * std::cos(z.im) - 2.0 * sh * sh, e * std::sin(z.im)};
}

// Repeated products by one complex factor b (a series' x, a recurrence's e^{lambda h}), where the
// host has two-double vectors (x86-64: SSE2): a = (re, im) in one register, a b computed as
// (re, im) br + (im, re) (-bi, bi), i.e. re br + (-(im bi)) and im br + re bi: the products and
// sums of operator*, lane by lane (x - y is x + (-y), and a sum does not depend on its order of
// operands), so every result is the same to the bit. Elsewhere (the Cortex-M cores) Cx itself.
#if SETTLE_PACKED_VECTOR
using Packed = __m128d;  // + and * lane by lane (GCC's and Clang's vector operators)
inline Packed pack(Cx a) noexcept { return _mm_set_pd(a.im, a.re); }
inline Cx unpack(Packed a) noexcept { return {_mm_cvtsd_f64(a), _mm_cvtsd_f64(_mm_unpackhi_pd(a, a))}; }
inline Packed splat(double s) noexcept { return _mm_set1_pd(s); }
struct PackedFactor {
  Packed re, im;  // (br, br), (-bi, bi)
  explicit PackedFactor(Cx b) noexcept : re{_mm_set1_pd(b.re)}, im{_mm_set_pd(b.im, -b.im)} {}
};
inline Packed operator*(Packed a, const PackedFactor& b) noexcept {
  return _mm_add_pd(_mm_mul_pd(a, b.re), _mm_mul_pd(_mm_shuffle_pd(a, a, 1), b.im));
}
#else
using Packed = Cx;
inline Cx pack(Cx a) noexcept { return a; }
inline Cx unpack(Cx a) noexcept { return a; }
inline double splat(double s) noexcept { return s; }
struct PackedFactor {
  Cx b;
  explicit PackedFactor(Cx f) noexcept : b{f} {}
};
inline Cx operator*(Cx a, const PackedFactor& f) noexcept { return a * f.b; }
#endif

// The upper pole of the mode (omega, zeta), 0 <= zeta < 1: -zeta omega + i omega sqrt(1 - zeta^2).
inline Cx pole(double omega, double zeta) noexcept { return {-zeta * omega, omega * std::sqrt(1.0 - zeta * zeta)}; }

}  // namespace settle::core::numeric
