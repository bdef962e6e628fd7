// SPDX-License-Identifier: Apache-2.0
#pragma once
// Profile `ramp-versine`: the ramp + cycloid + versine position command of seeds 001/002, with
// Y1..Y3 computed for the mode (omega, zeta) or given as fractions of the distance (--y). Only a
// velocity limit can be met: its velocity steps make acceleration and jerk impulses.
#include "settle/core/kinematics.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/ramp_versine.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

struct RampVersineProfile {
  static constexpr const char* name = "ramp-versine";
  static constexpr const char* summary = "ramp + cycloid + versine position command (seeds 001/002)";
  template <typename T>
  using Shape = RampVersine<T>;
  // Only vmax of the limits: its velocity steps have no finite acceleration or jerk. With its
  // fractions given (y) it designs for no mode.
  static constexpr ParamSet params{Param::time, Param::vmax, Param::omega, Param::zeta, Param::y};
  static constexpr ParamOverride overrides{Param::y, {Param::omega, Param::zeta}};
  [[nodiscard]] static Status plan(const MoveRequest& r, RampVersineParams& out, Peaks<double>& pk) noexcept {
    const double* fractions = r.y_fractions ? r.y_fractions->data() : nullptr;
    if (fractions != nullptr && !(std::fabs(fractions[0] + fractions[1] + fractions[2] - 1.0) <= 1e-9)) {
      return Status::bad_shape_parameter;
    }
    const double omega = r.omega();
    double tau = 0.0;
    if (r.time) {
      tau = *r.time;
    } else {
      if (!r.limits.vmax) return Status::missing_time_or_limits;
      if (r.limits.amax) return Status::acceleration_limit_exceeded;
      if (r.limits.jmax) return Status::jerk_limit_exceeded;
      if (!ramp_versine_shortest(r.distance, *r.limits.vmax, fractions, omega, r.zeta(), tau)) {
        return Status::velocity_limit_exceeded;
      }
    }
    out = ramp_versine_make(r.distance, tau, fractions, omega, r.zeta());
    pk = ramp_versine_peaks(out);
    return Status::ok;
  }
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = 1.0;
    r.time = 0.74;
    r.set_mode(28.28, 0.159);
    return r;
  }
};

}  // namespace settle::core
