// SPDX-License-Identifier: Apache-2.0
#include "settle/core/piecewise_jerk.hpp"

#include <algorithm>
#include <cmath>

namespace settle::core {

namespace {

// Appends a segment, dropping zero-length ones so that segment lookups never see them.
void push(PiecewiseJerkParams& p, double d, double a0, double j) noexcept {
  if (!(d > 0.0)) return;
  p.durations[p.count] = d;
  p.accel0[p.count] = a0;
  p.jerk[p.count] = j;
  ++p.count;
}

PiecewiseJerkParams trapezoid_segments(double distance, double ta, double tc, double a) noexcept {
  const double sg = distance < 0.0 ? -1.0 : 1.0;
  PiecewiseJerkParams p{};
  p.distance = distance;
  push(p, ta, sg * a, 0.0);
  push(p, tc, 0.0, 0.0);
  push(p, ta, -sg * a, 0.0);
  return p;
}

}  // namespace

PiecewiseJerkParams trapezoid_time_optimal(double distance, double vmax, double amax) noexcept {
  const double d = std::fabs(distance);
  double ta = vmax / amax;
  double v = vmax;
  if (d < vmax * vmax / amax) {  // never reaches vmax: triangle
    ta = std::sqrt(d / amax);
    v = amax * ta;
  }
  const double tc = v > 0.0 ? d / v - ta : 0.0;
  return trapezoid_segments(distance, ta, std::max(tc, 0.0), amax);
}

PiecewiseJerkParams trapezoid_timed(double distance, double duration, double v) noexcept {
  const double d = std::fabs(distance);
  const double ta = duration - d / v;
  const double a = ta > 0.0 ? v / ta : 0.0;
  return trapezoid_segments(distance, ta, std::max(duration - 2.0 * ta, 0.0), a);
}

PiecewiseJerkParams jerk_limited_time_optimal(double distance, double vmax, double amax, double jmax,
                                              Peaks<double>* peaks) noexcept {
  PiecewiseJerkParams p;
  jerk_limited_time_optimal(distance, vmax, amax, jmax, p, peaks);
  return p;
}

void jerk_limited_time_optimal(double distance, double vmax, double amax, double jmax, PiecewiseJerkParams& p,
                               Peaks<double>* peaks) noexcept {
  // Classic construction (e.g. Biagiotti & Melchiorri, ch. 3): accelerate with phases tj, ta-2tj, tj,
  // cruise tv, then the mirror image. Each case is the largest of: vmax reached or not, amax
  // reached or not.
  const double d = std::fabs(distance);
  double tj, ta, tv;
  if (vmax * jmax >= amax * amax) {
    tj = amax / jmax;
    ta = tj + vmax / amax;
  } else {
    tj = std::sqrt(vmax / jmax);
    ta = 2.0 * tj;
  }
  tv = d / vmax - ta;
  if (tv < 0.0) {
    tv = 0.0;
    // vmax not reached. With an amax plateau: d = amax (ta - tj) ta.
    tj = amax / jmax;
    ta = 0.5 * (tj + std::sqrt(tj * tj + 4.0 * d / amax));
    if (ta < 2.0 * tj) {  // no plateau either: d = 2 jmax tj^3
      tj = std::cbrt(d / (2.0 * jmax));
      ta = 2.0 * tj;
    }
  }
  const double sg = distance < 0.0 ? -1.0 : 1.0;
  const double alim = jmax * tj;
  p.distance = distance;
  p.count = 0;
  if (peaks != nullptr) *peaks = Peaks<double>{};
  if (d == 0.0) return;
  // The acceleration pulse (ramp, plateau, ramp) reaches alim and ends at the cruise velocity
  // alim (ta - tj), the move's peak; the deceleration mirrors it.
  if (peaks != nullptr) *peaks = Peaks<double>{alim * (ta - tj), alim, jmax};
  push(p, tj, 0.0, sg * jmax);
  push(p, ta - 2.0 * tj, sg * alim, 0.0);
  push(p, tj, sg * alim, -sg * jmax);
  push(p, tv, 0.0, 0.0);
  push(p, tj, 0.0, -sg * jmax);
  push(p, ta - 2.0 * tj, -sg * alim, 0.0);
  push(p, tj, -sg * alim, sg * jmax);
}

double piecewise_duration(const PiecewiseJerkParams& p) noexcept {
  double t = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) t += p.durations[i];
  return t;
}

Peaks<double> piecewise_peaks(const PiecewiseJerkParams& p) noexcept {
  Peaks<double> out{};
  double v = 0.0, a_end = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) {
    const double d = p.durations[i], a0 = p.accel0[i], j = p.jerk[i];
    if (std::fabs(a0 - a_end) > 1e-12 * std::max(1.0, std::fabs(a0))) out.acceleration_step = true;
    out.a = std::max({out.a, std::fabs(a0), std::fabs(a0 + j * d)});
    out.j = std::max(out.j, std::fabs(j));
    // interior velocity extremum where a0 + j u = 0
    if (j != 0.0) {
      const double u = -a0 / j;
      if (u > 0.0 && u < d) out.v = std::max(out.v, std::fabs(v + a0 * u + j * u * u / 2.0));
    }
    v += a0 * d + j * d * d / 2.0;
    a_end = a0 + j * d;
    out.v = std::max(out.v, std::fabs(v));
  }
  if (std::fabs(a_end) > 1e-12) out.acceleration_step = true;
  if (out.acceleration_step) out.j = infinity_v<double>;
  return out;
}

}  // namespace settle::core
