#include "settle/core/ramp_cycloid.hpp"

#include <algorithm>
#include <cmath>

namespace settle::core {

namespace {

constexpr double two_pi = 6.283185307179586476925286766559;

// One normalised transition (A = 1, tau = 1). Its jerk 1 - R cos(theta + phi) has at most two
// zeros, known in closed form, so r_a is monotone on at most three pieces of [0, 1]: roots of
// r_a = level are bracketed exactly and found by safeguarded Newton, without any scan.
struct Transition {
  CycloidShape<double> sh;
  double cuts[4];   // 0, critical points in order, 1
  double ra_at[4];  // r_a at each cut
  int ncuts;

  Transition(double c2, double c3) noexcept
      : sh{c2, c3}, cuts{0.0, 1.0, 1.0, 1.0}, ra_at{0.0, 1.0, 1.0, 1.0}, ncuts{2} {
    const double r = std::hypot(c2, c3);
    if (r > 1.0) {
      const double phi = std::atan2(c3, c2);
      const double base = std::acos(1.0 / r);
      double s[2];
      int k = 0;
      for (double th : {base - phi, -base - phi}) {
        th = std::fmod(th, two_pi);
        if (th < 0.0) th += two_pi;
        s[k++] = th / two_pi;
      }
      if (s[0] > s[1]) std::swap(s[0], s[1]);
      cuts[0] = 0.0;
      cuts[1] = s[0];
      cuts[2] = s[1];
      cuts[3] = 1.0;
      ncuts = 4;
      ra_at[1] = ra(s[0]);
      ra_at[2] = ra(s[1]);
      ra_at[3] = 1.0;
    }
  }
  [[nodiscard]] double ra(double s) const noexcept {
    const double th = two_pi * s;
    return sh.ra(s, std::sin(th), std::cos(th));
  }
  [[nodiscard]] double rv(double s) const noexcept {
    const double th = two_pi * s;
    return sh.rv(s, std::sin(th), std::cos(th));
  }

  // Root of r_a(s) = level inside the monotone piece [lo, hi] (sign change assumed).
  [[nodiscard]] double root(double level, double lo, double hi) const noexcept {
    double glo = ra(lo) - level;
    double s = 0.5 * (lo + hi);
    for (int it = 0; it < 60; ++it) {
      const double th = two_pi * s;
      const double sn = std::sin(th), cs = std::cos(th);
      const double g = sh.ra(s, sn, cs) - level;
      if (g == 0.0) return s;
      if ((g < 0.0) == (glo < 0.0)) {
        lo = s;
        glo = g;
      } else {
        hi = s;
      }
      const double d = sh.rj(sn, cs);
      double next = d != 0.0 ? s - g / d : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      // The roots are where the velocity is stationary, so an error e in s moves the velocity
      // peak by ~e^2: 1e-12 is far below anything measurable. (A tighter tolerance would chase
      // the rounding noise of r_a, which has cancellation when |c2| is large.)
      if (std::fabs(next - s) <= 1e-12 || hi - lo <= 1e-12) return next;
      s = next;
    }
    return s;
  }

  template <typename F>
  void for_each_root(double level, F&& on_root) const noexcept {
    for (int i = 0; i + 1 < ncuts; ++i) {
      const double lo = cuts[i], hi = cuts[i + 1];
      if (!(hi > lo)) continue;
      const double glo = ra_at[i] - level, ghi = ra_at[i + 1] - level;
      if ((glo < 0.0 && ghi > 0.0) || (glo > 0.0 && ghi < 0.0)) on_root(root(level, lo, hi));
    }
  }
};

TransitionPeaks accel_jerk_peaks(const Transition& tr) noexcept;

}  // namespace

CycloidWeights cycloid_weights(double tau, double omega, double zeta) noexcept {
  // Derivation in docs/scurve-damped.md: the jerk pulse of a transition must have a zero Laplace
  // transform at the mode's pole, which gives two real linear equations in c2 and c3.
  const double r = (two_pi / tau) / omega;
  return {1.0 - r * r, 2.0 * zeta * r};
}

namespace {

TransitionPeaks accel_jerk_peaks(const Transition& tr) noexcept {
  double rmin = 0.0, rmax = 1.0;  // r_a(0) = 0, r_a(1) = 1
  for (int i = 1; i + 1 < tr.ncuts; ++i) {
    const double v = tr.ra_at[i];
    rmin = std::min(rmin, v);
    rmax = std::max(rmax, v);
  }
  return {std::max(rmax, 1.0 - rmin), 1.0 + std::hypot(tr.sh.c2, tr.sh.c3)};
}

}  // namespace

TransitionPeaks transition_peaks(double c2, double c3) noexcept { return accel_jerk_peaks(Transition{c2, c3}); }

namespace {

// Velocity peak of the whole profile in units of A*tau. f0 = r_v on a rising transition,
// f1 = rv1 + s - r_v on a falling one; the decelerating half gives 1 - f0 and 1 - f1. Each is
// monotone unless the acceleration overshoots; interior extrema sit where r_a = 0 (for f0) or
// r_a = 1 (for f1).
double velocity_peak(const Transition& tr) noexcept {
  double lo0 = 0.0, hi0 = tr.sh.rv1, lo1 = tr.sh.rv1, hi1 = 1.0;
  tr.for_each_root(0.0, [&](double s) {
    const double v = tr.rv(s);
    lo0 = std::min(lo0, v);
    hi0 = std::max(hi0, v);
  });
  tr.for_each_root(1.0, [&](double s) {
    const double v = tr.sh.rv1 + s - tr.rv(s);
    lo1 = std::min(lo1, v);
    hi1 = std::max(hi1, v);
  });
  return std::max({std::fabs(lo0), std::fabs(hi0), std::fabs(lo1), std::fabs(hi1), std::fabs(1.0 - lo0),
                   std::fabs(1.0 - hi0), std::fabs(1.0 - lo1), std::fabs(1.0 - hi1)});
}

}  // namespace

double transition_velocity_peak(double c2, double c3) noexcept { return velocity_peak(Transition{c2, c3}); }

Peaks<double> ramp_cycloid_peaks(const RampCycloidParams& p) noexcept {
  Peaks<double> out{};
  const double a = std::fabs(p.amplitude);
  if (a == 0.0 || !(p.tau > 0.0)) return out;
  const Transition tr{p.c2, p.c3};
  const TransitionPeaks tp = accel_jerk_peaks(tr);
  out.a = a * tp.accel;
  out.j = a / p.tau * tp.jerk;
  out.v = a * p.tau * velocity_peak(tr);
  return out;
}

}  // namespace settle::core
