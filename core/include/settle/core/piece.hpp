// SPDX-License-Identifier: Apache-2.0
#pragma once
// A profile's exact decomposition into pieces, in double: over a piece's phase s (0 at its start,
// 1 at its end) the position is  P(s) = sum_k c_k s^k + Im(Z e^{2 pi i s}),  a polynomial of degree
// at most kMaxPieceDegree plus one phasor. Each closed-form shape (ramp-cycloid, ramp-versine,
// piecewise jerk) describes itself this way from its own evaluator's segment table, and the
// fixed-point builder quantises exactly these pieces (core/src/fixed/motion_build.cpp).
#include <array>
#include <cmath>
#include <cstddef>

#include "settle/core/kinematics.hpp"
#include "settle/core/trig.hpp"

namespace settle::core {

inline constexpr std::size_t kMaxPieceDegree = 5;

struct Piece {
  double start{0.0};   // s: time of the piece's start on the profile's clock
  double length{0.0};  // s
  std::array<double, kMaxPieceDegree + 1> c{};  // position (move units) per power of the phase
  double zr{0.0}, zi{0.0};                       // Z: the phasor's amplitude (move units)
  bool trig{false};
};

// The piece `pc` (a Piece, or any piece with the same members in T) at time t of the profile's
// clock (start <= t <= start + length): position, velocity, acceleration and jerk, in T, with
// core's sin_cos (std::sin and std::cos in double).
template <typename T, typename P>
[[nodiscard]] Sample<T> piece_sample(const P& pc, T t) noexcept {
  constexpr T w = T(6.283185307179586476925286766559);
  const T s = (t - pc.start) / pc.length;
  // Horner with the derivatives alongside: p = P(s), d1 = P'(s), d2 = P''(s) / 2, d3 = P^(3)(s) / 6.
  T p = T(0), d1 = T(0), d2 = T(0), d3 = T(0);
  for (std::size_t k = kMaxPieceDegree + 1; k-- > 0;) {
    d3 = d3 * s + d2;
    d2 = d2 * s + d1;
    d1 = d1 * s + p;
    p = p * s + pc.c[k];
  }
  T v = d1, a = T(2) * d2, j = T(6) * d3;  // per power of the phase
  if (pc.trig) {
    const SinCos<T> sc = sin_cos(w * s);
    p += pc.zr * sc.sin + pc.zi * sc.cos;
    v += w * (pc.zr * sc.cos - pc.zi * sc.sin);
    a -= w * w * (pc.zr * sc.sin + pc.zi * sc.cos);
    j -= w * w * w * (pc.zr * sc.cos - pc.zi * sc.sin);
  }
  const T il = T(1) / pc.length;
  return {p, v * il, a * il * il, j * il * il * il};
}

// The piece at time t of the profile's clock, in double: exactly the curve the fixed-point builder
// quantises. The simulator's one-sided evaluation at breakpoints uses it (plant/src/command.cpp).
[[nodiscard]] inline Sample<double> piece_at(const Piece& pc, double t) noexcept { return piece_sample(pc, t); }

}  // namespace settle::core
