// SPDX-License-Identifier: Apache-2.0
#pragma once
// --halt-at T and --retarget-at T:NEW_DISTANCE[,...] (docs/online.md): the change of a planned
// move at time T on its clock, planned by core, with every refusal blamed on the option.
#include <optional>
#include <string>
#include <vector>

#include "options.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/core/online.hpp"
#include "settle/plant/modal_plant.hpp"

namespace settle::app {

struct OnlineChange {
  const char* option{""};         // "--halt-at" or "--retarget-at"
  double at{0.0};                 // s on the move's clock
  std::optional<double> target;   // retarget: new distance from the move's start
  std::vector<core::Mode> modes;  // left at rest: the move's design modes (core::design_modes), else the plant's fundamental
  // --vmax/--amax/--jmax where given, else the move's own peaks; an unbounded jerk peak (a
  // trapezoid) becomes amax x the fastest mode's omega.
  core::OnlineLimits limits{};
  core::Blend blend{};
  // A halt may be better served by another blend or by finishing the move (core::OnlinePlan).
  core::OnlineChoice choice{core::OnlineChoice::blend};
  // When the command leaves the move for the blend: `at`, or on finish the move's end (the blend
  // then at rest on the move's distance, of no duration). The command is at rest at
  // switch_at + blend.duration().
  double switch_at{0.0};
};

// False with `err` on a bad value; true with `out` empty when neither option is given. A positive
// `period` (stream) rounds T to whole periods, at least 3 (the loop asks two periods ahead).
[[nodiscard]] bool parse_online_change(const ParsedArgs& args, const core::MoveRequest& req,
                                       const core::Move<double>& move, const plant::ModalPlant* plant, double period,
                                       std::optional<OnlineChange>& out, RequestError& err);

// The same for a coordinated move (--axes N, docs/multi_axis.md "Halt and retarget"): one T for
// every axis, --retarget-at T:D1,...,DN one new distance per axis. Each moving axis's change is
// asked from its own command (core::axis_command) with the modes and limits core::axis_online
// gives it (the plant's fundamental when it has no mode); with path sync a halt, or a retarget on
// the line, is planned once for every axis (core::plan_path_online), else each axis plans its own.
// An axis that does not move has none (a retarget must give it 0). `out` gets one entry per axis, all empty when neither option is given.
[[nodiscard]] bool parse_axes_online_change(const ParsedArgs& args, const core::MultiAxisRequest& req,
                                            const core::MultiAxisPlan& plan, const plant::ModalPlant* plant,
                                            double period, std::vector<std::optional<OnlineChange>>& out,
                                            RequestError& err);

}  // namespace settle::app
