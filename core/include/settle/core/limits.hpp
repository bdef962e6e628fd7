// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one type for a velocity / acceleration / jerk limit triple, its optional form (what a request
// asks for: each limit may be absent), and the one test of a move's peaks against either. Units:
// units/s, units/s^2, units/s^3, each > 0 where used.
#include <optional>

#include "settle/core/kinematics.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

struct Limits {
  double vmax{0.0};  // units/s
  double amax{0.0};  // units/s^2
  double jmax{0.0};  // units/s^3
};

// Limits a request gives or leaves out: an absent one does not limit.
struct OptionalLimits {
  std::optional<double> vmax;  // units/s
  std::optional<double> amax;  // units/s^2
  std::optional<double> jmax;  // units/s^3

  [[nodiscard]] constexpr bool any() const noexcept { return vmax || amax || jmax; }
  // Each given limit, else `fallback`'s.
  [[nodiscard]] constexpr Limits value_or(const Limits& fallback) const noexcept {
    return {vmax ? *vmax : fallback.vmax, amax ? *amax : fallback.amax, jmax ? *jmax : fallback.jmax};
  }
  // Each given limit times k (absent ones stay absent).
  [[nodiscard]] constexpr OptionalLimits scaled(double k) const noexcept {
    const auto times = [k](const std::optional<double>& l) { return l ? std::optional<double>{*l * k} : l; };
    return {times(vmax), times(amax), times(jmax)};
  }
};

// Every limit given.
[[nodiscard]] constexpr OptionalLimits as_optional(const Limits& l) noexcept { return {l.vmax, l.amax, l.jmax}; }

// Peaks are compared with limits with this relative slack, so that a plan built to touch a limit
// exactly is not refused for the last bit of rounding.
inline constexpr double kLimitSlack = 1e-9;
// Peaks against limits: ok, or the status naming the first exceeded (velocity, acceleration,
// jerk). Written so that a NaN peak is refused, never taken as within.
[[nodiscard]] constexpr Status check_limits(const Limits& l, const Peaks<double>& pk) noexcept {
  if (!(pk.v <= l.vmax * (1.0 + kLimitSlack))) return Status::velocity_limit_exceeded;
  if (!(pk.a <= l.amax * (1.0 + kLimitSlack))) return Status::acceleration_limit_exceeded;
  if (!(pk.j <= l.jmax * (1.0 + kLimitSlack))) return Status::jerk_limit_exceeded;
  return Status::ok;
}
// The same where each absent limit does not limit: what plan() refuses a move for (defined with
// the planner, planner.cpp).
[[nodiscard]] Status check_limits(const OptionalLimits& l, const Peaks<double>& pk) noexcept;
[[nodiscard]] constexpr bool within_limits(const Peaks<double>& pk, const Limits& l) noexcept {
  return check_limits(l, pk) == Status::ok;
}

}  // namespace settle::core
