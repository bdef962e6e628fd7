// SPDX-License-Identifier: Apache-2.0
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

namespace {

// w^e for w in [0, 1]: by squaring when e is a small whole number (poly345's), std::pow otherwise.
double power(double w, double e) noexcept {
  if (e == std::floor(e) && e >= 0.0 && e <= 64.0) {
    auto n = static_cast<unsigned>(e);
    double r = 1.0, b = w;
    for (; n != 0; n >>= 1, b *= b) {
      if (n & 1u) r *= b;
    }
    return r;
  }
  return std::pow(w, e);
}

// A generalized polynomial h(w) = sum_i c[i] w^x[i] with x ascending, on 0 < w < 1.
struct GenPoly {
  std::size_t n{0};
  double c[kMaxGammas]{};
  double x[kMaxGammas]{};

  // Rolle's ladder: level j is  h_j(w) = sum_{i>=j} c_i prod_{l<j} (x_i - x_l) w^(x_i - x_j),
  // so that h_0 = w^-x_0 h and h_j' = w^(x_{j+1} - x_j - 1) h_{j+1}: between consecutive roots of
  // h_{j+1} in (0, 1), h_j is monotone. The last level is a nonzero constant.
  [[nodiscard]] double level(std::size_t j, double w) const noexcept {
    double acc = 0.0;
    for (std::size_t i = j; i < n; ++i) {
      double k = c[i];
      for (std::size_t l = 0; l < j; ++l) k *= x[i] - x[l];
      acc += k * power(w, x[i] - x[j]);
    }
    return acc;
  }
  [[nodiscard]] double level_slope(std::size_t j, double w) const noexcept {
    return j + 1 < n ? power(w, x[j + 1] - x[j] - 1.0) * level(j + 1, w) : 0.0;
  }
};

// max |f| over [0, 1] for f(w) = sum_i a_i w^e_i (e_i >= 0), exactly: at w = 0, w = 1 and at the
// roots of f' inside, isolated down Rolle's ladder of w f'(w) (at most one root per level more
// than the level above, so at most n - 1 in all).
double max_abs_gen(const double* a, const double* e, std::size_t n) noexcept {
  // w f'(w) = sum a_i e_i w^e_i, its terms sorted by exponent, zero terms dropped.
  GenPoly h{};
  for (std::size_t i = 0; i < n; ++i) {
    const double ci = a[i] * e[i];
    if (ci == 0.0) continue;
    std::size_t k = h.n++;
    for (; k > 0 && h.x[k - 1] > e[i]; --k) {
      h.x[k] = h.x[k - 1];
      h.c[k] = h.c[k - 1];
    }
    h.x[k] = e[i];
    h.c[k] = ci;
  }
  double f0 = 0.0, f1 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    f1 += a[i];
    if (e[i] == 0.0) f0 += a[i];
  }
  double best = std::max(std::fabs(f0), std::fabs(f1));
  const auto f = [&](double w) {
    double acc = 0.0;
    for (std::size_t i = 0; i < n; ++i) acc += a[i] * power(w, e[i]);
    return acc;
  };
  double roots[kMaxGammas];
  std::size_t nr = 0;  // roots of the last level: none
  for (std::size_t j = h.n >= 1 ? h.n - 1 : 0; j-- > 0;) {
    if (j + 2 == h.n) {
      // Two terms, k0 + k1 w^(x1 - x0): its one root in closed form (the level below has none).
      const double k0 = h.level(j, 0.0), k1 = h.level(j, 1.0) - k0;
      const double q = -k0 / k1;
      if (q > 0.0 && q < 1.0) roots[nr++] = std::pow(q, 1.0 / (h.x[j + 1] - h.x[j]));
      continue;
    }
    double next[kMaxGammas];
    std::size_t nn = 0;
    double lo = 0.0;
    double glo = h.level(j, 0.0);
    for (std::size_t i = 0; i <= nr; ++i) {
      const double hi = i < nr ? roots[i] : 1.0;
      const double ghi = h.level(j, hi);
      if ((glo < 0.0 && ghi > 0.0) || (glo > 0.0 && ghi < 0.0)) {
        next[nn++] = detail::bracketed_root([&](double w) { return h.level(j, w); },
                                            [&](double w) { return h.level_slope(j, w); }, lo, hi, glo);
      }
      lo = hi;
      glo = ghi;
    }
    for (std::size_t i = 0; i < nn; ++i) roots[i] = next[i];
    nr = nn;
  }
  for (std::size_t i = 0; i < nr; ++i) best = std::max(best, std::fabs(f(roots[i])));
  return best;
}

}  // namespace

Peaks<double> pseudo_poly_unit_peaks(const PseudoPolyParams& p) noexcept {
  // Derivative k of the unit shape, in w = 1 - s: (-1)^(k+1) sum P(gamma_i, k) C_i w^(gamma_i - k).
  const auto peak = [&](int k) {
    double a[kMaxGammas]{}, e[kMaxGammas]{};
    for (std::size_t i = 0; i < p.count; ++i) {
      double pk = 1.0;
      for (int r = 0; r < k; ++r) pk *= p.gammas[i] - r;
      a[i] = pk * p.coeffs[i];
      e[i] = p.gammas[i] - k;
    }
    return max_abs_gen(a, e, p.count);
  };
  double gmin = p.gammas[0];
  for (std::size_t i = 1; i < p.count; ++i) gmin = std::min(gmin, p.gammas[i]);
  Peaks<double> out{};
  out.v = peak(1);
  out.a = peak(2);
  // With an exponent below 3 the jerk grows without bound as t -> T: say so instead of evaluating.
  out.j = gmin < 3.0 ? infinity_v<double> : peak(3);
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
