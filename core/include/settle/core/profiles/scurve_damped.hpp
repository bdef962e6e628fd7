// SPDX-License-Identifier: Apache-2.0
#pragma once
// Profile `scurve-damped`: Settle's ramp-cycloid S-curve with a versine term, exact for a damped
// mode (omega, zeta); docs/scurve-damped.md derives it. Planned as `scurve` is.
#include "settle/core/profiles/scurve.hpp"

namespace settle::core {

struct ScurveDampedProfile {
  static constexpr const char* name = "scurve-damped";
  static constexpr const char* summary = "the S-curve made exact for a damped mode (versine term; Settle's)";
  template <typename T>
  using Shape = RampCycloid<T>;
  static constexpr ParamSet params{Param::time, Param::vmax, Param::amax, Param::jmax, Param::omega, Param::zeta};
  [[nodiscard]] static Status plan(const MoveRequest& r, RampCycloidParams& out, Peaks<double>& pk) noexcept {
    return detail::plan_scurve(r, true, out, pk);
  }
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = -0.05;
    r.time = 0.3;
    r.set_mode(30.0, 0.1);
    return r;
  }
};

}  // namespace settle::core
