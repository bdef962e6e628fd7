// SPDX-License-Identifier: Apache-2.0
#pragma once
// Result codes of every planner and designer in core. Core never throws: a failed call returns
// one of these, leaves its output untouched, and the caller decides what to tell the user.
#include <cstdint>

namespace settle::core {

enum class Status : std::uint8_t {
  ok = 0,
  non_finite_input,            // a NaN or an infinity in the request
  non_positive_time,           // move time (or shaper time) <= 0
  non_positive_limit,          // vmax, amax or jmax <= 0
  missing_time_or_limits,      // neither a move time nor the limits the profile needs
  non_positive_omega,          // natural frequency <= 0
  zeta_out_of_range,           // damping ratio outside [0, 1)
  time_too_short_for_vmax,     // D / vmax >= T: the move cannot be made within vmax
  velocity_limit_exceeded,     // the planned profile's true peak |v| is over vmax
  acceleration_limit_exceeded, // the planned profile's true peak |a| is over amax
  jerk_limit_exceeded,         // the planned profile's true peak |j| is over jmax
  too_few_gammas,              // pseudo-polynomial needs at least 2 exponents
  too_many_gammas,             // more exponents than the fixed capacity
  gamma_too_small,             // an exponent <= 2 (acceleration would not vanish at the end)
  gammas_not_distinct,         // two exponents closer than the solver can tell apart
  singular_system,             // the Z system of the pseudo-polynomial cannot be solved
  bad_shape_parameter,         // Y fractions that do not sum to 1, a zero-length segment, ...
  bad_impulse,                 // a custom impulse with negative time or non-finite amplitude
  shaper_gain_not_unity,       // impulse amplitudes do not sum to 1: the move would miss its target
  too_many_impulses,           // shaper composition over the fixed capacity
  vtol_out_of_range,           // EI vibration tolerance outside (0, 0.5)
  no_solution,                 // an iterative design (EI with damping) did not converge
  unsupported_request,         // e.g. a shaper on a profile kind that cannot carry one
  // Fixed-point evaluation (core/fixed): a planned move whose numbers do not fit the integer
  // formats is refused by the builder, before anything is streamed.
  scale_invalid,                // counts per unit or tick period not finite and positive, Q bits out of 0..30
  distance_does_not_fit,        // a position of the move (distance, overshoot, a polynomial term) over the count format
  velocity_does_not_fit,        // peak |v| in counts/tick over the velocity format
  acceleration_does_not_fit,    // peak |a| in counts/tick^2 over the acceleration format
  duration_does_not_fit,        // the move (with its shaper delays) is longer than 2^30 ticks
  transition_shorter_than_tick, // a cycloid/versine segment shorter than one tick: the tick is too coarse
  precision_insufficient,       // the fixed evaluation could not keep the position within its error budget
  table_too_small,              // the cam table or the segment capacity cannot hold the move accurately
  impulse_does_not_fit,         // a shaper amplitude outside (-2, 2): it has no Q2.30 weight
  // Online changes (online.hpp): a halt with a bound (the running command's target and end).
  halt_passes_target,           // no blend within the limits stops short of the running command's target
  halt_finishes_command,        // finishing the running command is the halt (plan_online's OnlinePlan says so)
};

// Stable snake_case code for logs and JSON ("time_too_short_for_vmax").
[[nodiscard]] const char* to_string(Status s) noexcept;
// One sentence for humans.
[[nodiscard]] const char* describe(Status s) noexcept;

}  // namespace settle::core
