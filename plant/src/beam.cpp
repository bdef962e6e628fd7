// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/beam.hpp"

#include <algorithm>
#include <cmath>

#include <boost/math/quadrature/gauss.hpp>

namespace settle::plant {

namespace {

// 1 - gamma without cancellation: (sin b - cos b - e^-b) / (sinh b + sin b).
double one_minus_gamma(double b) noexcept {
  return (std::sin(b) - std::cos(b) - std::exp(-b)) / (std::sinh(b) + std::sin(b));
}

// int_0^1 f for a mode shape of wavenumber beta: about one panel per radian of oscillation, 20
// Gauss-Legendre nodes each, which is exact to rounding for these entire functions and, unlike
// an adaptive rule at 1e-14, cheap even for the 40th mode.
template <typename F>
double integrate(F f, double beta) {
  const int panels = std::max(4, static_cast<int>(std::ceil(beta)));
  double acc = 0.0;
  for (int k = 0; k < panels; ++k) {
    acc += boost::math::quadrature::gauss<double, 20>::integrate(f, static_cast<double>(k) / panels,
                                                                 static_cast<double>(k + 1) / panels);
  }
  return acc;
}

}  // namespace

SimStatus validate(const BeamParams& p) noexcept {
  for (double v : {p.length, p.modulus, p.thickness, p.width, p.beam_mass, p.tip_mass}) {
    if (!std::isfinite(v)) return SimStatus::non_finite_parameter;
  }
  if (!(p.length > 0.0)) return SimStatus::non_positive_length;
  if (!(p.modulus > 0.0)) return SimStatus::non_positive_modulus;
  if (!(p.thickness > 0.0) || !(p.width > 0.0)) return SimStatus::non_positive_section;
  if (!(p.beam_mass > 0.0)) return SimStatus::non_positive_mass;
  if (p.tip_mass < 0.0) return SimStatus::negative_tip_mass;
  return SimStatus::ok;
}

double beam_characteristic(double beta, double mu) noexcept {
  const double th = std::tanh(beta);
  return 1.0 / std::cosh(beta) + std::cos(beta) + beta * mu * (std::cos(beta) * th - std::sin(beta));
}

double beam_shape(double beta, double xi) noexcept {
  const double b = beta * xi;
  const double omg = one_minus_gamma(beta);
  return std::exp(-b) + omg * std::sinh(b) - std::cos(b) + (1.0 - omg) * std::sin(b);
}

SimStatus beam_modes(const BeamParams& p, std::size_t count, std::vector<BeamMode>& out) {
  const SimStatus st = validate(p);
  if (st != SimStatus::ok) return st;
  if (count == 0 || count > kMaxBeamModes) return SimStatus::bad_mode_count;
  const double rho = p.beam_mass / p.length;
  const double mu = p.tip_mass / (rho * p.length);
  const double inertia = p.width * p.thickness * p.thickness * p.thickness / 12.0;
  const double scale_w = std::sqrt(p.modulus * inertia / (rho * std::pow(p.length, 4)));

  // Roots are about pi apart (tan b = tanh b for a heavy tip, cos b cosh b = -1 without one), and
  // the first one tends to 0 as the tip mass grows; a scan at a step far below pi from near 0
  // cannot step over a pair, and bisection then converges whatever the slope.
  std::vector<double> roots;
  constexpr double kStep = 0.01;
  double lo = 1e-6;
  double flo = beam_characteristic(lo, mu);
  const double b_max = (static_cast<double>(count) + 2.0) * 3.2 + 2.0;
  while (roots.size() < count && lo < b_max) {
    const double hi = lo + kStep;
    const double fhi = beam_characteristic(hi, mu);
    if ((flo < 0.0) != (fhi < 0.0)) {
      double a = lo, b = hi, fa = flo;
      for (int it = 0; it < 200 && b - a > 4e-16 * b; ++it) {
        const double m = 0.5 * (a + b);
        const double fm = beam_characteristic(m, mu);
        if ((fm < 0.0) == (fa < 0.0)) {
          a = m;
          fa = fm;
        } else {
          b = m;
        }
      }
      roots.push_back(0.5 * (a + b));
    }
    lo = hi;
    flo = fhi;
  }
  if (roots.size() < count) return SimStatus::root_not_found;

  std::vector<BeamMode> modes;
  for (double beta : roots) {
    BeamMode m;
    m.beta = beta;
    m.omega = beta * beta * scale_w;
    m.gamma = 1.0 - one_minus_gamma(beta);
    const double sq = integrate([beta](double xi) {
      const double s = beam_shape(beta, xi);
      return s * s;
    }, beta);
    const double lin = integrate([beta](double xi) { return beam_shape(beta, xi); }, beta);
    const double tip = beam_shape(beta, 1.0);
    // int_0^L phi^2 dx = L int_0^1 phi(xi)^2 dxi.
    m.scale = 1.0 / std::sqrt(rho * p.length * sq + p.tip_mass * tip * tip);
    m.phi_tip = m.scale * tip;
    m.lambda = -rho * p.length * m.scale * lin - p.tip_mass * m.phi_tip;
    modes.push_back(m);
  }
  out = std::move(modes);
  return SimStatus::ok;
}

}  // namespace settle::plant
