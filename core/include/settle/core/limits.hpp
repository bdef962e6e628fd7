// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one type for a velocity / acceleration / jerk limit triple, and the one test of a move's
// peaks against it. Plain values (units/s, units/s^2, units/s^3, each > 0 where used); a request
// whose limits are optional holds std::optional<double> fields and resolves them into a Limits.
#include "settle/core/kinematics.hpp"

namespace settle::core {

struct Limits {
  double vmax{0.0};  // units/s
  double amax{0.0};  // units/s^2
  double jmax{0.0};  // units/s^3
};

// Peaks are compared with limits with this relative slack, so that a plan built to touch a limit
// exactly is not refused for the last bit of rounding.
inline constexpr double kLimitSlack = 1e-9;
[[nodiscard]] inline bool within_limits(const Peaks<double>& pk, const Limits& l) noexcept {
  return pk.v <= l.vmax * (1.0 + kLimitSlack) && pk.a <= l.amax * (1.0 + kLimitSlack) &&
         pk.j <= l.jmax * (1.0 + kLimitSlack);
}

}  // namespace settle::core
