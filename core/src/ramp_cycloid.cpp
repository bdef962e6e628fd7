// SPDX-License-Identifier: Apache-2.0
#include "settle/core/ramp_cycloid.hpp"

#include <algorithm>
#include <cmath>

#include "settle/core/golden_section.hpp"
#include "settle/core/mode.hpp"

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

namespace {

RampCycloidParams scurve_params(double distance, double tau, double cruise, double v, double omega,
                                double zeta) noexcept {
  const CycloidWeights w = cycloid_weights(tau, omega, zeta);
  const double sg = distance < 0.0 ? -1.0 : 1.0;
  return {distance, tau, cruise, sg * v / tau, w.c2, w.c3};
}

constexpr double inf = infinity_v<double>;

}  // namespace

// Seed 000's planning rule: with vmax the profile cruises at vmax when it must; otherwise (or when
// vmax is generous) the 4-segment profile.
Status scurve_timed(double distance, double time, double vmax, double omega, double zeta,
                    RampCycloidParams& out) noexcept {
  const double d = std::fabs(distance);
  const double t = time;
  const bool has_vmax = vmax > 0.0;
  if (has_vmax && d / vmax >= t) return Status::time_too_short_for_vmax;
  double tau = t / 4.0;
  double cruise = 0.0;
  if (has_vmax && vmax < 2.0 * d / t) {  // a cruise at vmax is needed
    // With a short transition the velocity overshoots vmax; lowering the cruise velocity only
    // shortens tau and makes that worse, so such a request is refused by the peak check.
    tau = (t * vmax - d) / (2.0 * vmax);
    cruise = t - 4.0 * tau;
  }
  out = scurve_params(distance, tau, cruise, d / (t - 2.0 * tau), omega, zeta);
  return Status::ok;
}

Status plan_fastest_scurve(double distance, double vmax, double amax, double jmax, double omega, double zeta,
                           bool damped, RampCycloidParams& out) noexcept {
  if (!std::isfinite(distance) || !std::isfinite(vmax) || !std::isfinite(amax) || std::isnan(jmax) ||
      !std::isfinite(omega) || !std::isfinite(zeta)) {
    return Status::non_finite_input;
  }
  if (!(vmax > 0.0 && amax > 0.0 && jmax > 0.0)) return Status::non_positive_limit;
  if (const Status st = mode_status(omega, zeta); st != Status::ok) return st;
  const double z = damped ? zeta : 0.0;
  const double d = std::fabs(distance);
  if (d == 0.0) {
    out = RampCycloidParams{};
    return Status::ok;
  }
  // For a transition length tau, the largest cruise velocity V that keeps every true peak
  // within its limit; the move then lasts D/V + 2 tau (with no cruise when V = D/(2 tau)).
  // Peaks scale as |v| = V vn, |a| = (V/tau) an, |j| = (V/tau^2) jn with vn, an, jn shape factors.
  // vn needs root finding, so the search first runs on a relaxation that applies vmax to V
  // alone (vn >= 1): its minimum is a lower bound, and it is the answer whenever the true
  // velocity peak there is within vmax. Only otherwise is the search repeated with vn.
  bool with_vn = false;
  auto best_v = [&](double tau) {
    const CycloidWeights w = cycloid_weights(tau, omega, z);
    const TransitionPeaks u = transition_peaks(w.c2, w.c3);
    double v = std::min({vmax, amax * tau / u.accel, d / (2.0 * tau)});
    if (std::isfinite(jmax)) v = std::min(v, jmax * tau * tau / u.jerk);
    if (with_vn && u.accel > 1.0) v = std::min(v, vmax / transition_velocity_peak(w.c2, w.c3));
    return v;
  };
  auto total = [&](double tau) { return d / best_v(tau) + 2.0 * tau; };
  const double scales[4] = {d / vmax, std::sqrt(d / amax), 6.283185307179586 / omega,
                            std::isfinite(jmax) ? std::cbrt(d / jmax) : d / vmax};
  const double s_lo = *std::min_element(scales, scales + 4) * 1e-2;
  const double s_hi = std::max(d / vmax, std::sqrt(d / amax)) * 2.0;
  auto search = [&]() {
    // Geometric scan of tau, then golden section on the best bracket. T(tau) is flat at its
    // minimum, so tau to 1e-7 gives T to far better than 1e-9.
    constexpr int kScan = 32;
    const double ratio = std::pow(s_hi / s_lo, 1.0 / kScan);
    int best = 0;
    double best_t = inf;
    for (int i = 0; i <= kScan; ++i) {
      const double t = total(s_lo * std::pow(ratio, i));
      if (t < best_t) {
        best_t = t;
        best = i;
      }
    }
    double lo = s_lo * std::pow(ratio, std::max(best - 1, 0));
    double hi = s_lo * std::pow(ratio, std::min(best + 1, kScan));
    // The minimum of total is the maximum of -total (the same probes, negation is exact).
    const GoldenProbes p = golden_section_max([&](double t) { return -total(t); }, lo, hi, 40,
                                              [](double l, double h) { return !(h - l > 1e-7 * h); });
    const double grid = s_lo * std::pow(ratio, best);
    if (best_t < -std::max(p.fc, p.fd)) return grid;
    return p.fc > p.fd ? p.c : p.d;
  };
  double tau = search();
  {
    const CycloidWeights w = cycloid_weights(tau, omega, z);
    if (best_v(tau) * transition_velocity_peak(w.c2, w.c3) > vmax * (1.0 + 1e-12)) {
      with_vn = true;
      tau = search();
    }
  }
  const double v = best_v(tau);
  const double cruise = std::max(0.0, d / v - 2.0 * tau);
  if (!std::isfinite(v) || !(v > 0.0)) return Status::no_solution;
  out = scurve_params(distance, tau, cruise, v, omega, z);
  return Status::ok;
}

}  // namespace settle::core
