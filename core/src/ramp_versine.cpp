// SPDX-License-Identifier: Apache-2.0
#include "settle/core/ramp_versine.hpp"

#include <cmath>

namespace settle::core {

namespace {
constexpr double two_pi = 6.283185307179586476925286766559;

// Generic shortest move time: the smallest T in [t_lo, t_hi] for which feasible(T) holds, by a
// geometric scan and bisection. For peaks that have no closed-form inverse.
template <typename F>
bool shortest_time(F&& feasible, double t_lo, double t_hi, double& t_out) noexcept {
  constexpr int kScan = 64;
  const double ratio = std::pow(t_hi / t_lo, 1.0 / kScan);
  double prev = t_lo;
  if (feasible(t_lo)) {
    t_out = t_lo;
    return true;
  }
  for (int i = 1; i <= kScan; ++i) {
    const double t = t_lo * std::pow(ratio, i);
    if (feasible(t)) {
      double lo = prev, hi = t;
      for (int it = 0; it < 60 && hi - lo > 1e-13 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (feasible(mid)) {
          hi = mid;
        } else {
          lo = mid;
        }
      }
      t_out = hi;
      return true;
    }
    prev = t;
  }
  return false;
}
}  // namespace

RampVersineParams ramp_versine_make(double distance, double tau, const double* fractions, double omega,
                                    double zeta) noexcept {
  if (fractions != nullptr) {
    return RampVersineParams{distance, tau, fractions[0] * distance, fractions[1] * distance, fractions[2] * distance};
  }
  return ramp_versine_zero_vibration(distance, tau, omega, zeta);
}

bool ramp_versine_shortest(double distance, double vmax, const double* fractions, double omega, double zeta,
                           double& tau) noexcept {
  const double d = std::fabs(distance);
  auto ok = [&](double t) { return ramp_versine_peaks(ramp_versine_make(distance, t, fractions, omega, zeta)).v <= vmax; };
  return shortest_time(ok, d / vmax, 1e4 * d / vmax, tau);
}

RampVersineParams ramp_versine_zero_vibration(double distance, double tau, double omega,
                                              double zeta) noexcept {
  const double r = two_pi / tau;
  const double w2 = omega * omega;
  return {distance, tau, distance * r * (r - 2.0 * zeta * omega) / w2, distance * (1.0 - r * r / w2),
          distance * 2.0 * zeta * r / omega};
}

Peaks<double> ramp_versine_peaks(const RampVersineParams& p) noexcept {
  // v = (R/2pi)(L - Y2 cos + Y3 sin): over a full period its extremes are L -+ hypot(Y2, Y3).
  const double r = two_pi / p.tau;
  const double h = std::hypot(p.y2, p.y3);
  Peaks<double> out{};
  out.v = r / two_pi * (std::fabs(p.distance) + h);
  const double step = r / two_pi * std::fabs(p.distance - p.y2);  // |y'(0+)| = |y'(tau-)|
  out.velocity_step = step > 0.0;
  // Inside the move a and j are sinusoids of amplitude R^2 h/2pi and R^3 h/2pi; the velocity
  // steps at the ends are acceleration impulses, reported as infinite.
  out.a = out.velocity_step ? infinity_v<double> : r * r / two_pi * h;
  out.j = out.velocity_step ? infinity_v<double> : r * r * r / two_pi * h;
  out.acceleration_step = std::fabs(p.y3) > 0.0;
  return out;
}

}  // namespace settle::core
