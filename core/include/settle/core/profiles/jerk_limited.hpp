// SPDX-License-Identifier: Apache-2.0
#pragma once
// Profile `jerk-limited`: the classic 7-phase jerk-limited S-curve under vmax, amax and jmax,
// time-optimal or stretched to a move time by lowering its cruise velocity.
#include <cmath>

#include "settle/core/kinematics.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/piecewise_jerk.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

struct JerkLimitedProfile {
  static constexpr const char* name = "jerk-limited";
  static constexpr const char* summary = "classic 7-phase jerk-limited S-curve (needs vmax, amax, jmax)";
  template <typename T>
  using Shape = PiecewiseJerk<T>;
  static constexpr ParamSet params{Param::time, Param::vmax, Param::amax, Param::jmax};
  [[nodiscard]] static Status plan(const MoveRequest& r, PiecewiseJerkParams& out, Peaks<double>& pk) noexcept {
    if (!r.limits.vmax || !r.limits.amax || !r.limits.jmax) return Status::missing_time_or_limits;
    const double d = std::fabs(r.distance);
    if (!r.time) {
      jerk_limited_time_optimal(r.distance, *r.limits.vmax, *r.limits.amax, *r.limits.jmax, out, &pk);
      return Status::ok;
    }
    const PiecewiseJerkParams p = jerk_limited_time_optimal(r.distance, *r.limits.vmax, *r.limits.amax, *r.limits.jmax);
    const double t = *r.time;
    if (d / *r.limits.vmax >= t) return Status::time_too_short_for_vmax;
    if (t < piecewise_duration(p)) {
      const double t_acc = piecewise_duration(trapezoid_time_optimal(r.distance, *r.limits.vmax, *r.limits.amax));
      return t < t_acc ? Status::acceleration_limit_exceeded : Status::jerk_limit_exceeded;
    }
    // Stretch to the requested time by lowering the cruise velocity: duration falls
    // monotonically as v rises, so bisection on v finds the profile of exactly duration t.
    double lo = d / t, hi = *r.limits.vmax;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (piecewise_duration(jerk_limited_time_optimal(r.distance, mid, *r.limits.amax, *r.limits.jmax)) > t) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    jerk_limited_time_optimal(r.distance, hi, *r.limits.amax, *r.limits.jmax, out, &pk);
    return Status::ok;
  }
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = 0.4;
    r.limits.vmax = 0.5;
    r.limits.amax = 2.0;
    r.limits.jmax = 20.0;
    return r;
  }
};

}  // namespace settle::core
