// SPDX-License-Identifier: Apache-2.0
#pragma once
// A mode and where its true values may lie: what identify_modes estimates (identify.hpp) and what
// tune designs for (tune.hpp), one type for both.

namespace settle::commission {

// omega_lo <= omega <= omega_hi (rad/s, > 0) and zeta_lo <= zeta <= zeta_hi (within [0, 1)).
struct UncertainMode {
  double omega{0.0};  // rad/s
  double zeta{0.0};
  double gain{1.0};  // g: deflection per base acceleration through the mode (signed); tune only reports it
  double omega_lo{0.0}, omega_hi{0.0};
  double zeta_lo{0.0}, zeta_hi{0.0};
  // Standard errors of an identified mode (the intervals are built from them); 0 for a band given
  // as such (--mode with --uncertainty PCT).
  double omega_sd{0.0}, zeta_sd{0.0}, gain_sd{0.0};
};

}  // namespace settle::commission
