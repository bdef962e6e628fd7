#include "move_options.hpp"

#include <cmath>
#include <string>

namespace settle::cli {

namespace {

struct ShaperName {
  const char* name;
  core::ShaperKind kind;
};
constexpr ShaperName kShapers[] = {{"none", core::ShaperKind::none},
                                   {"zv", core::ShaperKind::zv},
                                   {"zvd", core::ShaperKind::zvd},
                                   {"zvdd", core::ShaperKind::zvdd},
                                   {"ei", core::ShaperKind::ei}};

}  // namespace

const char* param_of(core::Status s, const core::MoveRequest& r) {
  using core::Status;
  switch (s) {
    case Status::non_positive_time:
    case Status::time_too_short_for_vmax:
    case Status::missing_time_or_limits: return "--time";
    case Status::non_positive_limit:
      if (r.vmax && !(*r.vmax > 0.0)) return "--vmax";
      if (r.amax && !(*r.amax > 0.0)) return "--amax";
      return "--jmax";
    case Status::velocity_limit_exceeded: return "--vmax";
    case Status::acceleration_limit_exceeded: return "--amax";
    case Status::jerk_limit_exceeded: return "--jmax";
    case Status::non_positive_omega: return "--omega";
    case Status::zeta_out_of_range: return "--zeta";
    case Status::too_few_gammas:
    case Status::too_many_gammas:
    case Status::gamma_too_small:
    case Status::gammas_not_distinct:
    case Status::singular_system: return "--gammas";
    case Status::bad_shape_parameter: return "--y";
    case Status::vtol_out_of_range: return "--vtol";
    case Status::bad_impulse:
    case Status::shaper_gain_not_unity:
    case Status::too_many_impulses: return "--shaper";
    case Status::no_solution:
      // Without a shaper, what did not converge is the profile's own design for the mode or
      // the limits: name what the user gave for it.
      if (r.shaper != core::ShaperKind::none) return "--shaper";
      if (r.time) return "--time";
      if (r.vmax) return "--vmax";
      return "--profile";
    case Status::non_finite_input: {
      const std::pair<const char*, std::optional<double>> opts[] = {
          {"--distance", r.distance}, {"--time", r.time}, {"--vmax", r.vmax}, {"--amax", r.amax},
          {"--jmax", r.jmax},         {"--omega", r.omega}, {"--zeta", r.zeta}, {"--vtol", r.vtol}};
      for (const auto& [name, v] : opts) {
        if (v && !std::isfinite(*v)) return name;
      }
      if (r.y_fractions) return "--y";
      if (r.gamma_count > 0) return "--gammas";
      return "--distance";
    }
    default: return "--profile";
  }
}

bool parse_move_request(const ParsedArgs& a, core::MoveRequest& req, RequestError& err) {
  core::MoveRequest r{};
  const auto prof = a.text("--profile");
  if (!prof) {
    err = {"missing_option", "--profile", "--profile: required (scurve, scurve-damped, ramp-versine, pseudopoly, "
                                          "poly345, trapezoid, jerk-limited)"};
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
  const std::string s = a.text("--shaper", "none");
  for (const ShaperName& n : kShapers) {
    if (s == n.name) r.shaper = n.kind;
  }
  req = r;
  return true;
}

bool plan_move(const core::MoveRequest& req, core::Move<double>& out, RequestError& err) {
  const core::Status st = core::plan(req, out);
  if (st != core::Status::ok) {
    const char* p = param_of(st, req);
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

}  // namespace settle::cli
