#include "move_options.hpp"

#include <cmath>
#include <string>

#include "plan_json.hpp"
#include "settle/sim/move_vocabulary.hpp"

namespace settle::cli {

bool parse_move_request(const ParsedArgs& a, core::MoveRequest& req, RequestError& err) {
  core::MoveRequest r{};
  const auto prof = a.text("--profile");
  if (!prof) {
    err = {"missing_option", "--profile", "--profile: required (" + sim::profile_list() + ")"};
    return false;
  }
  if (!core::parse_profile_kind(prof->c_str(), r.profile)) {  // the table lists only core's names
    err = {"unknown_profile", "--profile", "--profile: unknown profile '" + *prof + "'"};
    return false;
  }
  const auto distance = a.real("--distance");
  if (!distance) {
    err = {"missing_option", "--distance", "--distance: required"};
    return false;
  }
  r.distance = *distance;
  r.time = a.real("--time");
  r.vmax = a.real("--vmax");
  r.amax = a.real("--amax");
  r.jmax = a.real("--jmax");
  r.omega = a.real("--omega");
  r.zeta = a.real("--zeta", 0.0);
  const std::vector<double> omegas = a.reals("--omega"), zetas = a.reals("--zeta");
  if (omegas.size() > 1 && r.profile != core::ProfileKind::fastest) {
    err = {"bad_option", "--omega", "--omega: given more than once; only --profile fastest designs for several modes"};
    return false;
  }
  if (zetas.size() > 1 && zetas.size() != omegas.size()) {
    err = {"bad_option", "--zeta", "--zeta: give one per --omega, in the same order (or one for a single mode)"};
    return false;
  }
  for (std::size_t i = 1; i < omegas.size(); ++i) {
    r.extra_modes[i - 1] = {omegas[i], i < zetas.size() ? zetas[i] : 0.0};
    r.extra_mode_count = i;
  }
  if (r.profile == core::ProfileKind::fastest && r.time) {
    err = {"bad_option", "--time", "--time: --profile fastest finds the shortest time itself; give --vmax, --amax, --jmax"};
    return false;
  }
  r.robust = a.real("--robust");
  if (r.robust && r.profile != core::ProfileKind::fastest) {
    err = {"bad_option", "--robust", "--robust: only --profile fastest takes it"};
    return false;
  }
  r.vtol = a.real("--vtol", 0.05);
  if (a.has("--gammas")) {
    const std::vector<double> v = a.list("--gammas");
    r.gamma_count = v.size();  // at most kMaxGammas: the table's item limit
    for (std::size_t i = 0; i < v.size() && i < r.gammas.size(); ++i) r.gammas[i] = v[i];
  } else if (r.profile == core::ProfileKind::pseudopoly) {
    err = {"missing_option", "--gammas", "--gammas: required for the pseudopoly profile"};
    return false;
  }
  if (a.has("--y")) {
    const std::vector<double> v = a.list("--y");
    r.y_fractions = std::array<double, 3>{v[0], v[1], v[2]};
  }
  (void)sim::parse_shaper(a.text("--shaper", "none"), r.shaper);  // the table lists only these names
  req = r;
  return true;
}

bool plan_move(const core::MoveRequest& req, core::Move<double>& out, RequestError& err) {
  const core::Status st = core::plan(req, out);
  if (st != core::Status::ok) {
    const char* p = sim::option_of(st, req);
    err = {core::to_string(st), p, std::string{p} + ": " + core::describe(st)};
    return false;
  }
  // What the options allow can still plan into a move too long or too extreme to report:
  // refuse it here, before anything is printed or sized from it.
  const char* main = req.time ? "--time" : (req.vmax ? "--vmax" : "--distance");
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

bool move_from_args(const ParsedArgs& args, core::Move<double>& out, RequestError& err) {
  if (const auto file = args.text("--plan-from")) {
    for (const char* o : {"--profile", "--distance", "--time", "--vmax", "--amax", "--jmax", "--omega", "--zeta",
                          "--gammas", "--y", "--shaper", "--vtol"}) {
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
  if (!parse_move_request(args, req, err)) return false;
  return plan_move(req, out, err);
}

}  // namespace settle::cli
