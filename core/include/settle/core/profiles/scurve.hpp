// SPDX-License-Identifier: Apache-2.0
#pragma once
// Profile `scurve`: the ramp-cycloid S-curve of seed 000, vibration-free for an undamped mode
// (omega). Timed (D, T, optional vmax) or the fastest under vmax/amax (and jmax).
#include <cmath>
#include <limits>

#include "settle/core/kinematics.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/ramp_cycloid.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

namespace detail {
// The ramp-cycloid hook both S-curves share: undamped (c3 = 0, zeta ignored) or damped.
[[nodiscard]] inline Status plan_scurve(const MoveRequest& r, bool damped, RampCycloidParams& out,
                                        Peaks<double>& pk) noexcept {
  const double zeta = damped ? r.zeta() : 0.0;
  RampCycloidParams p{};
  Status st = Status::ok;
  if (r.time) {
    st = scurve_timed(r.distance, *r.time, r.limits.vmax.value_or(0.0), r.omega(), zeta, p);
  } else {
    if (!r.limits.vmax || !r.limits.amax) return Status::missing_time_or_limits;
    st = plan_fastest_scurve(r.distance, *r.limits.vmax, *r.limits.amax, r.limits.jmax.value_or(std::numeric_limits<double>::infinity()),
                             r.omega(), zeta, damped, p);
  }
  if (st != Status::ok) return st;
  pk = ramp_cycloid_peaks(p);
  out = p;
  return Status::ok;
}
}  // namespace detail

struct ScurveProfile {
  static constexpr const char* name = "scurve";
  static constexpr const char* summary = "ramp-cycloid S-curve, vibration-free for an undamped mode (seed 000)";
  template <typename T>
  using Shape = RampCycloid<T>;
  // What the hook reads besides the distance (design_params.hpp): a mode it reads (omega) is
  // required by plan(); a limit is met, or with a time checked. zeta is not read: the undamped design.
  static constexpr ParamSet params{Param::time, Param::vmax, Param::amax, Param::jmax, Param::omega};
  [[nodiscard]] static Status plan(const MoveRequest& r, RampCycloidParams& out, Peaks<double>& pk) noexcept {
    return detail::plan_scurve(r, false, out, pk);
  }
  // A request this profile plans (its kind is set by the caller): what the registry tests run.
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = 0.1;
    r.time = 0.5;
    r.set_mode(22.05);
    return r;
  }
};

}  // namespace settle::core
