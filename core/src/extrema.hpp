#pragma once
// Private numerical helpers of the planners: bracketing roots and scanning extrema of smooth
// one-dimensional functions. Planning time only; never on the servo path.
#include <algorithm>
#include <cmath>

namespace settle::core {

struct Range {
  double lo;
  double hi;
  void include(double x) noexcept {
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
};

namespace detail {

// Calls on_root(x) for every x in (a, b) where f(x) crosses level, found by a 64-cell sign scan
// and bisection to machine precision. Tangential touches are not roots of interest here (they
// are inflections of the integral, not extrema).
template <typename F, typename G>
void for_each_root(F&& f, double level, double a, double b, G&& on_root, int cells = 64) noexcept {
  double x0 = a;
  double g0 = f(a) - level;
  for (int i = 1; i <= cells; ++i) {
    const double x1 = a + (b - a) * i / cells;
    const double g1 = f(x1) - level;
    if ((g0 < 0.0 && g1 > 0.0) || (g0 > 0.0 && g1 < 0.0)) {
      double lo = x0, hi = x1, glo = g0;
      for (int it = 0; it < 60 && hi - lo > 1e-15 * (1.0 + std::fabs(lo)); ++it) {
        const double mid = 0.5 * (lo + hi);
        const double gm = f(mid) - level;
        if ((gm < 0.0) == (glo < 0.0)) {
          lo = mid;
          glo = gm;
        } else {
          hi = mid;
        }
      }
      on_root(0.5 * (lo + hi));
    }
    x0 = x1;
    g0 = g1;
  }
}

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
      double lo = a + (b - a) * (i - 2) / cells;
      double hi = x;
      constexpr double g = 0.6180339887498948482;
      double c = hi - g * (hi - lo);
      double d = lo + g * (hi - lo);
      double fc = std::fabs(f(c));
      double fd = std::fabs(f(d));
      for (int it = 0; it < 60 && hi - lo > 1e-14 * (b - a); ++it) {
        if (fc > fd) {
          hi = d;
          d = c;
          fd = fc;
          c = hi - g * (hi - lo);
          fc = std::fabs(f(c));
        } else {
          lo = c;
          c = d;
          fc = fd;
          d = lo + g * (hi - lo);
          fd = std::fabs(f(d));
        }
      }
      best = std::max({best, fc, fd});
    }
    prev2 = prev1;
    prev1 = cur;
  }
  return best;
}

}  // namespace detail
}  // namespace settle::core
