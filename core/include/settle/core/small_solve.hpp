// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fixed-size dense linear solve (Gaussian elimination with partial pivoting) for the small
// systems of the planners (the pseudo-polynomial's Z system, the EI shaper's Newton steps).
// Eigen's fixed-size matrices would do, but pulling Eigen into the freestanding core for an
// 8x8 solve is not worth the dependency on the Cortex-M images; this is 30 lines.
#include <array>
#include <cmath>
#include <cstddef>
#include <utility>

namespace settle::core {

// Solves m[0..n)[0..n) x = b in place (b becomes x). Returns false when a pivot is below
// tol * (largest entry of its column), i.e. the system is numerically singular.
template <std::size_t N>
[[nodiscard]] bool solve_in_place(std::array<std::array<double, N>, N>& m, std::array<double, N>& b,
                                  std::size_t n, double tol = 1e-13) noexcept {
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t piv = c;
    double scale = 0.0;
    for (std::size_t r = c; r < n; ++r) {
      scale = std::fmax(scale, std::fabs(m[r][c]));
      if (std::fabs(m[r][c]) > std::fabs(m[piv][c])) piv = r;
    }
    if (!(scale > 0.0) || std::fabs(m[piv][c]) <= tol * scale) return false;
    if (piv != c) {
      for (std::size_t k = 0; k < n; ++k) std::swap(m[piv][k], m[c][k]);  // not the columns from n on
      std::swap(b[piv], b[c]);
    }
    for (std::size_t r = c + 1; r < n; ++r) {
      const double f = m[r][c] / m[c][c];
      for (std::size_t k = c; k < n; ++k) m[r][k] -= f * m[c][k];
      b[r] -= f * b[c];
    }
  }
  for (std::size_t c = n; c-- > 0;) {
    double acc = b[c];
    for (std::size_t k = c + 1; k < n; ++k) acc -= m[c][k] * b[k];
    b[c] = acc / m[c][c];
  }
  for (std::size_t c = 0; c < n; ++c) {
    if (!std::isfinite(b[c])) return false;
  }
  return true;
}

}  // namespace settle::core
