// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one complex type of core's private numerics (core keeps to <cmath>: no <complex>, which
// pulls in streams). The mode algebra of the planners needs only these operations: a mode's pole,
// exponentials along it, and the moduli the residual checks read.

#include <cmath>

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

inline Cx cexp(Cx a) noexcept {
  const double e = std::exp(a.re);
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

// The upper pole of the mode (omega, zeta), 0 <= zeta < 1: -zeta omega + i omega sqrt(1 - zeta^2).
inline Cx pole(double omega, double zeta) noexcept { return {-zeta * omega, omega * std::sqrt(1.0 - zeta * zeta)}; }

}  // namespace settle::core::numeric
