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

namespace detail {
// solve_in_place's steps, inlined into each caller (solve_in_place_fixed: with n a constant).
template <std::size_t N>
[[gnu::always_inline]] inline bool solve_steps(std::array<std::array<double, N>, N>& m, std::array<double, N>& b,
                                               std::size_t n, double tol) noexcept {
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t piv = c;
    double scale = 0.0, best = std::fabs(m[c][c]);
    for (std::size_t r = c; r < n; ++r) {
      const double a = std::fabs(m[r][c]);
      if (a > scale) scale = a;  // std::fmax (a NaN entry left out), without its call
      if (a > best) {
        piv = r;
        best = a;
      }
    }
    if (!(scale > 0.0) || best <= tol * scale) return false;
    if (piv != c) {
      // Not the columns from n on, nor those before c (the lower triangle: never read again).
      for (std::size_t k = c; k < n; ++k) std::swap(m[piv][k], m[c][k]);
      std::swap(b[piv], b[c]);
    }
    for (std::size_t r = c + 1; r < n; ++r) {
      const double f = m[r][c] / m[c][c];
      // Column c below the pivot is never read again: not updated.
      for (std::size_t k = c + 1; k < n; ++k) m[r][k] -= f * m[c][k];
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
}  // namespace detail

// Solves m[0..n)[0..n) x = b in place (b becomes x). Returns false when a pivot is below
// tol * (largest entry of its column), i.e. the system is numerically singular. m is left
// holding the eliminated upper triangle and, below it, whatever the elimination did not need
// to touch (no caller reads it after the solve).
template <std::size_t N>
[[nodiscard]] bool solve_in_place(std::array<std::array<double, N>, N>& m, std::array<double, N>& b,
                                  std::size_t n, double tol = 1e-13) noexcept {
  return detail::solve_steps(m, b, n, tol);
}

// solve_in_place for n = K, a constant: the same operations in the same order (every result the
// same bits), its loops' counts known to the compiler (unrolled; on the `fastest` planner's
// Newton steps, 7 unknowns in a 23-wide matrix, a third fewer instructions).
template <std::size_t N, std::size_t K>
[[nodiscard]] bool solve_in_place_fixed(std::array<std::array<double, N>, N>& m, std::array<double, N>& b,
                                        double tol = 1e-13) noexcept {
  static_assert(K <= N);
  return detail::solve_steps(m, b, K, tol);
}

}  // namespace settle::core
