// SPDX-License-Identifier: Apache-2.0
#include "online_options.hpp"

#include <array>
#include <cmath>

#include "settle/plant/online_command.hpp"

namespace settle::app {

namespace {

// "T:D1[,D2,...]", every item a strict number, no empty item.
bool split_retarget(const std::string& s, double& t, std::vector<double>& d) {
  const auto colon = s.find(':');
  if (colon == std::string::npos || !parse_real(s.substr(0, colon), t)) return false;
  d.clear();
  std::size_t from = colon + 1;
  for (;;) {
    const auto comma = s.find(',', from);
    double v = 0.0;
    if (!parse_real(s.substr(from, comma == std::string::npos ? std::string::npos : comma - from), v)) return false;
    d.push_back(v);
    if (comma == std::string::npos) return true;
    from = comma + 1;
  }
}

// Which change the options ask for, when (rounded for a loop of `period` s when positive) and,
// for a retarget, the `count` new distances. `duration`: the move's. False with `err`; true with
// c.option empty when neither option is given.
bool parse_when(const ParsedArgs& args, std::size_t count, double duration, double period, OnlineChange& c,
                std::vector<double>& targets, RequestError& err) {
  targets.clear();
  const bool halt = args.has("--halt-at"), retarget = args.has("--retarget-at");
  if (!halt && !retarget) return true;
  if (halt && retarget) {
    err = {"conflicting_options", "--retarget-at", "--retarget-at: give either --halt-at or --retarget-at, not both"};
    return false;
  }
  c.option = halt ? "--halt-at" : "--retarget-at";
  const std::string opt = c.option;
  if (halt) {
    c.at = args.real("--halt-at", 0.0);
  } else {
    double t = 0.0;
    if (!split_retarget(args.text("--retarget-at", ""), t, targets)) {
      err = {"bad_number", opt,
             opt + ": expected T:NEW_DISTANCE" + (count > 1 ? std::string{",..."} : std::string{}) +
                 ", e.g. 0.2:0.05 (T in s, NEW_DISTANCE in m or rad" + (count > 1 ? ", one per axis)" : ")")};
      return false;
    }
    if (targets.size() != count) {
      err = {"bad_list", opt,
             opt + ": " + std::to_string(count) + (count == 1 ? " axis needs " : " axes need ") + std::to_string(count) +
                 (count == 1 ? " NEW_DISTANCE" : " NEW_DISTANCEs") + ", got " + std::to_string(targets.size())};
      return false;
    }
    bool finite = std::isfinite(t);
    for (const double d : targets) finite = finite && std::isfinite(d);
    if (!finite) {
      err = {"non_finite_input", opt, opt + ": T and NEW_DISTANCE must be finite"};
      return false;
    }
    for (const double d : targets) {
      if (!(std::fabs(d) <= 1e6)) {
        err = {"out_of_range", opt, opt + ": NEW_DISTANCE " + format_number(d) + " is outside -1e6..1e6"};
        return false;
      }
    }
    c.at = t;
  }
  if (!(c.at >= 0.0 && c.at <= duration)) {
    err = {"out_of_range", opt,
           opt + ": T " + format_number(c.at) + " s is outside the move, 0.." + format_number(duration) + " s"};
    return false;
  }
  if (period > 0.0) {
    c.at = std::fmax(std::nearbyint(c.at / period), 3.0) * period;
    if (!(c.at < duration)) {
      err = {"out_of_range", opt,
             opt + ": T rounds to " + format_number(c.at) + " s (whole periods, at least 3), not before the move's end " +
                 format_number(duration) + " s"};
      return false;
    }
  }
  return true;
}

// Refusals of the limits (core::online_limits) or of the blend, blamed on the option; `who` names
// the axis ("" with one).
void limits_error(core::Status st, const std::string& opt, const std::string& who, RequestError& err) {
  err = {core::to_string(st), opt,
         opt + ": " + who +
             (st == core::Status::unsupported_request
                  ? std::string{"the move steps in velocity (its acceleration is unbounded): no blend can start "
                                "from it with continuous acceleration"}
                  : "no limits for a blend: " + std::string{core::describe(st)})};
}

// The change `plan` made of `move` into `c`.
void take_plan(const core::Move<double>& move, const core::OnlinePlan& plan, OnlineChange& c) {
  c.choice = plan.choice;
  c.switch_at = c.at;
  c.blend = plan.blend;
  if (plan.choice == core::OnlineChoice::finish) {
    c.switch_at = move.duration();
    c.blend = core::Blend{{move.distance(), 0.0, 0.0, 0.0}, 0.0, {}};
  }
}

void blend_error(core::Status st, const OnlineChange& c, const std::string& who, RequestError& err) {
  const std::string opt = c.option;
  err = {core::to_string(st), opt,
         opt + ": " + who + "no blend within the limits from the move's state at " + format_number(c.at) + " s (" +
             core::describe(st) + ")"};
}

bool plan_blend(const core::Move<double>& move, OnlineChange& c, const std::string& who, RequestError& err) {
  core::OnlinePlan plan{};
  const core::Status st = plant::OnlineChangeCommand::plan(move, c.at, c.modes, c.limits, c.target, plan);
  if (st != core::Status::ok) {
    blend_error(st, c, who, err);
    return false;
  }
  take_plan(move, plan, c);
  return true;
}

}  // namespace

bool parse_online_change(const ParsedArgs& args, const core::MoveRequest& req, const core::Move<double>& move,
                         const plant::ModalPlant* plant, double period, std::optional<OnlineChange>& out,
                         RequestError& err) {
  out.reset();
  OnlineChange c{};
  std::vector<double> targets;
  if (!parse_when(args, 1, move.duration(), period, c, targets, err)) return false;
  if (std::string{c.option}.empty()) return true;
  if (!targets.empty()) c.target = targets.front();
  // Every mode the move is designed for (fastest: up to four), else the plant's fundamental.
  std::array<core::Mode, core::kMaxOnlineModes> modes{};
  const core::Mode fundamental =
      plant != nullptr ? core::Mode{plant->fundamental().omega, plant->fundamental().zeta} : core::Mode{};
  const std::size_t n = core::design_modes(req, modes, plant != nullptr ? &fundamental : nullptr);
  c.modes.assign(modes.begin(), modes.begin() + static_cast<std::ptrdiff_t>(n));
  if (const core::Status st =
          core::online_limits(req.limits, move.peaks(), c.modes.data(), c.modes.size(), c.limits);
      st != core::Status::ok) {
    limits_error(st, c.option, "", err);
    return false;
  }
  if (!plan_blend(move, c, "", err)) return false;
  out = c;
  return true;
}

bool parse_axes_online_change(const ParsedArgs& args, const core::MultiAxisRequest& req,
                              const core::MultiAxisPlan& plan, const plant::ModalPlant* plant, double period,
                              std::vector<std::optional<OnlineChange>>& out, RequestError& err) {
  out.assign(plan.count(), std::nullopt);
  OnlineChange when{};
  std::vector<double> targets;
  if (!parse_when(args, plan.count(), plan.duration(), period, when, targets, err)) return false;
  if (std::string{when.option}.empty()) return true;
  const std::string opt = when.option;
  const core::Mode fundamental =
      plant != nullptr ? core::Mode{plant->fundamental().omega, plant->fundamental().zeta} : core::Mode{};
  std::vector<std::optional<OnlineChange>> changes(plan.count());
  std::vector<core::Move<double>> moves(plan.count());
  std::vector<core::OnlineRequest> requests(plan.count());
  std::array<const core::OnlineRequest*, core::kMaxAxes> rp{};
  std::array<double, core::kMaxAxes> distance{};
  const auto who = [](std::size_t i) { return "axis " + std::to_string(i + 1) + ": "; };
  for (std::size_t i = 0; i < plan.count(); ++i) {
    if (plan.distance(i) == 0.0) {
      // It holds still the whole move: a halt leaves it so, a retarget may only keep it there.
      if (!targets.empty() && targets[i] != 0.0) {
        err = {"unsupported_request", opt,
               opt + ": " + who(i) + "it does not move, so there is no running move to retarget (give 0)"};
        return false;
      }
      continue;
    }
    core::Move<double>& move = moves[i];
    core::AxisOnline o{};
    core::Status st = core::axis_command(req, plan, i, move);
    if (st == core::Status::ok) st = core::axis_online(req, plan, i, o, plant != nullptr ? &fundamental : nullptr);
    if (st != core::Status::ok) {
      if (st == core::Status::unsupported_request && plan.path_mode_count() > core::kMaxOnlineModes) {
        err = {core::to_string(st), opt,
               opt + ": the path is shaped for " + std::to_string(plan.path_mode_count()) +
                   " modes; a blend keeps at most " + std::to_string(core::kMaxOnlineModes) + " at rest"};
      } else {
        limits_error(st, opt, who(i), err);
      }
      return false;
    }
    OnlineChange c = when;
    if (!targets.empty()) c.target = targets[i];
    c.modes.assign(o.modes.begin(), o.modes.begin() + static_cast<std::ptrdiff_t>(o.mode_count));
    c.limits = o.limits;
    st = core::online_request(move, c.at, c.modes.data(), c.modes.size(), c.limits, c.target, requests[i]);
    if (st != core::Status::ok) {
      blend_error(st, c, who(i), err);
      return false;
    }
    rp[i] = &requests[i];
    distance[i] = plan.distance(i);
    changes[i] = c;
  }
  // Path sync: a halt, or a retarget on the line, planned once and scaled per axis (every axis at
  // rest at the same instant); anything else each axis on its own.
  if (plan.sync() == core::SyncMode::path && core::path_change(rp.data(), distance.data(), plan.count())) {
    std::array<core::OnlinePlan, core::kMaxAxes> plans{};
    std::size_t ref = core::kMaxAxes;
    const core::Status st = core::plan_path_online(rp.data(), distance.data(), plan.count(), plans.data(), ref);
    if (st != core::Status::ok) {
      blend_error(st, *changes[ref], who(ref), err);
      return false;
    }
    for (std::size_t i = 0; i < plan.count(); ++i) {
      if (changes[i]) take_plan(moves[i], plans[i], *changes[i]);
    }
  } else {
    for (std::size_t i = 0; i < plan.count(); ++i) {
      if (changes[i] && !plan_blend(moves[i], *changes[i], who(i), err)) return false;
    }
  }
  out = changes;
  return true;
}

}  // namespace settle::app
