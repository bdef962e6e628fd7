#include "settle/core/pseudo_poly.hpp"

#include <algorithm>
#include <cmath>

#include "extrema.hpp"
#include "settle/core/small_solve.hpp"

namespace settle::core {

Status pseudo_poly_design(double distance, double duration, const double* gammas, std::size_t count,
                          PseudoPolyParams& out) noexcept {
  if (count < 2) return Status::too_few_gammas;
  if (count > kMaxGammas) return Status::too_many_gammas;
  if (!std::isfinite(distance) || !std::isfinite(duration)) return Status::non_finite_input;
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(gammas[i])) return Status::non_finite_input;
  }
  if (!(duration > 0.0)) return Status::non_positive_time;
  for (std::size_t i = 0; i < count; ++i) {
    if (!(gammas[i] > 2.0)) return Status::gamma_too_small;
  }
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t k = i + 1; k < count; ++k) {
      if (std::fabs(gammas[i] - gammas[k]) <= 1e-9 * std::max(gammas[i], gammas[k])) {
        return Status::gammas_not_distinct;
      }
    }
  }
  std::array<std::array<double, kMaxGammas>, kMaxGammas> z{};
  std::array<double, kMaxGammas> rhs{};
  for (std::size_t i = 0; i < count; ++i) {
    double pk = 1.0;  // P(gamma, k) built up row by row
    for (std::size_t k = 0; k < count; ++k) {
      z[k][i] = pk;
      pk *= gammas[i] - static_cast<double>(k);
    }
  }
  rhs[0] = 1.0;
  if (!solve_in_place(z, rhs, count)) return Status::singular_system;
  PseudoPolyParams p{};
  p.distance = distance;
  p.duration = duration;
  p.count = count;
  for (std::size_t i = 0; i < count; ++i) {
    p.gammas[i] = gammas[i];
    p.coeffs[i] = rhs[i];
  }
  out = p;
  return Status::ok;
}

Peaks<double> pseudo_poly_unit_peaks(const PseudoPolyParams& p) noexcept {
  // Derivative k of the unit shape, in w = 1 - s: (-1)^(k+1) sum P(gamma_i, k) C_i w^(gamma_i - k).
  auto deriv = [&](int k, double s) {
    const double w = 1.0 - s;
    double acc = 0.0;
    for (std::size_t i = 0; i < p.count; ++i) {
      double pk = 1.0;
      for (int r = 0; r < k; ++r) pk *= p.gammas[i] - r;
      acc += pk * p.coeffs[i] * std::pow(w, p.gammas[i] - k);
    }
    return acc;
  };
  double gmin = p.gammas[0];
  for (std::size_t i = 1; i < p.count; ++i) gmin = std::min(gmin, p.gammas[i]);
  Peaks<double> out{};
  out.v = detail::max_abs([&](double s) { return deriv(1, s); }, 0.0, 1.0);
  out.a = detail::max_abs([&](double s) { return deriv(2, s); }, 0.0, 1.0);
  // With an exponent below 3 the jerk grows without bound as t -> T: say so instead of sampling.
  out.j = gmin < 3.0 ? infinity_v<double> : detail::max_abs([&](double s) { return deriv(3, s); }, 0.0, 1.0);
  // With two exponents only position and velocity vanish at t = 0: the acceleration steps there.
  out.acceleration_step = p.count < 3;
  if (out.acceleration_step) out.j = infinity_v<double>;
  return out;
}

Peaks<double> pseudo_poly_peaks(const PseudoPolyParams& p) noexcept {
  Peaks<double> u = pseudo_poly_unit_peaks(p);
  const double d = std::fabs(p.distance);
  const double t = p.duration;
  u.v *= d / t;
  u.a *= d / (t * t);
  u.j = d == 0.0 ? 0.0 : u.j * d / (t * t * t);
  if (d == 0.0) {
    u.v = u.a = 0.0;
  }
  return u;
}

}  // namespace settle::core
