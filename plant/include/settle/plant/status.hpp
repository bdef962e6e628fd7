// SPDX-License-Identifier: Apache-2.0
#pragma once
// Result codes of the simulator's constructors and steppers. Bad plant parameters come from users
// (CLI options, a drive node's configuration), so they are reported with a specific code and the
// output is left untouched; nothing in sim throws across its API.
#include <cstdint>

#include "settle/core/enum_text.hpp"

namespace settle::plant {

// Every status in order (ok first, 0): its enumerator, which is also its code (to_string), and
// the sentence describe() gives. The enum and both tables are made from this list (enum_text.hpp).
#define SETTLE_PLANT_STATUSES(X) \
  X(ok, "success") \
  /* a NaN or an infinity among the plant parameters */ \
  X(non_finite_parameter, "a plant parameter is NaN or infinite") \
  /* mass, beam mass or inertia <= 0 */ \
  X(non_positive_mass, "mass, beam mass and inertia must be positive") \
  /* tip mass < 0 */ \
  X(negative_tip_mass, "the tip mass must not be negative") \
  /* spring or belt stiffness <= 0 */ \
  X(non_positive_stiffness, "stiffness must be positive") \
  /* damping coefficient < 0 */ \
  X(negative_damping, "damping must not be negative") \
  /* damping ratio >= 1 (residual amplitude needs a damped frequency) */ \
  X(not_underdamped, "the damping ratio must be below 1 (the plant must be underdamped)") \
  /* beam length <= 0 */ \
  X(non_positive_length, "the beam length must be positive") \
  /* Young's modulus <= 0 */ \
  X(non_positive_modulus, "Young's modulus must be positive") \
  /* beam thickness or width <= 0 */ \
  X(non_positive_section, "beam thickness and width must be positive") \
  /* a pulley radius <= 0 */ \
  X(non_positive_radius, "pulley radii must be positive") \
  /* gear ratio <= 0 */ \
  X(non_positive_ratio, "the gear ratio must be positive") \
  /* a mode's natural frequency <= 0 */ \
  X(non_positive_omega, "every mode needs a positive natural frequency") \
  /* no modes, or more than the beam solver supports */ \
  X(bad_mode_count, "the number of modes must be between 1 and the supported maximum") \
  /* the beam's characteristic equation gave fewer roots than asked */ \
  X(root_not_found, "the beam's characteristic equation did not give enough roots") \
  /* state-space matrices of inconsistent sizes */ \
  X(dimension_mismatch, "the state-space matrices have inconsistent sizes") \
  /* dt <= 0 or not finite */ \
  X(non_positive_step, "the time step must be positive and finite") \
  /* base polynomial above kMaxBaseDegree */ \
  X(degree_too_high, "the base polynomial's degree is above the supported maximum") \
  /* NaN/inf in a base polynomial or a command sample */ \
  X(non_finite_input, "the base motion contains NaN or infinity") \
  /* A is singular where an equilibrium is needed */ \
  X(singular_dynamics, "the dynamics matrix is singular: no rest position for a fixed base") \
  /* optimiser exponents: fewer than 3, more than the core capacity, or <= 2 */ \
  X(bad_gammas, "the exponents must be at least 3, at most the core capacity, all above 2") \
  /* Levenberg-Marquardt could not make progress */ \
  X(optimiser_failed, "the optimiser could not reduce the residual energy") \
  /* core refused a move the experiment needs */ \
  X(plan_failed, "the move could not be planned") \
  /* a CSV or plot file could not be written */ \
  X(io_error, "a file could not be written") \
  /* a counts-per-unit scale <= 0 or not finite */ \
  X(non_positive_scale, "counts per unit must be positive and finite") \
  /* servo model bandwidth <= 0 or damping outside (0, 1) */ \
  X(bad_drive_model, "the servo model needs a positive bandwidth and a damping ratio in (0, 1)") \
  /* the computation needs more than kMaxSamples samples (limits.hpp) */ \
  X(too_many_samples, "the computation needs more than 10 000 000 samples (kMaxSamples)") \
  /* more than kMaxModes modes (or kMaxStates states) */ \
  X(too_many_modes, "the plant has more than 64 modes (kMaxModes)") \
  /* move + tail beyond kMaxSimulatedTime, or a NaN/infinite duration */ \
  X(too_long, "move plus tail exceeds 3600 s of simulated time (kMaxSimulatedTime) or is not finite") \
  /* a sweep or search range that is empty, non-finite or not around 1 */ \
  X(bad_range, "the range is empty, not finite, or does not contain the nominal point") \
  /* the simulation overflowed: parameters too extreme for double precision */ \
  X(non_finite_result, "the simulation overflowed: the parameters are too extreme for double precision")
enum class SimStatus : std::uint8_t { SETTLE_PLANT_STATUSES(SETTLE_ENUM_ENUMERATOR) };

// Stable snake_case code for logs and JSON.
[[nodiscard]] const char* to_string(SimStatus s) noexcept;
// One sentence for humans.
[[nodiscard]] const char* describe(SimStatus s) noexcept;

}  // namespace settle::plant
