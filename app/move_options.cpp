// SPDX-License-Identifier: Apache-2.0
#include "move_options.hpp"

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "io/plan_json.hpp"
#include "settle/plant/move_vocabulary.hpp"

namespace settle::app {

namespace {

bool parse_profile(const ParsedArgs& a, core::MoveRequest& r, RequestError& err) {
  const auto prof = a.text("--profile");
  if (!prof) {
    err = {"missing_option", "--profile", "--profile: required (" + plant::profile_list() + ")"};
    return false;
  }
  if (!core::parse_profile_kind(prof->c_str(), r.profile)) {  // the table lists only core's names
    err = {"unknown_profile", "--profile", "--profile: unknown profile '" + *prof + "'"};
    return false;
  }
  return true;
}

// What shapes the move besides its distance, limits and modes (shared by every axis of --axes).
void parse_shape(const ParsedArgs& a, core::MoveRequest& r) {
  r.robust = a.real("--robust");
  r.vtol = a.real_or_default("--vtol");
  if (a.has("--gammas")) {
    const std::vector<double> v = a.list("--gammas");
    r.gamma_count = v.size();  // at most kMaxGammas: the table's item limit
    for (std::size_t i = 0; i < v.size() && i < r.gammas.size(); ++i) r.gammas[i] = v[i];
  }
  if (a.has("--y")) {
    const std::vector<double> v = a.list("--y");
    r.y_fractions = std::array<double, 3>{v[0], v[1], v[2]};
  }
  (void)plant::parse_shaper(a.text("--shaper", "none"), r.shaper);  // the table lists only these names
}

// The design parameters given on the command line: the move group's rows that name one.
core::ParamSet given_params(const ParsedArgs& a) {
  core::ParamSet s;
  for (const OptionSpec& o : move_options()) {
    if (o.param && a.has(o.name)) s = s | core::ParamSet{*o.param};
  }
  return s;
}

// Refuses an option that the move planned from `r` would ignore (core's registry says which
// profiles and shapers use each; plant::check_params_used), before anything is planned. `also_used`:
// what the command uses besides the planner (a change mid-way, the coordination of axes);
// `omega_fallback`: the command designs for the plant's fundamental when --omega is not given.
bool check_used(const ParsedArgs& a, const core::MoveRequest& r, core::ParamSet also_used, bool omega_fallback,
                RequestError& err) {
  core::Param unused{};
  std::string why;
  if (plant::check_params_used(r, given_params(a), also_used, omega_fallback, unused, why)) return true;
  const std::string o = std::string{"--"} + core::to_string(unused);
  err = {"unused_option", o, o + ": " + why};
  return false;
}

// A change mid-way (--halt-at, --retarget-at: simulate and stream) leaves the move's design modes
// at rest, whether or not its profile designs for them: it uses --omega and --zeta.
core::ParamSet used_by_command(const ParsedArgs& a) {
  if (a.has("--halt-at") || a.has("--retarget-at")) return {core::Param::omega, core::Param::zeta};
  return {};
}

// Pseudopoly without its exponents: named here, where the option is known.
bool check_required(const core::MoveRequest& r, RequestError& err) {
  if (core::profile_params(r.profile).contains(core::Param::gammas) && r.gamma_count == 0) {
    err = {"missing_option", "--gammas",
           std::string{"--gammas: required for --profile "} + core::to_string(r.profile)};
    return false;
  }
  return true;
}

constexpr const char* kPerAxisOptions[] = {"--distance", "--vmax", "--amax", "--jmax", "--omega", "--zeta"};

// Without --axes the move is one axis: no per-axis list, no --sync.
bool check_single_axis(const ParsedArgs& a, RequestError& err) {
  for (const char* o : kPerAxisOptions) {
    for (const std::vector<double>& l : a.lists(o)) {
      if (l.size() > 1) {
        err = {"bad_option", o, std::string{o} + ": a comma list gives one value per axis; it needs --axes N"};
        return false;
      }
    }
  }
  if (a.has("--sync")) {
    err = {"bad_option", "--sync", "--sync: synchronises the axes of --axes N; give --axes too"};
    return false;
  }
  return true;
}

// The per-axis values of option `o`: N of them, or (`one_for_all`) one for every axis. None when
// the option is absent.
bool axis_values(const ParsedArgs& a, const char* o, std::size_t n, bool one_for_all,
                 std::optional<std::vector<double>>& out, RequestError& err) {
  const std::vector<std::vector<double>> given = a.lists(o);
  if (given.empty()) return true;
  if (given.size() > 1) {
    err = {"bad_option", o, std::string{o} + ": with --axes give it once, one value per axis (comma-separated)"};
    return false;
  }
  std::vector<double> v = given.front();
  if (v.size() == 1 && one_for_all) v.assign(n, v.front());
  if (v.size() != n) {
    err = {"bad_list", o,
           std::string{o} + ": --axes " + std::to_string(n) + " needs " + std::to_string(n) +
               " comma-separated values" + (one_for_all ? " (or one for every axis)" : "") + ", got " +
               std::to_string(given.front().size())};
    return false;
  }
  out = std::move(v);
  return true;
}

}  // namespace

bool parse_move_request(const ParsedArgs& a, core::MoveRequest& req, RequestError& err,
                        const DesignFallback* fallback) {
  if (!check_single_axis(a, err)) return false;
  core::MoveRequest r{};
  if (!parse_profile(a, r, err)) return false;
  const auto distance = a.real("--distance");
  if (!distance) {
    err = {"missing_option", "--distance", "--distance: required"};
    return false;
  }
  r.distance = *distance;
  r.time = a.real("--time");
  r.limits = limits_of(a);
  const char* option = nullptr;
  std::string message;
  if (!plant::set_design_modes(a.reals("--omega"), a.reals("--zeta"), r, option, message)) {
    err = {"bad_option", option, std::string{option} + ": " + message};
    return false;
  }
  parse_shape(a, r);
  if (!check_used(a, r, used_by_command(a), fallback != nullptr && core::needs_mode(r), err) ||
      !check_required(r, err)) {
    return false;
  }
  if (fallback != nullptr && !a.has("--omega") && core::needs_mode(r)) {
    const std::vector<double> zetas = a.reals("--zeta");
    r.set_mode(fallback->omega, zetas.empty() ? fallback->zeta : zetas[0]);
  }
  req = r;
  return true;
}

bool wants_axes(const ParsedArgs& a) { return a.has("--axes"); }

bool parse_axes_request(const ParsedArgs& a, core::MultiAxisRequest& req, RequestError& err,
                        const DesignFallback* fallback) {
  core::MultiAxisRequest r{};
  if (!parse_profile(a, r.base, err)) return false;
  r.count = static_cast<std::size_t>(a.integer("--axes", 1));  // 1..kMaxAxes: the table's range
  r.sync = a.text("--sync", "path") == "time" ? core::SyncMode::time : core::SyncMode::path;
  std::optional<std::vector<double>> d, vmax, amax, jmax, omega, zeta;
  if (!axis_values(a, "--distance", r.count, false, d, err)) return false;
  if (!d) {
    err = {"missing_option", "--distance", "--distance: required (" + std::to_string(r.count) +
                                               " comma-separated values, one per axis)"};
    return false;
  }
  if (!axis_values(a, "--vmax", r.count, true, vmax, err) || !axis_values(a, "--amax", r.count, true, amax, err) ||
      !axis_values(a, "--jmax", r.count, true, jmax, err) || !axis_values(a, "--omega", r.count, false, omega, err) ||
      !axis_values(a, "--zeta", r.count, false, zeta, err)) {
    return false;
  }
  for (std::size_t i = 0; i < r.count; ++i) {
    core::AxisSpec& x = r.axes[i];
    x.distance = (*d)[i];
    if (vmax) x.limits.vmax = (*vmax)[i];
    if (amax) x.limits.amax = (*amax)[i];
    if (jmax) x.limits.jmax = (*jmax)[i];
    if (omega) x.omega = (*omega)[i];
    if (zeta) x.zeta = (*zeta)[i];
  }
  r.base.time = a.real("--time");
  parse_shape(a, r.base);
  // The axes' limits and modes are checked as one axis's would be; besides, when the profile and
  // shaper design for no mode, the coordination shapes each axis for its own mode (ZV, or the
  // request's shaper: core::plan_axes), so --omega and --zeta are used then.
  core::MoveRequest probe = r.base;
  probe.limits.vmax = vmax ? std::optional<double>{vmax->front()} : std::nullopt;
  probe.limits.amax = amax ? std::optional<double>{amax->front()} : std::nullopt;
  probe.limits.jmax = jmax ? std::optional<double>{jmax->front()} : std::nullopt;
  probe.mode_count = 0;
  const core::ParamSet coordination =
      core::needs_mode(probe) ? core::ParamSet{} : core::ParamSet{core::Param::omega, core::Param::zeta};
  if (!check_used(a, probe, used_by_command(a) | coordination, fallback != nullptr && core::needs_mode(probe), err) ||
      !check_required(probe, err)) {
    return false;
  }
  if (fallback != nullptr) probe.set_mode(fallback->omega);
  if (fallback != nullptr && !omega && core::needs_mode(probe)) {
    for (std::size_t i = 0; i < r.count && i < r.axes.size(); ++i) {
      r.axes[i].omega = fallback->omega;
      if (!zeta) r.axes[i].zeta = fallback->zeta;
    }
  }
  req = r;
  return true;
}

plant::PositionUnit position_unit(const ParsedArgs& args, plant::PositionUnit fallback) {
  const auto text = args.text("--unit");
  if (!text) return fallback;
  return plant::parse_position_unit(*text).value_or(fallback);  // the parser took only m or rad
}

core::OptionalLimits limits_of(const ParsedArgs& args) {
  return {args.real("--vmax"), args.real("--amax"), args.real("--jmax")};
}

const char* binding_limit(double distance, const core::OptionalLimits& limits, const char* fallback, double* bound) {
  const core::LimitTimes by = core::shortest_times(distance, limits);
  const char* who = fallback;
  double longest = 0.0;
  const auto take = [&](const char* name, bool given, double t) {
    if (given && !(t <= longest)) {  // NaN or inf: that limit is to blame
      longest = t;
      who = name;
    }
  };
  take("--vmax", limits.vmax.has_value(), by.by_vmax);
  take("--amax", limits.amax.has_value(), by.by_amax);
  take("--jmax", limits.jmax.has_value(), by.by_jmax);
  if (bound != nullptr) *bound = longest;
  return who;
}

bool plan_move(const core::MoveRequest& req, core::Move<double>& out, RequestError& err) {
  // Limits so small that no move within them fits the longest one allowed: refused naming the
  // limit, before the planner (which, fed a denormal, fails in ways that name another option).
  if (!req.time) {
    double bound = 0.0;
    const char* limit = binding_limit(req.distance, req.limits, "--vmax", &bound);
    if (!(bound <= kMaxSeconds)) {
      err = {"too_long", limit,
             std::string{limit} + ": a move of " + format_number(req.distance) + " within this limit lasts at least " +
                 format_number(bound) + " s; at most 3600 s"};
      return false;
    }
  }
  const core::Status st = core::plan(req, out);
  if (st != core::Status::ok) {
    const char* p = plant::option_of(st, req);
    err = {core::to_string(st), p, std::string{p} + ": " + plant::reason_of(st, req)};
    return false;
  }
  // What the options allow can still plan into a move too long or too extreme to report:
  // refuse it here, before anything is printed or sized from it.
  const char* main = req.time ? "--time" : binding_limit(req.distance, req.limits, "--distance");
  if (!std::isfinite(out.duration()) || !std::isfinite(out.distance())) {
    err = {"non_finite_result", main, std::string{main} + ": the planned move is not finite"};
    return false;
  }
  if (out.duration() > kMaxSeconds) {
    const char* who = req.time ? (out.profile().duration() > kMaxSeconds ? "--time" : "--omega") : main;
    err = {"too_long", who,
           std::string{who} + ": the planned move lasts " + format_number(out.duration()) + " s; at most 3600 s" +
               (req.time ? "" : " (raise --vmax, --amax or --jmax)")};
    return false;
  }
  return true;
}

bool plan_axes(const core::MultiAxisRequest& req, core::MultiAxisPlan& out, RequestError& err) {
  std::size_t culprit = core::kMaxAxes;
  const core::Status st = core::plan_axes(req, out, culprit);
  if (st != core::Status::ok) {
    // The option is named as for one axis with the culprit's values; the message says which axis.
    core::MoveRequest q = req.base;
    std::string axis;
    if (culprit < req.count) {
      q = core::axis_request(req, culprit);
      axis = "axis " + std::to_string(culprit + 1) + ": ";
    }
    if (st == core::Status::unsupported_request && req.sync == core::SyncMode::time) {
      err = {core::to_string(st), "--sync",
             "--sync: time plans every axis to the slowest one's duration; --profile " +
                 std::string{core::to_string(req.base.profile)} + " cannot be planned to a move time (use --sync path)"};
      return false;
    }
    const char* p = plant::option_of(st, q);
    err = {core::to_string(st), p, std::string{p} + ": " + axis + plant::reason_of(st, q)};
    return false;
  }
  if (!std::isfinite(out.duration())) {
    err = {"non_finite_result", "--distance", "--distance: the planned move is not finite"};
    return false;
  }
  if (out.duration() > kMaxSeconds) {
    const char* who = req.base.time ? "--time" : "--vmax";
    err = {"too_long", who,
           std::string{who} + ": the planned move lasts " + format_number(out.duration()) + " s; at most 3600 s"};
    return false;
  }
  return true;
}

bool move_from_args(const ParsedArgs& args, core::Move<double>& out, RequestError& err,
                    const DesignFallback* fallback) {
  if (const auto file = args.text("--plan-from")) {
    for (const char* o : {"--profile", "--distance", "--time", "--vmax", "--amax", "--jmax", "--omega", "--zeta",
                          "--gammas", "--y", "--shaper", "--vtol", "--sync"}) {
      if (args.has(o)) {
        err = {"conflicting_options", o, std::string{o} + ": the move comes from --plan-from; give no move option with it"};
        return false;
      }
    }
    core::Move<double> m{};
    if (!load_plan_file(*file, "--plan-from", m, err)) return false;
    if (!(m.duration() <= kMaxSeconds)) {
      err = {"too_long", "--plan-from", "--plan-from: the plan lasts " + format_number(m.duration()) + " s; at most 3600 s"};
      return false;
    }
    out = m;
    return true;
  }
  core::MoveRequest req{};
  if (!parse_move_request(args, req, err, fallback)) return false;
  return plan_move(req, out, err);
}

}  // namespace settle::app
