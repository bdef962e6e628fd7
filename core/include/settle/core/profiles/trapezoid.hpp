// SPDX-License-Identifier: Apache-2.0
#pragma once
// Profile `trapezoid`: trapezoidal velocity, the baseline users compare against. Timed (it
// accelerates for a third of the move unless vmax binds) or time-optimal under vmax and amax.
#include <algorithm>
#include <cmath>

#include "settle/core/kinematics.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/piecewise_jerk.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

struct TrapezoidProfile {
  static constexpr const char* name = "trapezoid";
  static constexpr const char* summary = "trapezoidal velocity (acceleration steps)";
  template <typename T>
  using Shape = PiecewiseJerk<T>;
  // No jmax: its acceleration steps have no finite jerk to keep within one.
  static constexpr ParamSet params{Param::time, Param::vmax, Param::amax};
  [[nodiscard]] static Status plan(const MoveRequest& r, PiecewiseJerkParams& out, Peaks<double>& pk) noexcept {
    const double d = std::fabs(r.distance);
    PiecewiseJerkParams p{};
    if (r.time) {
      const double t = *r.time;
      if (r.limits.vmax && d / *r.limits.vmax >= t) return Status::time_too_short_for_vmax;
      // Without a binding vmax, accelerate for a third of the move (cruise at 1.5 D/T).
      const double v = r.limits.vmax ? std::min(*r.limits.vmax, 1.5 * d / t) : 1.5 * d / t;
      p = trapezoid_timed(r.distance, t, v);
    } else {
      if (!r.limits.vmax || !r.limits.amax) return Status::missing_time_or_limits;
      p = trapezoid_time_optimal(r.distance, *r.limits.vmax, *r.limits.amax);
    }
    pk = piecewise_peaks(p);
    out = p;
    return Status::ok;
  }
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = -0.3;
    r.time = 0.6;
    return r;
  }
};

}  // namespace settle::core
