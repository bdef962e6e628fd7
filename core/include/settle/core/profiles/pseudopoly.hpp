// SPDX-License-Identifier: Apache-2.0
#pragma once
// Profile `pseudopoly`: Incerti's pseudo-polynomial of seed 004, with the user's exponents
// (--gammas). Timed, or the shortest within whichever of vmax, amax, jmax are given.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "settle/core/kinematics.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/pseudo_poly.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

namespace detail {
// The pseudo-polynomial hook for exponents g[0..n): designed on a unit duration (its coefficients
// depend on neither T nor D), then stretched to the time asked or the limits.
[[nodiscard]] inline Status plan_pseudopoly(const MoveRequest& r, const double* g, std::size_t n,
                                            PseudoPolyParams& out, Peaks<double>& pk) noexcept {
  PseudoPolyParams p{};
  const Status st = pseudo_poly_design(r.distance, 1.0, g, n, p);
  if (st != Status::ok) return st;
  double t = 0.0;
  if (r.time) {
    t = *r.time;
  } else {
    if (!r.limits.any()) return Status::missing_time_or_limits;
    const Peaks<double> u = pseudo_poly_unit_peaks(p);
    const double d = std::fabs(r.distance);
    if (r.limits.vmax) t = std::max(t, d * u.v / *r.limits.vmax);
    if (r.limits.amax) t = std::max(t, std::sqrt(d * u.a / *r.limits.amax));
    if (r.limits.jmax) {
      if (!std::isfinite(u.j)) return Status::jerk_limit_exceeded;
      t = std::max(t, std::cbrt(d * u.j / *r.limits.jmax));
    }
  }
  p.duration = t;
  pk = pseudo_poly_peaks(p);
  out = p;
  return Status::ok;
}
}  // namespace detail

struct PseudopolyProfile {
  static constexpr const char* name = "pseudopoly";
  static constexpr const char* summary = "pseudo-polynomial with the exponents of --gammas (seed 004)";
  template <typename T>
  using Shape = PseudoPoly<T>;
  static constexpr ParamSet params{Param::time, Param::vmax, Param::amax, Param::jmax, Param::gammas};
  [[nodiscard]] static Status plan(const MoveRequest& r, PseudoPolyParams& out, Peaks<double>& pk) noexcept {
    return detail::plan_pseudopoly(r, r.gammas.data(), r.gamma_count, out, pk);
  }
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = 3.0;
    r.time = 0.8;
    r.gamma_count = 4;
    r.gammas = {3.0, 5.0, 7.0, 9.0};
    return r;
  }
};

}  // namespace settle::core
