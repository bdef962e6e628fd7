#pragma once
// Private numerical helper of the planners: scanning the extrema of smooth one-dimensional
// functions. Planning time only; never on the servo path.
#include <algorithm>
#include <cmath>

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
