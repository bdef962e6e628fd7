// SPDX-License-Identifier: Apache-2.0
#pragma once
// The integral of a profile against a mode's exponential, F(te) = int_0^te e^{lambda (te - u)} p(u) du:
// exactly, piece by piece, where the profile has pieces (piece.hpp), by Gauss-Legendre quadrature
// otherwise (the pseudo-polynomial). Private to core: the residual (residual.hpp) and the online
// blends (online.cpp) are built on it. Defined in residual.cpp.
#include <algorithm>
#include <cmath>

#include "numeric/complex.hpp"
#include "numeric/quadrature.hpp"
#include "settle/core/piece.hpp"

namespace settle::core::detail {

using numeric::Cx;

// phi1(x) = (e^x - 1) / x and phi2(x) = (e^x - 1 - x) / x^2, by their series near 0 where the
// closed forms cancel. Given ex = cexp(x), read only where the closed form is taken (|x| >= 0.5,
// resp. 1; pass anything otherwise): the blend's system has the exponential already.
[[nodiscard]] Cx phi1(Cx x, Cx ex) noexcept;
[[nodiscard]] Cx phi2(Cx x, Cx ex) noexcept;
// phi1 computing its own exponential where it needs one.
[[nodiscard]] Cx phi1(Cx x) noexcept;

// int over one piece, from its start to u_c = min(end, te), of e^{lambda (te - u)} P(u) du, exactly.
// With u = u_c - L sigma the kernel decays along sigma (Re lambda <= 0): no overflow for long
// pieces or heavy damping.
[[nodiscard]] Cx piece_integral(const Piece& pc, Cx lam, double te) noexcept;

// F(te) = int_0^te e^{lambda (te - u)} p(u) du for an unshaped profile (p = D past its end).
template <typename Shape>
[[nodiscard]] Cx profile_integral(const Shape& prof, Cx lam, double te) noexcept {
  const double tp = prof.duration();
  Cx acc{};
  const double body = std::min(te, tp);
  if constexpr (requires { prof.piece_count(); }) {
    for (int i = 0; i < prof.piece_count(); ++i) {
      const Piece pc = prof.piece(i);
      if (!(pc.length > 0.0) || pc.start >= body) continue;
      acc = acc + piece_integral(pc, lam, te);
    }
  } else {
    // No exact pieces (the pseudo-polynomial): composite Gauss-Legendre on panels short against
    // the mode's time scale, so that the exponential is resolved to rounding.
    if (body > 0.0) {
      const int panels = std::clamp(static_cast<int>(std::ceil(cabs_max(lam) * body)) * 2, 32, 512);
      numeric::gauss_legendre_8(0.0, body, panels,
                                [&](double u, double w) { acc = acc + (w * prof.at(u).p) * cexp((te - u) * lam); });
    }
  }
  if (te > tp) acc = acc + (prof.distance() * (te - tp)) * phi1((te - tp) * lam);
  return acc;
}

}  // namespace settle::core::detail
