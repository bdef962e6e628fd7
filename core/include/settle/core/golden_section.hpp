// SPDX-License-Identifier: Apache-2.0
#pragma once
// Golden-section search for a maximum of a function that is unimodal on a bracket: the one
// implementation behind the extremum refinement of the planners' peaks (core/src/extrema.hpp),
// the cycloid ramp's duration search and the tuner's search for the worst plant in a band.
// Freestanding (no heap, no exceptions): it runs wherever its callers do.

namespace settle::core {

// (sqrt(5) - 1) / 2: each step keeps this fraction of the bracket.
inline constexpr double kGoldenSection = 0.6180339887498948482;

// The two interior probes the search ended with (c < d) and the function's values there.
struct GoldenProbes {
  double c{0.0};
  double fc{0.0};
  double d{0.0};
  double fd{0.0};
};

// Shrinks [lo, hi] towards a maximum of f, one evaluation of f per step: at most `steps` steps
// after the first two probes, fewer once `done(lo, hi)` holds (a width reached, or a caller's
// evaluation failed). To minimise, maximise -f: the probes and the steps are the same.
template <typename F, typename Done>
GoldenProbes golden_section_max(F&& f, double lo, double hi, int steps, Done&& done) {
  constexpr double g = kGoldenSection;
  GoldenProbes p{hi - g * (hi - lo), 0.0, lo + g * (hi - lo), 0.0};
  p.fc = f(p.c);
  p.fd = f(p.d);
  for (int it = 0; it < steps && !done(lo, hi); ++it) {
    if (p.fc > p.fd) {
      hi = p.d;
      p.d = p.c;
      p.fd = p.fc;
      p.c = hi - g * (hi - lo);
      p.fc = f(p.c);
    } else {
      lo = p.c;
      p.c = p.d;
      p.fc = p.fd;
      p.d = lo + g * (hi - lo);
      p.fd = f(p.d);
    }
  }
  return p;
}

}  // namespace settle::core
