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
// Peaks against limits, each absent limit not limiting: ok, or the status naming the first
// exceeded (velocity, acceleration, jerk). Written so that a NaN peak is refused, never taken as
// within. Defined with the planner (planner.cpp): out of line, because inlined at each of the
// planner's callers it costs the Cortex-M images 1.7 KB of flash.
[[nodiscard]] Status check_limits(const OptionalLimits& l, const Peaks<double>& pk) noexcept;
// The same with every limit given.
[[nodiscard]] inline Status check_limits(const Limits& l, const Peaks<double>& pk) noexcept {
  return check_limits(as_optional(l), pk);
}
// The shortest rest-to-rest time of a move of |distance| that each limit alone allows (0 for an
// absent one): |D|/vmax, 2 sqrt(|D|/amax), cbrt(32 |D|/jmax), in s. No move within the limits is
// shorter than the largest. Defined with the planner (planner.cpp).
struct LimitTimes {
  double by_vmax{0.0};  // s
  double by_amax{0.0};  // s
  double by_jmax{0.0};  // s
};
[[nodiscard]] LimitTimes shortest_times(double distance, const OptionalLimits& l) noexcept;

[[nodiscard]] inline bool within_limits(const Peaks<double>& pk, const Limits& l) noexcept {
  return check_limits(l, pk) == Status::ok;
}

}  // namespace settle::core
