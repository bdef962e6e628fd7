#include "settle/core/ramp_versine.hpp"

#include <cmath>

namespace settle::core {

namespace {
constexpr double two_pi = 6.283185307179586476925286766559;
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
