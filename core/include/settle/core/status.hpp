// SPDX-License-Identifier: Apache-2.0
#pragma once
// Result codes of every planner and designer in core. Core never throws: a failed call returns
// one of these, leaves its output untouched, and the caller decides what to tell the user.
#include <cstdint>

#include "settle/core/enum_text.hpp"

namespace settle::core {

// Every status in order (ok first, 0): its enumerator, which is also its code (to_string), and
// the sentence describe() gives. The enum and both tables are made from this list (enum_text.hpp).
#define SETTLE_CORE_STATUSES(X) \
  X(ok, "ok") \
  /* a NaN or an infinity in the request */ \
  X(non_finite_input, "an input is NaN or infinite") \
  /* move time (or shaper time) <= 0 */ \
  X(non_positive_time, "the move time must be positive") \
  /* vmax, amax or jmax <= 0 */ \
  X(non_positive_limit, "velocity, acceleration and jerk limits must be positive") \
  /* neither a move time nor the limits the profile needs */ \
  X(missing_time_or_limits, "give either a move time or the limits this profile needs") \
  /* natural frequency <= 0 */ \
  X(non_positive_omega, "the natural frequency omega must be positive") \
  /* damping ratio outside [0, 1) */ \
  X(zeta_out_of_range, "the damping ratio zeta must lie in [0, 1)") \
  /* D / vmax >= T: the move cannot be made within vmax */ \
  X(time_too_short_for_vmax, "the move time is too short to cover the distance within vmax (D/vmax >= T)") \
  /* the planned profile's true peak |v| is over vmax */ \
  X(velocity_limit_exceeded, "the profile's peak velocity exceeds vmax") \
  /* the planned profile's true peak |a| is over amax */ \
  X(acceleration_limit_exceeded, "the profile's peak acceleration exceeds amax") \
  /* the planned profile's true peak |j| is over jmax */ \
  X(jerk_limit_exceeded, "the profile's peak jerk exceeds jmax") \
  /* pseudo-polynomial needs at least 2 exponents */ \
  X(too_few_gammas, "a pseudo-polynomial needs at least two exponents") \
  /* more exponents than the fixed capacity */ \
  X(too_many_gammas, "too many exponents for the pseudo-polynomial's fixed capacity") \
  /* an exponent <= 2 (acceleration would not vanish at the end) */ \
  X(gamma_too_small, "every exponent must be greater than 2") \
  /* two exponents closer than the solver can tell apart */ \
  X(gammas_not_distinct, "the exponents must be distinct") \
  /* the Z system of the pseudo-polynomial cannot be solved */ \
  X(singular_system, "the pseudo-polynomial coefficient system is singular") \
  /* Y fractions that do not sum to 1, a zero-length segment, ... */ \
  X(bad_shape_parameter, "a shape parameter is out of range") \
  /* a custom impulse with negative time or non-finite amplitude */ \
  X(bad_impulse, "an impulse has a negative time or a non-finite amplitude") \
  /* impulse amplitudes do not sum to 1: the move would miss its target */ \
  X(shaper_gain_not_unity, "the impulse amplitudes must sum to 1") \
  /* shaper composition over the fixed capacity */ \
  X(too_many_impulses, "the shaper has more impulses than its fixed capacity") \
  /* EI vibration tolerance outside (0, 0.5) */ \
  X(vtol_out_of_range, "the EI vibration tolerance must lie in (0, 0.5)") \
  /* an iterative design (EI with damping) did not converge */ \
  X(no_solution, "the iterative design did not converge") \
  /* e.g. a shaper on a profile kind that cannot carry one */ \
  X(unsupported_request, "this combination of options is not supported") \
  /* Fixed-point evaluation (core/fixed): a planned move whose numbers do not fit the integer */ \
  /* formats is refused by the builder, before anything is streamed. */ \
  /* counts per unit or tick period not finite and positive, Q bits out of 0..30 */ \
  X(scale_invalid, \
    "the fixed-point scale needs positive finite counts per unit and tick period, and 0..30 " \
    "fraction bits") \
  /* a position of the move (distance, overshoot, a polynomial term) over the count format */ \
  X(distance_does_not_fit, "a position of the move does not fit the fixed-point count format") \
  /* peak |v| in counts/tick over the velocity format */ \
  X(velocity_does_not_fit, "the move's peak velocity does not fit the fixed-point velocity format") \
  /* peak |a| in counts/tick^2 over the acceleration format */ \
  X(acceleration_does_not_fit, \
    "the move's peak acceleration does not fit the fixed-point acceleration format") \
  /* the move (with its shaper delays) is longer than 2^30 ticks */ \
  X(duration_does_not_fit, "the move is longer than the fixed-point tick format allows (2^30 ticks)") \
  /* a cycloid/versine segment shorter than one tick: the tick is too coarse */ \
  X(transition_shorter_than_tick, "a cycloid or versine transition is shorter than one servo tick") \
  /* the fixed evaluation could not keep the position within its error budget */ \
  X(precision_insufficient, "the fixed-point evaluation cannot keep this move within one count") \
  /* the cam table or the segment capacity cannot hold the move accurately */ \
  X(table_too_small, "the table or segment capacity is too small to hold the move accurately") \
  /* a shaper amplitude outside (-2, 2): it has no Q2.30 weight */ \
  X(impulse_does_not_fit, "a shaper impulse amplitude lies outside (-2, 2)") \
  /* Online changes (online.hpp): a halt with a bound (the running command's target and end). */ \
  /* no blend within the limits stops short of the running command's target */ \
  X(halt_passes_target, \
    "no halt within the limits stops short of the running command's target, and that command " \
    "does not leave every mode at rest") \
  /* finishing the running command is the halt (plan_online's OnlinePlan says so) */ \
  X(halt_finishes_command, \
    "the halt is the running command itself: no blend stops short of its target and before its " \
    "end")
enum class Status : std::uint8_t { SETTLE_CORE_STATUSES(SETTLE_ENUM_ENUMERATOR) };

// Stable snake_case code for logs and JSON ("time_too_short_for_vmax").
[[nodiscard]] const char* to_string(Status s) noexcept;
// One sentence for humans.
[[nodiscard]] const char* describe(Status s) noexcept;

}  // namespace settle::core
