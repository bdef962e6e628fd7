// SPDX-License-Identifier: Apache-2.0
#pragma once
// Modal analysis of seed 000's plant: an Euler-Bernoulli cantilever with a tip mass, clamped to a
// translating base. Roots of the characteristic equation by bracketing (any number of modes, any
// tip-mass ratio), mass-normalised mode shapes, participation factors Lambda_j and tip values.
#include <cstddef>
#include <vector>

#include "settle/plant/limits.hpp"
#include "settle/plant/status.hpp"

namespace settle::plant {

// Defaults: Table 1 of seed 000 (PMMA beam).
struct BeamParams {
  double length{0.25};      // L (m)
  double modulus{3e9};      // E (Pa)
  double thickness{0.002};  // (m), bending about the thin direction: I = width thickness^3 / 12
  double width{0.025};      // (m)
  double beam_mass{0.02};   // (kg), rho = beam_mass / length
  double tip_mass{0.015};   // m_t (kg)
};

struct BeamMode {
  double beta{0.0};     // root of 1 + cos b cosh b + b mu (cos b sinh b - sin b cosh b) = 0
  double omega{0.0};    // beta^2 sqrt(EI / (rho L^4)) (rad/s)
  double gamma{0.0};    // (cosh b + cos b) / (sinh b + sin b)
  double scale{0.0};    // A_j: makes rho int phi^2 + m_t phi(L)^2 = 1
  double lambda{0.0};   // -rho int phi - m_t phi(L): q'' + w^2 q = lambda a(t)
  double phi_tip{0.0};  // phi_j(L): tip deflection = sum phi_j(L) q_j
};

[[nodiscard]] SimStatus validate(const BeamParams& p) noexcept;
// The first `count` modes, in increasing frequency. On failure `out` is untouched.
[[nodiscard]] SimStatus beam_modes(const BeamParams& p, std::size_t count, std::vector<BeamMode>& out);

// The characteristic function divided by cosh(beta), so it stays finite for high modes; it has
// the same roots. mu = m_t / (rho L).
[[nodiscard]] double beam_characteristic(double beta, double mu) noexcept;
// The bracket of the mode shape, cosh - cos - gamma (sinh - sin), at xi = x / L, written so that
// it does not cancel catastrophically when beta is large (gamma -> 1).
[[nodiscard]] double beam_shape(double beta, double xi) noexcept;

}  // namespace settle::plant
