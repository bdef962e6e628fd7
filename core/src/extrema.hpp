// SPDX-License-Identifier: Apache-2.0
#pragma once
// Private numerical helpers of the planners: extrema of one-dimensional functions, exactly for
// piecewise polynomial-plus-phasor motions (max_abs_derivative) and by a dense scan for anything
// else (max_abs). Planning time only; never on the servo path.
#include <algorithm>
#include <cmath>

#include "settle/core/golden_section.hpp"

namespace settle::core {

namespace detail {

// Maximum of |f| over [a, b]: a dense scan, then golden-section refinement around every local
// maximum of the scan. Accurate to ~1e-12 relative for the smooth shapes of this library.
template <typename F>
double max_abs(F&& f, double a, double b, int cells = 256) noexcept {
  double best = 0.0;
  double prev2 = std::fabs(f(a));
  double prev1 = std::fabs(f(a + (b - a) / cells));
  best = std::max(prev2, prev1);
  for (int i = 2; i <= cells; ++i) {
    const double x = a + (b - a) * i / cells;
    const double cur = std::fabs(f(x));
    best = std::max(best, cur);
    if (prev1 >= prev2 && prev1 >= cur) {
      // local maximum of the scan near x - h: refine on [x - 2h, x]
      const double tol = 1e-14 * (b - a);
      const GoldenProbes p = golden_section_max([&](double t) { return std::fabs(f(t)); },
                                                a + (b - a) * (i - 2) / cells, x, 60,
                                                [tol](double lo, double hi) { return !(hi - lo > tol); });
      best = std::max({best, p.fc, p.fd});
    }
    prev2 = prev1;
    prev1 = cur;
  }
  return best;
}

// A root of g on [lo, hi] where g changes sign (glo = g(lo)) and is monotone: Newton steps kept
// inside the shrinking bracket, bisection when a step leaves it. dg is g's derivative. At most 64
// iterations; the bracket shrinks at least by half on every rejected step. It stops within 1e-13
// of the bracket's width of the root (or a few ulps): an extremum's value is quadratic in its
// abscissa's error, so that is already far below the peaks' 1e-9 relative accuracy.
template <typename G, typename DG>
double bracketed_root(G&& g, DG&& dg, double lo, double hi, double glo) noexcept {
  const double tol = std::max(4e-16 * (std::fabs(lo) + std::fabs(hi)), 1e-13 * (hi - lo)) + 1e-300;
  double x = 0.5 * (lo + hi);
  for (int it = 0; it < 64; ++it) {
    const double gx = g(x);
    if (gx == 0.0) return x;
    if ((gx < 0.0) == (glo < 0.0)) {
      lo = x;
      glo = gx;
    } else {
      hi = x;
    }
    if (hi - lo <= tol) break;
    const double d = dg(x);
    double xn = d != 0.0 ? x - gx / d : lo;
    if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
    const bool converged = std::fabs(xn - x) <= tol;
    x = xn;
    if (converged) break;
  }
  return x;
}

// The motion on one interval of a piecewise profile (or of a sum of delayed copies of one),
// in local time x in [0, len]:  F(x) = sum_k b[k] x^k + Im(W e^{i w x}),  W = wr + i wi
// (w = 0: no phasor). Polynomial pieces and ramp-cycloid / versine pieces (piece.hpp) both sum to
// this form on every interval between their breakpoints, as long as their phasors share one period.
struct PhasorPoly {
  static constexpr int kDegree = 5;
  double b[kDegree + 1]{};
  double wr{0.0}, wi{0.0};
  double w{0.0};

  // k! / (k - r)! for k <= kDegree, r <= kDegree + 1 (0 when r > k).
  static constexpr double falling(int k, int r) noexcept {
    double f = 1.0;
    for (int q = 0; q < r; ++q) f *= static_cast<double>(k - q);
    return f;
  }

  // F^(r)(x).
  [[nodiscard]] double deriv(int r, double x) const noexcept {
    struct Table {
      double t[kDegree + 1][kDegree + 2];
    };
    static constexpr Table kFalling = [] {
      Table tb{};
      for (int k = 0; k <= kDegree; ++k) {
        for (int q = 0; q <= kDegree + 1; ++q) tb.t[k][q] = falling(k, q);
      }
      return tb;
    }();
    double acc = 0.0;
    for (int k = kDegree; k >= r; --k) acc = acc * x + kFalling.t[k][r] * b[k];
    if (w != 0.0) {
      const double c = std::cos(w * x), s = std::sin(w * x);
      const double er = wr * c - wi * s, ei = wr * s + wi * c;  // W e^{i w x}
      double im = 0.0;  // Im(i^r W e^{i w x})
      switch (r & 3) {
        case 0: im = ei; break;
        case 1: im = er; break;
        case 2: im = -ei; break;
        default: im = -er; break;
      }
      double wp = 1.0;
      for (int q = 0; q < r; ++q) wp *= w;
      acc += wp * im;
    }
    return acc;
  }
  [[nodiscard]] int degree() const noexcept {
    int m = kDegree;
    while (m > 0 && b[m] == 0.0) --m;
    return m;
  }
};

// max |F^(r)| over [0, len], exactly: F^(r) at both ends and at every root of F^(r+1) inside.
// The roots are isolated by Rolle's cascade: F^(top) is a pure sinusoid (its roots in closed
// form, top = degree + 1) or a nonzero constant (no roots, top = degree); between consecutive roots
// of F^(k+1), F^(k) is monotone and has at most one root, bracketed and refined. Each level adds at
// most one root to the one above, and a pure sinusoid has at most 3 roots on one period, so the
// root lists stay within a small fixed bound.
[[nodiscard]] inline double max_abs_derivative(const PhasorPoly& f, int r, double len) noexcept {
  constexpr int kMaxRoots = PhasorPoly::kDegree + 8;
  double roots[kMaxRoots];
  int n = 0;
  const int m = f.degree();
  int top;
  if (f.w != 0.0 && (f.wr != 0.0 || f.wi != 0.0)) {
    top = std::max(m + 1, r + 1);
    // F^(top) = w^top Im(i^top W e^{iwx}) = w^top |W| sin(phi + w x), phi = arg(i^top W).
    constexpr double kPi = 3.14159265358979323846;
    const double phi = std::atan2(f.wi, f.wr) + 0.5 * kPi * static_cast<double>(top & 3);
    // roots: w x = j pi - phi for integers j, inside (0, len)
    double j = std::floor(phi / kPi) + 1.0;
    for (; n < 4; j += 1.0) {
      const double x = (j * kPi - phi) / f.w;
      if (!(x < len)) break;
      if (x > 0.0) roots[n++] = x;
    }
  } else {
    top = m;  // F^(m) is constant: no roots
    if (top <= r) {
      return std::max(std::fabs(f.deriv(r, 0.0)), std::fabs(f.deriv(r, len)));
    }
  }
  // Down the cascade: roots of F^(k) from those of F^(k+1), for k = top - 1 .. r + 1.
  for (int k = top - 1; k >= r + 1; --k) {
    double next[kMaxRoots];
    int nn = 0;
    double lo = 0.0;
    double glo = f.deriv(k, lo);
    for (int i = 0; i <= n && nn < kMaxRoots; ++i) {
      const double hi = i < n ? roots[i] : len;
      const double ghi = f.deriv(k, hi);
      if (glo == 0.0 && lo > 0.0) {
        if (nn == 0 || next[nn - 1] < lo) next[nn++] = lo;
      } else if ((glo < 0.0 && ghi > 0.0) || (glo > 0.0 && ghi < 0.0)) {
        next[nn++] = bracketed_root([&](double x) { return f.deriv(k, x); },
                                    [&](double x) { return f.deriv(k + 1, x); }, lo, hi, glo);
      }
      lo = hi;
      glo = ghi;
    }
    for (int i = 0; i < nn; ++i) roots[i] = next[i];
    n = nn;
  }
  double best = std::max(std::fabs(f.deriv(r, 0.0)), std::fabs(f.deriv(r, len)));
  for (int i = 0; i < n; ++i) best = std::max(best, std::fabs(f.deriv(r, roots[i])));
  return best;
}

}  // namespace detail
}  // namespace settle::core
