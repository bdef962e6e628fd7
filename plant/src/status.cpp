// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/status.hpp"

#include "settle/plant/limits.hpp"

namespace settle::plant {

// describe() spells the bounds out for humans; keep it in step with limits.hpp.
static_assert(kMaxSamples == 10'000'000 && kMaxModes == 64 && kMaxSimulatedTime == 3600.0);

const char* to_string(SimStatus s) noexcept {
  switch (s) {
    case SimStatus::ok: return "ok";
    case SimStatus::non_finite_parameter: return "non_finite_parameter";
    case SimStatus::non_positive_mass: return "non_positive_mass";
    case SimStatus::negative_tip_mass: return "negative_tip_mass";
    case SimStatus::non_positive_stiffness: return "non_positive_stiffness";
    case SimStatus::negative_damping: return "negative_damping";
    case SimStatus::not_underdamped: return "not_underdamped";
    case SimStatus::non_positive_length: return "non_positive_length";
    case SimStatus::non_positive_modulus: return "non_positive_modulus";
    case SimStatus::non_positive_section: return "non_positive_section";
    case SimStatus::non_positive_radius: return "non_positive_radius";
    case SimStatus::non_positive_ratio: return "non_positive_ratio";
    case SimStatus::non_positive_omega: return "non_positive_omega";
    case SimStatus::bad_mode_count: return "bad_mode_count";
    case SimStatus::root_not_found: return "root_not_found";
    case SimStatus::dimension_mismatch: return "dimension_mismatch";
    case SimStatus::non_positive_step: return "non_positive_step";
    case SimStatus::degree_too_high: return "degree_too_high";
    case SimStatus::non_finite_input: return "non_finite_input";
    case SimStatus::singular_dynamics: return "singular_dynamics";
    case SimStatus::bad_gammas: return "bad_gammas";
    case SimStatus::optimiser_failed: return "optimiser_failed";
    case SimStatus::plan_failed: return "plan_failed";
    case SimStatus::io_error: return "io_error";
    case SimStatus::non_positive_scale: return "non_positive_scale";
    case SimStatus::bad_drive_model: return "bad_drive_model";
    case SimStatus::too_many_samples: return "too_many_samples";
    case SimStatus::too_many_modes: return "too_many_modes";
    case SimStatus::too_long: return "too_long";
    case SimStatus::bad_range: return "bad_range";
    case SimStatus::non_finite_result: return "non_finite_result";
  }
  return "unknown";
}

const char* describe(SimStatus s) noexcept {
  switch (s) {
    case SimStatus::ok: return "success";
    case SimStatus::non_finite_parameter: return "a plant parameter is NaN or infinite";
    case SimStatus::non_positive_mass: return "mass, beam mass and inertia must be positive";
    case SimStatus::negative_tip_mass: return "the tip mass must not be negative";
    case SimStatus::non_positive_stiffness: return "stiffness must be positive";
    case SimStatus::negative_damping: return "damping must not be negative";
    case SimStatus::not_underdamped: return "the damping ratio must be below 1 (the plant must be underdamped)";
    case SimStatus::non_positive_length: return "the beam length must be positive";
    case SimStatus::non_positive_modulus: return "Young's modulus must be positive";
    case SimStatus::non_positive_section: return "beam thickness and width must be positive";
    case SimStatus::non_positive_radius: return "pulley radii must be positive";
    case SimStatus::non_positive_ratio: return "the gear ratio must be positive";
    case SimStatus::non_positive_omega: return "every mode needs a positive natural frequency";
    case SimStatus::bad_mode_count: return "the number of modes must be between 1 and the supported maximum";
    case SimStatus::root_not_found: return "the beam's characteristic equation did not give enough roots";
    case SimStatus::dimension_mismatch: return "the state-space matrices have inconsistent sizes";
    case SimStatus::non_positive_step: return "the time step must be positive and finite";
    case SimStatus::degree_too_high: return "the base polynomial's degree is above the supported maximum";
    case SimStatus::non_finite_input: return "the base motion contains NaN or infinity";
    case SimStatus::singular_dynamics: return "the dynamics matrix is singular: no rest position for a fixed base";
    case SimStatus::bad_gammas: return "the exponents must be at least 3, at most the core capacity, all above 2";
    case SimStatus::optimiser_failed: return "the optimiser could not reduce the residual energy";
    case SimStatus::plan_failed: return "the move could not be planned";
    case SimStatus::io_error: return "a file could not be written";
    case SimStatus::non_positive_scale: return "counts per unit must be positive and finite";
    case SimStatus::bad_drive_model: return "the servo model needs a positive bandwidth and a damping ratio in (0, 1)";
    case SimStatus::too_many_samples: return "the computation needs more than 10 000 000 samples (kMaxSamples)";
    case SimStatus::too_many_modes: return "the plant has more than 64 modes (kMaxModes)";
    case SimStatus::too_long: return "move plus tail exceeds 3600 s of simulated time (kMaxSimulatedTime) or is not finite";
    case SimStatus::bad_range: return "the range is empty, not finite, or does not contain the nominal point";
    case SimStatus::non_finite_result: return "the simulation overflowed: the parameters are too extreme for double precision";
  }
  return "unknown status";
}

}  // namespace settle::plant
