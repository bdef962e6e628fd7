// SPDX-License-Identifier: Apache-2.0
#pragma once
// Levenberg-Marquardt with minimum-norm steps for small, fixed-size, possibly underdetermined
// systems F(y) = 0 whose Jacobian is dense over the first columns and has at most one further
// entry per row (a squared slack turning an inequality into an equality). The planner of the
// `fastest` profile solves its bang-coast switch times with it (core/src/fastest.cpp).
// Freestanding: fixed-size arrays on the stack, no heap, no exceptions.

#include <array>
#include <cmath>
#include <cstddef>

#include "settle/core/small_solve.hpp"

namespace settle::core::numeric {

// The Jacobian as it is structured: dense over the first columns ("duration" columns), and each
// later ("slack") column holding one entry, on its own row. Stored so, it takes a fraction of the
// stack of a dense kRows x kCols matrix.
template <std::size_t kRows, std::size_t kDense, std::size_t kCols>
struct SlackJacobian {
  static constexpr std::size_t kNone = kCols;
  std::array<std::array<double, kDense>, kRows> d{};  // d[row][dense column]
  std::array<std::size_t, kRows> slack_col{};         // the row's slack column, or kNone
  std::array<double, kRows> slack{};                  // and its entry
  void clear(std::size_t rows, std::size_t dense) noexcept {
    for (std::size_t r = 0; r < rows; ++r) {
      for (std::size_t c = 0; c < dense; ++c) d[r][c] = 0.0;
      slack_col[r] = kNone;
      slack[r] = 0.0;
    }
  }
  void set_slack(std::size_t row, std::size_t col, double v) noexcept {
    slack_col[row] = col;
    slack[row] = v;
  }
};

template <std::size_t N>
double norm_inf(const std::array<double, N>& f, std::size_t n) noexcept {
  double m = 0.0;
  for (std::size_t i = 0; i < n; ++i) m = std::fmax(m, std::fabs(f[i]));
  return m;
}
template <std::size_t N>
double norm2(const std::array<double, N>& f, std::size_t n) noexcept {
  double m = 0.0;
  for (std::size_t i = 0; i < n; ++i) m += f[i] * f[i];
  return m;
}

// The system's size: n unknowns, m equations, the first nd unknowns dense in the Jacobian; the
// solve stops when |F|_inf < tol.
struct LmSize {
  std::size_t n{0}, m{0}, nd{0};
  double tol{0.0};
};

// y <- y - J^T (J J^T + lambda I)^{-1} F, from y, at most max_iter steps. residuals(y, f, jac)
// fills F(y) and, when jac is not null, its Jacobian. True when |F|_inf < tol. Its stack is the
// Jacobian and one m x m matrix (J J^T is formed afresh for each damping tried).
template <std::size_t kRows, std::size_t kDense, std::size_t kCols, typename Residuals>
bool levenberg_marquardt(Residuals&& residuals, const LmSize& sz, std::array<double, kCols>& y,
                         int max_iter) noexcept {
  using EqVec = std::array<double, kRows>;
  using Jac = SlackJacobian<kRows, kDense, kCols>;
  const std::size_t n = sz.n, m = sz.m, nd = sz.nd;
  EqVec f{};
  Jac jac{};
  residuals(y, f, &jac);
  double cost = norm2(f, m);
  double lambda = 1e-6;
  int slow = 0;
  for (int it = 0; it < max_iter; ++it) {
    if (norm_inf(f, m) < sz.tol) return true;
    const double cost_before = cost;
    bool improved = false;
    // The undamped (Gauss-Newton, minimum-norm) step first: the rows differ in stiffness by many
    // orders (the end velocity against the residual sums), and damping them evenly spoils the
    // stiff ones near the solution. Then damped steps, more and more like gradient steps.
    for (int tries = 0; tries < 8 && !improved; ++tries) {
      const double lam = tries == 0 ? 0.0 : lambda;
      std::array<std::array<double, kRows>, kRows> aa;
      EqVec w{};
      // J J^T: the slack columns hold one entry each, on their own row, so they add to the
      // diagonal only (the same sums as over every column: the rest are exact zeros).
      for (std::size_t r = 0; r < m; ++r) {
        for (std::size_t c = 0; c <= r; ++c) {
          double s = 0.0;
          for (std::size_t v = 0; v < nd; ++v) s += jac.d[r][v] * jac.d[c][v];
          aa[r][c] = aa[c][r] = s;
        }
        aa[r][r] += jac.slack[r] * jac.slack[r];
        w[r] = f[r];
      }
      for (std::size_t r = 0; r < m; ++r) aa[r][r] += lam * (1.0 + aa[r][r]);
      if (!solve_in_place(aa, w, m, 1e-300)) {
        if (tries > 0) lambda *= 10.0;
        continue;
      }
      std::array<double, kCols> yn = y;
      for (std::size_t v = 0; v < nd; ++v) {
        double s = 0.0;
        for (std::size_t r = 0; r < m; ++r) s += jac.d[r][v] * w[r];
        yn[v] -= s;
      }
      for (std::size_t r = 0; r < m; ++r) {
        if (jac.slack_col[r] < n) yn[jac.slack_col[r]] -= jac.slack[r] * w[r];
      }
      // The undamped step usually succeeds: take its Jacobian with its residual (and redo the
      // old one in the rare case it does not).
      EqVec fn{};
      residuals(yn, fn, tries == 0 ? &jac : nullptr);
      const double cn = norm2(fn, m);
      if (std::isfinite(cn) && cn < cost) {
        y = yn;
        f = fn;
        cost = cn;
        if (tries > 0) {
          lambda = std::fmax(lambda * 0.1, 1e-15);
          residuals(y, f, &jac);
        }
        improved = true;
      } else {
        if (tries > 0) lambda *= 10.0;
        if (tries == 0) residuals(y, f, &jac);
      }
    }
    if (!improved) return norm_inf(f, m) < sz.tol;
    // Stagnating far from a solution (less than 1 % gained per step, three steps running):
    // this start does not lead to one; stop rather than grind.
    slow = cost > 0.99 * cost_before ? slow + 1 : 0;
    if (slow >= 3 && cost > 1e-12) return false;
  }
  return norm_inf(f, m) < sz.tol;
}

}  // namespace settle::core::numeric
