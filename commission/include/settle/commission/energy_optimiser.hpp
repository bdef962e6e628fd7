// SPDX-License-Identifier: Apache-2.0
#pragma once
// Seed 004: the residual energy a pseudo-polynomial motor command leaves in a damped mode driven
// through -lambda phi_m'' (the belt platform), E(T) = h H with H = G^2 + w^2 F^2, computed by
// adaptive Gauss-Kronrod quadrature, and the exponents that minimise it (Eigen's
// Levenberg-Marquardt). Zero energy is a curve (three exponents) or a larger set (more): every
// point on it still leaves a residual that grows linearly with an error in w, and the slope, which
// differs along the set, is what more exponents can lower (see reproduce_004).
#include <cstddef>
#include <vector>

#include "settle/plant/limits.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/plant/status.hpp"

namespace settle::commission {

// The mode and the move H is evaluated for.
struct EnergyTarget {
  double omega{0.0};     // w_n (rad/s)
  double zeta{0.0};      // xi
  double lambda{1.0};    // motor-to-platform ratio (the mode is driven by -lambda phi_m'')
  double inertia{1.0};   // J, for E = h H
  double distance{0.0};  // Phi, motor displacement (rad)
  double duration{1.0};  // T (s)
};
// Table III of seed 004 with Phi = 15 rev and T = 1 s.
[[nodiscard]] EnergyTarget belt_energy_target(const plant::BeltParams& p, double distance, double duration);

struct EnergyIntegrals {
  double f{0.0};
  double g{0.0};
  double h_index{0.0};  // H = G^2 + w^2 F^2
  double energy{0.0};   // E(T) = h H
};
// h = 1/2 J (lambda / w_d)^2.
[[nodiscard]] double energy_scale(const EnergyTarget& t) noexcept;
// F, G, H and E(T) for the pseudo-polynomial with the given exponents (core designs the C_i).
// w T above kMaxEnergyPhase is refused (too_many_samples): the quadrature's work grows with it.
[[nodiscard]] plant::SimStatus energy_integrals(const EnergyTarget& t, const std::vector<double>& gammas,
                                         EnergyIntegrals& out);

struct OptimiserOptions {
  double min_gamma{2.05};      // exponents stay above this
  double min_gap{0.05};        // and at least this far apart
  int max_evaluations{4000};
  // Retry from the start stretched and shifted when LM stalls above zero (see the .cpp); off for
  // callers that run their own set of starts.
  bool retry{true};
};

struct OptimiserResult {
  std::vector<double> gammas;
  double h_initial{0.0};  // H at the start
  double h_final{0.0};    // H at the result (nominal frequency)
  double energy{0.0};     // E(T) at the result
  // |w d(G, w F)/dw| at the result: how fast the residual grows with a frequency error (with H = 0
  // the residual amplitude is proportional to slope times the relative error).
  double slope{0.0};
  int evaluations{0};
  int iterations{0};
};

// Minimises H from `start` (3..8 exponents, each > 2). On failure `out` is untouched.
[[nodiscard]] plant::SimStatus optimise_exponents(const EnergyTarget& t, const std::vector<double>& start,
                                           const OptimiserOptions& opt, OptimiserResult& out);

}  // namespace settle::commission
