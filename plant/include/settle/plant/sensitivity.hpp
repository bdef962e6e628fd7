// SPDX-License-Identifier: Apache-2.0
#pragma once
// How a move's residual vibration degrades when the plant is not what the move was designed for:
// PRV against the ratio of true to designed natural frequency (or damping), and the insensitivity
// width, the span of frequency ratios around 1 over which PRV stays under a threshold (5 % usual).
#include <cstddef>
#include <vector>

#include "settle/plant/command.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/status.hpp"

namespace settle::plant {

// PRV (percent) that `cmd` leaves on a single mode q'' + 2 zeta w q' + w^2 q = y''.
[[nodiscard]] SimStatus prv_on_mode(const Command& cmd, double omega, double zeta, double& prv_percent);

struct SensitivityPoint {
  double ratio{0.0};  // true / designed
  double prv_percent{0.0};
};

// PRV for true frequency ratio * omega_design, ratio evenly spaced in [lo, hi] (0 < lo < hi, both
// finite, else bad_range; 2 <= n <= kMaxSweepPoints, else bad_range / too_many_samples).
[[nodiscard]] SimStatus omega_sensitivity(const Command& cmd, double omega_design, double zeta_true, double lo,
                                          double hi, std::size_t n, std::vector<SensitivityPoint>& out);
// PRV for true damping ratio * zeta_design on the designed frequency.
[[nodiscard]] SimStatus zeta_sensitivity(const Command& cmd, double omega_true, double zeta_design, double lo,
                                         double hi, std::size_t n, std::vector<SensitivityPoint>& out);

struct InsensitivityWidth {
  double lo{1.0};     // lowest ratio of the interval around 1 with PRV <= threshold
  double hi{1.0};     // highest
  double width{0.0};  // hi - lo (0 when the nominal itself is over the threshold)
  bool lo_open{false};  // the search limit was reached below: the width is at least this
  bool hi_open{false};  // the search limit was reached above
};

// The interval of ratios around 1 (searched within [r_min, r_max], 0.01 <= r_min < 1 < r_max <= 100,
// else bad_range) over which PRV <= threshold. A failed simulation ends the search with its status.
[[nodiscard]] SimStatus insensitivity_width(const Command& cmd, double omega_design, double zeta_true,
                                            double threshold_percent, InsensitivityWidth& out, double r_min = 0.25,
                                            double r_max = 3.0);

}  // namespace settle::plant
