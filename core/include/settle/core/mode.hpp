// SPDX-License-Identifier: Apache-2.0
#pragma once
// A mode of the machine a move is designed for, and which modes Settle plans for: the one check
// every planner, shaper and residual reads (its statuses are the user's errors: status.hpp).
#include <cmath>

#include "settle/core/status.hpp"

namespace settle::core {

struct Mode {
  double omega{0.0};  // natural frequency, rad/s
  double zeta{0.0};   // damping ratio
};

// Status::ok for a mode Settle plans for (finite, omega > 0, 0 <= zeta < 1), else the first
// condition it breaks: non_finite_input, non_positive_omega, zeta_out_of_range.
[[nodiscard]] inline Status mode_status(double omega, double zeta) noexcept {
  if (!std::isfinite(omega) || !std::isfinite(zeta)) return Status::non_finite_input;
  if (!(omega > 0.0)) return Status::non_positive_omega;
  if (!(zeta >= 0.0 && zeta < 1.0)) return Status::zeta_out_of_range;
  return Status::ok;
}
[[nodiscard]] inline Status mode_status(const Mode& m) noexcept { return mode_status(m.omega, m.zeta); }

}  // namespace settle::core
