// SPDX-License-Identifier: Apache-2.0
#include "settle/core/status.hpp"

namespace settle::core {

const char* to_string(Status s) noexcept {
  switch (s) {
    case Status::ok: return "ok";
    case Status::non_finite_input: return "non_finite_input";
    case Status::non_positive_time: return "non_positive_time";
    case Status::non_positive_limit: return "non_positive_limit";
    case Status::missing_time_or_limits: return "missing_time_or_limits";
    case Status::non_positive_omega: return "non_positive_omega";
    case Status::zeta_out_of_range: return "zeta_out_of_range";
    case Status::time_too_short_for_vmax: return "time_too_short_for_vmax";
    case Status::velocity_limit_exceeded: return "velocity_limit_exceeded";
    case Status::acceleration_limit_exceeded: return "acceleration_limit_exceeded";
    case Status::jerk_limit_exceeded: return "jerk_limit_exceeded";
    case Status::too_few_gammas: return "too_few_gammas";
    case Status::too_many_gammas: return "too_many_gammas";
    case Status::gamma_too_small: return "gamma_too_small";
    case Status::gammas_not_distinct: return "gammas_not_distinct";
    case Status::singular_system: return "singular_system";
    case Status::bad_shape_parameter: return "bad_shape_parameter";
    case Status::bad_impulse: return "bad_impulse";
    case Status::shaper_gain_not_unity: return "shaper_gain_not_unity";
    case Status::too_many_impulses: return "too_many_impulses";
    case Status::vtol_out_of_range: return "vtol_out_of_range";
    case Status::no_solution: return "no_solution";
    case Status::unsupported_request: return "unsupported_request";
    case Status::scale_invalid: return "scale_invalid";
    case Status::distance_does_not_fit: return "distance_does_not_fit";
    case Status::velocity_does_not_fit: return "velocity_does_not_fit";
    case Status::acceleration_does_not_fit: return "acceleration_does_not_fit";
    case Status::duration_does_not_fit: return "duration_does_not_fit";
    case Status::transition_shorter_than_tick: return "transition_shorter_than_tick";
    case Status::precision_insufficient: return "precision_insufficient";
    case Status::table_too_small: return "table_too_small";
    case Status::impulse_does_not_fit: return "impulse_does_not_fit";
    case Status::halt_passes_target: return "halt_passes_target";
    case Status::halt_finishes_command: return "halt_finishes_command";
  }
  return "unknown";
}

const char* describe(Status s) noexcept {
  switch (s) {
    case Status::ok: return "ok";
    case Status::non_finite_input: return "an input is NaN or infinite";
    case Status::non_positive_time: return "the move time must be positive";
    case Status::non_positive_limit: return "velocity, acceleration and jerk limits must be positive";
    case Status::missing_time_or_limits: return "give either a move time or the limits this profile needs";
    case Status::non_positive_omega: return "the natural frequency omega must be positive";
    case Status::zeta_out_of_range: return "the damping ratio zeta must lie in [0, 1)";
    case Status::time_too_short_for_vmax: return "the move time is too short to cover the distance within vmax (D/vmax >= T)";
    case Status::velocity_limit_exceeded: return "the profile's peak velocity exceeds vmax";
    case Status::acceleration_limit_exceeded: return "the profile's peak acceleration exceeds amax";
    case Status::jerk_limit_exceeded: return "the profile's peak jerk exceeds jmax";
    case Status::too_few_gammas: return "a pseudo-polynomial needs at least two exponents";
    case Status::too_many_gammas: return "too many exponents for the pseudo-polynomial's fixed capacity";
    case Status::gamma_too_small: return "every exponent must be greater than 2";
    case Status::gammas_not_distinct: return "the exponents must be distinct";
    case Status::singular_system: return "the pseudo-polynomial coefficient system is singular";
    case Status::bad_shape_parameter: return "a shape parameter is out of range";
    case Status::bad_impulse: return "an impulse has a negative time or a non-finite amplitude";
    case Status::shaper_gain_not_unity: return "the impulse amplitudes must sum to 1";
    case Status::too_many_impulses: return "the shaper has more impulses than its fixed capacity";
    case Status::vtol_out_of_range: return "the EI vibration tolerance must lie in (0, 0.5)";
    case Status::no_solution: return "the iterative design did not converge";
    case Status::unsupported_request: return "this combination of options is not supported";
    case Status::scale_invalid: return "the fixed-point scale needs positive finite counts per unit and tick period, and 0..30 fraction bits";
    case Status::distance_does_not_fit: return "a position of the move does not fit the fixed-point count format";
    case Status::velocity_does_not_fit: return "the move's peak velocity does not fit the fixed-point velocity format";
    case Status::acceleration_does_not_fit: return "the move's peak acceleration does not fit the fixed-point acceleration format";
    case Status::duration_does_not_fit: return "the move is longer than the fixed-point tick format allows (2^30 ticks)";
    case Status::transition_shorter_than_tick: return "a cycloid or versine transition is shorter than one servo tick";
    case Status::precision_insufficient: return "the fixed-point evaluation cannot keep this move within one count";
    case Status::table_too_small: return "the table or segment capacity is too small to hold the move accurately";
    case Status::impulse_does_not_fit: return "a shaper impulse amplitude lies outside (-2, 2)";
    case Status::halt_passes_target:
      return "no halt within the limits stops short of the running command's target, and that command does not leave "
             "every mode at rest";
    case Status::halt_finishes_command:
      return "the halt is the running command itself: no blend stops short of its target and before its end";
  }
  return "unknown status";
}

}  // namespace settle::core
