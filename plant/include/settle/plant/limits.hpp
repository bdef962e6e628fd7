// SPDX-License-Identifier: Apache-2.0
#pragma once
// The sizes sim accepts: every function that allocates or loops in proportion to an input checks
// it against these bounds first, and refuses with a specific SimStatus (too_many_samples,
// too_many_modes, too_long) before anything is allocated. The CLI cites the same constants in its
// help text and checks its options against them, so both refuse the same requests.
#include <cstddef>

namespace settle::plant {

// Samples, grid points, setpoints, recorded history rows or replayed periods of one computation
// (simulate's grid plus its tail, stream_setpoints, replay_stream's periods plus its window).
inline constexpr std::size_t kMaxSamples = 10'000'000;

// Grid steps x modes of the continuous simulations the CLI runs (simulate, stream's reference).
inline constexpr double kMaxSimWork = 2e6;

// Modes of a ModalPlant (each is two states; a LinearPlant has at most 2 kMaxModes states).
inline constexpr std::size_t kMaxModes = 64;
inline constexpr std::size_t kMaxStates = 2 * kMaxModes;

// Modes the beam solver computes (its root bracketing is validated up to here).
inline constexpr std::size_t kMaxBeamModes = 40;

// Simulated time of one simulate() run: the command's duration plus the recorded tail (s).
inline constexpr double kMaxSimulatedTime = 3600.0;

// The horizon of the closed-form settling time after a move (s): a decay slower than this (a
// denormal damping ratio, say) is reported as Settling::beyond_horizon instead of being searched.
inline constexpr double kMaxSettlingTime = 3600.0;

// Points of a sensitivity sweep (omega_sensitivity, zeta_sensitivity): each is a simulation.
inline constexpr std::size_t kMaxSweepPoints = 10'000;

// Oscillation of the residual-energy integrand (seed 004): w T rad over the move, about one
// quadrature panel per 2 rad; energy_integrals and optimise_exponents refuse more (too_many_samples).
inline constexpr double kMaxEnergyPhase = 2e6;

// Entries (samples x 2 per mode) of fitted_residual's least-squares matrix: 16 M doubles, 128 MB.
inline constexpr std::size_t kMaxFitEntries = 16'000'000;

}  // namespace settle::plant
