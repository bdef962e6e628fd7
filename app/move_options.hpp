// SPDX-License-Identifier: Apache-2.0
#pragma once
// The move every move-taking command plans: a core::MoveRequest from the validated options of
// the move group (options.cpp), and planning it with each refusal blamed on the option to change.
#include <optional>

#include "options.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/core/planner.hpp"
#include "settle/plant/csv_columns.hpp"

namespace settle::app {

// The mode a move is designed for when --omega is not given and its profile or shaper designs for
// one: the plant's fundamental (with its zeta unless --zeta is given). The commands that know the
// plant (simulate, stream) pass it; the others require --omega.
struct DesignFallback {
  double omega;
  double zeta;
};

// The --vmax, --amax and --jmax given.
// --unit as given, else `fallback` (m; simulate: the plant's): it labels, it scales nothing.
[[nodiscard]] plant::PositionUnit position_unit(const ParsedArgs& args,
                                                plant::PositionUnit fallback = plant::PositionUnit::m);

[[nodiscard]] core::OptionalLimits limits_of(const ParsedArgs& args);

// Fills `req` from the options (already range-checked); false (with `err`) when a required
// option is missing or the options contradict each other (a per-axis list, or --sync, without --axes).
[[nodiscard]] bool parse_move_request(const ParsedArgs& args, core::MoveRequest& req, RequestError& err,
                                      const DesignFallback* fallback = nullptr);
// Plans the request; on failure fills `err` naming the option the status is about
// (plant::option_of). A plan whose
// duration, peaks or shaper are not finite, or that lasts longer than kMaxSeconds, is refused.
[[nodiscard]] bool plan_move(const core::MoveRequest& req, core::Move<double>& out, RequestError& err);

// The limit that makes a move of `distance` long: of the ones given, the one whose own lower bound
// on any rest-to-rest move's duration is the longest (|D| / vmax, 2 sqrt(|D| / amax),
// cbrt(32 |D| / jmax)): "--vmax", "--amax" or "--jmax" (`fallback` when none is given). `bound`
// receives that duration (s).
[[nodiscard]] const char* binding_limit(double distance, const core::OptionalLimits& limits, const char* fallback,
                                        double* bound = nullptr);

// Whether the command line asks for a coordinated move of several axes (--axes, docs/multi_axis.md).
[[nodiscard]] bool wants_axes(const ParsedArgs& args);
// Fills `req` from --axes N, --sync and the move group: --distance, --omega, --zeta N values each,
// --vmax, --amax, --jmax one or N; the rest (profile, time, shaper, ...) shared by every axis.
// Without --omega, `fallback` gives every axis its mode, as with one axis.
[[nodiscard]] bool parse_axes_request(const ParsedArgs& args, core::MultiAxisRequest& req, RequestError& err,
                                      const DesignFallback* fallback = nullptr);
// Plans it; a refusal names the option and, when it is about one axis, which (1-based). A plan longer
// than kMaxSeconds or not finite is refused too.
[[nodiscard]] bool plan_axes(const core::MultiAxisRequest& req, core::MultiAxisPlan& out, RequestError& err);

// The move of a command that takes either the move options or --plan-from FILE (a plan written by
// `settle tune --json`, reproduced exactly; no move option may be given with it).
[[nodiscard]] bool move_from_args(const ParsedArgs& args, core::Move<double>& out, RequestError& err,
                                  const DesignFallback* fallback = nullptr);

}  // namespace settle::app
