// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one quadrature of core's private numerics: composite eight-point Gauss-Legendre on equal
// panels, for integrands with no exact pieces (the pseudo-polynomial against a mode's
// exponential). Freestanding: the caller sums, so the rule works for real or complex values.

namespace settle::core::numeric {

// Eight-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree 15.
inline constexpr double kGl8X[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                    -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                    0.7966664774136267,  0.9602898564975363};
inline constexpr double kGl8W[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                    0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                    0.2223810344533745, 0.1012285362903763};

// int_lo^hi f ~ sum of w f(u) over the nodes of `panels` equal panels: visit(u, w) once per node,
// panel by panel and ascending within each, so a caller's sum is reproducible to the bit.
template <typename Visit>
void gauss_legendre_8(double lo, double hi, int panels, Visit&& visit) noexcept {
  const double hp = (hi - lo) / panels;
  for (int k = 0; k < panels; ++k) {
    const double mid = lo + (k + 0.5) * hp;
    for (int q = 0; q < 8; ++q) visit(mid + 0.5 * hp * kGl8X[q], 0.5 * hp * kGl8W[q]);
  }
}

}  // namespace settle::core::numeric
