// SPDX-License-Identifier: Apache-2.0
#pragma once
// Result codes of the simulator's constructors and steppers. Bad plant parameters come from users
// (CLI options, a drive node's configuration), so they are reported with a specific code and the
// output is left untouched; nothing in sim throws across its API.
#include <cstdint>

namespace settle::plant {

enum class SimStatus : std::uint8_t {
  ok = 0,
  non_finite_parameter,     // a NaN or an infinity among the plant parameters
  non_positive_mass,        // mass, beam mass or inertia <= 0
  negative_tip_mass,        // tip mass < 0
  non_positive_stiffness,   // spring or belt stiffness <= 0
  negative_damping,         // damping coefficient < 0
  not_underdamped,          // damping ratio >= 1 (residual amplitude needs a damped frequency)
  non_positive_length,      // beam length <= 0
  non_positive_modulus,     // Young's modulus <= 0
  non_positive_section,     // beam thickness or width <= 0
  non_positive_radius,      // a pulley radius <= 0
  non_positive_ratio,       // gear ratio <= 0
  non_positive_omega,       // a mode's natural frequency <= 0
  bad_mode_count,           // no modes, or more than the beam solver supports
  root_not_found,           // the beam's characteristic equation gave fewer roots than asked
  dimension_mismatch,       // state-space matrices of inconsistent sizes
  non_positive_step,        // dt <= 0 or not finite
  degree_too_high,          // base polynomial above kMaxBaseDegree
  non_finite_input,         // NaN/inf in a base polynomial or a command sample
  singular_dynamics,        // A is singular where an equilibrium is needed
  bad_gammas,               // optimiser exponents: fewer than 3, more than the core capacity, or <= 2
  optimiser_failed,         // Levenberg-Marquardt could not make progress
  plan_failed,              // core refused a move the experiment needs
  io_error,                 // a CSV or plot file could not be written
  non_positive_scale,       // a counts-per-unit scale <= 0 or not finite
  bad_drive_model,          // servo model bandwidth <= 0 or damping outside (0, 1)
  too_many_samples,         // the computation needs more than kMaxSamples samples (limits.hpp)
  too_many_modes,           // more than kMaxModes modes (or kMaxStates states)
  too_long,                 // move + tail beyond kMaxSimulatedTime, or a NaN/infinite duration
  bad_range,                // a sweep or search range that is empty, non-finite or not around 1
  non_finite_result,        // the simulation overflowed: parameters too extreme for double precision
};

// Stable snake_case code for logs and JSON.
[[nodiscard]] const char* to_string(SimStatus s) noexcept;
// One sentence for humans.
[[nodiscard]] const char* describe(SimStatus s) noexcept;

}  // namespace settle::plant
