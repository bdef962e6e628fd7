// SPDX-License-Identifier: Apache-2.0
#include "io/plan_json.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include "settle/core/profiles/registry.hpp"
#include "settle/commission/tune.hpp"
#include "settle/plant/move_vocabulary.hpp"

namespace settle::app {

namespace {
// The limits given, each under its own key ("vmax", "amax", "jmax"); an absent one is left out.
void put_limits(Json& j, const core::OptionalLimits& l) {
  if (l.vmax) j["vmax"] = *l.vmax;
  if (l.amax) j["amax"] = *l.amax;
  if (l.jmax) j["jmax"] = *l.jmax;
}
}  // namespace

Json peaks_json(const core::Peaks<double>& pk) {
  const bool impulse_a = pk.velocity_step || pk.acceleration_step;
  Json peaks;
  peaks["velocity"] = pk.v;
  peaks["acceleration"] = pk.velocity_step && !std::isfinite(pk.a) ? Json(nullptr) : Json(pk.a);
  peaks["jerk"] = impulse_a && !std::isfinite(pk.j) ? Json(nullptr) : Json(pk.j);
  peaks["velocity_step"] = pk.velocity_step;
  peaks["acceleration_step"] = pk.acceleration_step;
  return peaks;
}

Json plan_json(const core::Move<double>& m) {
  Json j;
  j["status"] = "ok";
  j["profile"] = core::to_string(m.profile().kind());
  if (const std::string f = plant::profile_family(m.profile()); !f.empty()) j["family"] = f;
  j["distance"] = m.distance();
  j["duration"] = m.duration();
  j["profile_duration"] = m.profile().duration();
  Json params = Json::object();
  for (const auto& [k, v] : plant::profile_params(m.profile())) params[k] = v;
  j["params"] = params;
  j["peaks"] = peaks_json(m.peaks());
  Json impulses = Json::array();
  for (std::size_t i = 0; i < m.shaper().count; ++i) {
    impulses.push_back(Json{{"amplitude", m.shaper().amp[i]}, {"time", m.shaper().time[i]}});
  }
  j["shaper"]["impulses"] = impulses;
  return j;
}

Json shortest_json(const core::Move<double>& m, const core::MoveRequest& r) {
  const std::optional<core::FastestCertificate> c = plant::shortest_proof(m, r);
  if (!c) return Json(nullptr);
  Json j;
  j["proven"] = c->proof == core::FastestProof::proven;
  j["reason"] = core::to_string(c->proof);
  const bool located = core::located(c->proof);
  j["at"] = located ? Json(c->at) : Json(nullptr);
  j["gap"] = c->proof == core::FastestProof::proven || located ? Json(c->gap) : Json(nullptr);
  return j;
}

Json axes_json(const core::MultiAxisPlan& p, const core::MultiAxisRequest& r) {
  Json j;
  j["status"] = "ok";
  j["axes"] = p.count();
  j["sync"] = core::to_string(p.sync());
  j["profile"] = core::to_string(r.base.profile);
  j["duration"] = p.duration();
  std::array<double, core::kMaxAxes> per_axis{};
  j["line_deviation"] = core::line_deviation(p, per_axis);
  if (p.sync() == core::SyncMode::path) {
    Json path = plan_json(p.path());
    path.erase("status");
    j["path"] = path;
    Json modes = Json::array();
    for (std::size_t k = 0; k < p.path_mode_count(); ++k) {
      modes.push_back(Json{{"omega", p.path_mode(k).omega}, {"zeta", p.path_mode(k).zeta}});
    }
    j["path_modes"] = modes;
  }
  Json axes = Json::array();
  for (std::size_t i = 0; i < p.count(); ++i) {
    const core::AxisSpec& x = r.axes[i];
    Json a;
    a["distance"] = p.distance(i);
    if (x.omega) a["omega"] = *x.omega;
    a["zeta"] = x.zeta;
    Json limits = Json::object();
    put_limits(limits, x.limits);
    a["limits"] = limits;
    a["peaks"] = peaks_json(p.peaks(i));
    a["line_deviation"] = per_axis[i];
    if (p.sync() == core::SyncMode::time) {
      Json own = plan_json(p.axis_move(i));
      own.erase("status");
      a["plan"] = own;
    }
    axes.push_back(a);
  }
  j["axis"] = axes;
  return j;
}

Json request_json(const core::MoveRequest& r) {
  Json j;
  j["profile"] = core::to_string(r.profile);
  j["distance"] = r.distance;
  if (r.time) j["time"] = *r.time;
  put_limits(j, r.limits);
  // One list of the modes the move is designed for, in order, each with its omega and zeta (read
  // back by request_modes, below); none: no "modes".
  if (r.has_mode()) {
    Json modes = Json::array();
    for (const core::Mode& m : r.mode_list()) modes.push_back(Json{{"omega", m.omega}, {"zeta", m.zeta}});
    j["modes"] = modes;
  }
  if (r.robust) j["robust"] = *r.robust;
  if (r.gamma_count > 0) j["gammas"] = std::vector<double>(r.gammas.begin(), r.gammas.begin() + static_cast<std::ptrdiff_t>(r.gamma_count));
  if (r.y_fractions) j["y"] = *r.y_fractions;
  if (r.shaper != core::ShaperKind::none) {
    j["shaper"] = core::to_string(r.shaper);
    j["vtol"] = r.vtol;
  }
  return j;
}

bool read_bounded_file(const std::string& path, const std::string& option, std::size_t max_bytes, std::string& out,
                       RequestError& err) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    err = {"cannot_read", option, option + ": cannot read '" + path + "'"};
    return false;
  }
  std::string text;
  char buf[65536];
  std::size_t n = 0;
  bool too_large = false;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
    if (text.size() + n > max_bytes) {
      too_large = true;
      break;
    }
    text.append(buf, n);
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (too_large) {
    err = {"file_too_large", option, option + ": '" + path + "' is larger than " + std::to_string(max_bytes) + " bytes"};
    return false;
  }
  if (failed) {
    err = {"cannot_read", option, option + ": cannot read '" + path + "' (a directory?)"};
    return false;
  }
  out = std::move(text);
  return true;
}

namespace {

bool close_to(double a, double b) { return std::fabs(a - b) <= 1e-9 * std::max({1.0, std::fabs(a), std::fabs(b)}); }

bool mismatch_err(RequestError& err, const std::string& option, const std::string& what) {
  err = {"plan_mismatch", option,
         option + ": " + what + " differs from what its request plans (edited, or made by another version?)"};
  return false;
}

// A mode as plan files write it: {"omega": finite number, "zeta": finite number}.
bool finite_mode(const Json& m) {
  const auto finite = [&](const char* k) { return m.contains(k) && m[k].is_number() && std::isfinite(m[k].get<double>()); };
  return m.is_object() && finite("omega") && finite("zeta");
}

// The shaper settle tune designed for the plan: "candidate": {"shaper", "design_modes"} and
// "residual_max", designed again by commission::tuned_shaper.
bool designed_shaper(const Json& j, core::Shaper<double>& out, RequestError& err, const std::string& option) {
  auto bad = [&](const std::string& why) {
    err = {"bad_plan_file", option, option + ": " + why};
    return false;
  };
  if (!j.contains("candidate") || !j["candidate"].is_object()) return bad("no \"candidate\" object (the output of settle tune --json)");
  const Json& c = j["candidate"];
  core::ShaperKind kind{};
  if (!c.contains("shaper") || !c["shaper"].is_string() || !plant::parse_shaper(c["shaper"].get<std::string>(), kind)) {
    return bad("candidate.shaper is not a shaper's name");
  }
  if (!c.contains("design_modes") || !c["design_modes"].is_array() || c["design_modes"].size() > commission::kMaxTuneModes) {
    return bad("candidate.design_modes must be an array of at most " + std::to_string(commission::kMaxTuneModes) + " modes");
  }
  std::vector<double> omega, zeta;
  for (const Json& m : c["design_modes"]) {
    if (!finite_mode(m)) return bad("every candidate.design_modes entry needs finite numbers \"omega\" and \"zeta\"");
    omega.push_back(m["omega"].get<double>());
    zeta.push_back(m["zeta"].get<double>());
  }
  if (!j.contains("residual_max") || !j["residual_max"].is_number() || !std::isfinite(j["residual_max"].get<double>())) {
    return bad("residual_max is missing or not a finite number");
  }
  if (const core::Status st = commission::tuned_shaper(kind, omega, zeta, j["residual_max"].get<double>(), out);
      st != core::Status::ok) {
    return bad(std::string{"its shaper cannot be designed again: "} + core::describe(st));
  }
  return true;
}

// The request's "modes" (request_json writes them): the modes the move is designed for, in order,
// each {"omega", "zeta"}; absent: none. A file written before the request held one list (its first
// mode as "omega" and "zeta", the further ones as "extra_modes") reads as that same list.
template <class Bad>
bool request_modes(const Json& rq, core::MoveRequest& r, Bad& bad) {
  const bool earlier = rq.contains("omega") || rq.contains("extra_modes");
  if (earlier && rq.contains("modes")) {
    return bad("request.modes and request.omega/extra_modes are both given (one list of modes: request.modes)");
  }
  Json modes = rq.contains("modes") ? rq["modes"] : Json::array();
  const char* field = "request.modes";
  if (earlier) {
    if (!rq.contains("omega")) return bad("request.extra_modes needs request.omega, the first mode");
    modes = Json::array({Json{{"omega", rq["omega"]}, {"zeta", rq.contains("zeta") ? rq["zeta"] : Json(0.0)}}});
    if (rq.contains("extra_modes") && !rq["extra_modes"].is_array()) return bad("request.extra_modes is not an array");
    if (rq.contains("extra_modes")) modes.insert(modes.end(), rq["extra_modes"].begin(), rq["extra_modes"].end());
    field = "request.omega, zeta and extra_modes";
  }
  if (!modes.is_array() || modes.size() > core::kMaxModes) {
    return bad(std::string{field} + " must be an array of at most " + std::to_string(core::kMaxModes) + " modes");
  }
  for (const Json& m : modes) {
    if (!finite_mode(m)) {
      return bad(std::string{"every mode of "} + field + " needs finite numbers \"omega\" and \"zeta\"");
    }
    (void)r.add_mode({m["omega"].get<double>(), m["zeta"].get<double>()});
  }
  return true;
}

// The request's optional parts beyond distance, time, limits and modes: pseudopoly's exponents
// ("gammas"), ramp-versine's given Y/L ("y"), and a shaper by name with its EI tolerance.
template <class Bad>
bool request_extras(const Json& rq, core::MoveRequest& r, Bad& bad) {
  auto finite = [](const Json& v) { return v.is_number() && std::isfinite(v.get<double>()); };
  if (rq.contains("gammas")) {
    const Json& g = rq["gammas"];
    if (!g.is_array() || g.empty() || g.size() > core::kMaxGammas || !std::all_of(g.begin(), g.end(), finite)) {
      return bad("request.gammas must be an array of 1 to " + std::to_string(core::kMaxGammas) + " finite numbers");
    }
    for (const Json& v : g) r.gammas[r.gamma_count++] = v.get<double>();
  }
  if (rq.contains("y")) {
    const Json& y = rq["y"];
    if (!y.is_array() || y.size() != 3 || !std::all_of(y.begin(), y.end(), finite)) {
      return bad("request.y must be an array of 3 finite numbers (Y1/L, Y2/L, Y3/L)");
    }
    r.y_fractions = std::array<double, 3>{y[0].get<double>(), y[1].get<double>(), y[2].get<double>()};
  }
  if (rq.contains("shaper") && (!rq["shaper"].is_string() || !plant::parse_shaper(rq["shaper"].get<std::string>(), r.shaper))) {
    return bad("request.shaper is not a shaper's name (" + plant::shaper_list() + ")");
  }
  if (rq.contains("vtol")) {
    if (!finite(rq["vtol"])) return bad("request.vtol is not a finite number");
    r.vtol = rq["vtol"].get<double>();
  }
  return true;
}

}  // namespace

bool read_json_object_file(const std::string& path, const std::string& option, const JsonDocumentKind& kind,
                           Json& out, RequestError& err) {
  std::string text;
  if (!read_bounded_file(path, option, kind.max_bytes, text, err)) return false;
  auto bad = [&](const std::string& why) {
    err = {kind.code, option, option + ": " + why};
    return false;
  };
  if (json_nesting_depth(text) > kMaxJsonDepth) {
    return bad("nests arrays and objects more than " + std::to_string(kMaxJsonDepth) + " levels deep; a " + kind.name +
               " nests 4");
  }
  out = Json::parse(text, nullptr, false);
  if (out.is_discarded() || !out.is_object()) {
    return bad(std::string{"not a JSON object (the output of "} + kind.producer + ")");
  }
  return true;
}

bool load_plan_file(const std::string& path, const std::string& option, core::Move<double>& out, RequestError& err) {
  Json j;
  if (!read_json_object_file(path, option, {"plan file", "settle plan --json or settle tune --json", "bad_plan_file", kMaxPlanFileBytes}, j,
                             err)) {
    return false;
  }
  auto bad = [&](const std::string& why) {
    err = {"bad_plan_file", option, option + ": " + why};
    return false;
  };
  if (!j.contains("status") || j["status"] != "ok") return bad("\"status\" is not \"ok\"");
  if (!j.contains("request") || !j["request"].is_object()) return bad("no \"request\" object");
  const Json& rq = j["request"];
  core::MoveRequest r{};
  if (!rq.contains("profile") || !rq["profile"].is_string() ||
      !core::parse_profile_kind(rq["profile"].get<std::string>().c_str(), r.profile)) {
    return bad("request.profile is not a profile's name (" + plant::profile_list() + ")");
  }
  auto number = [&](const char* key, std::optional<double>& to, bool required) {
    if (!rq.contains(key)) return !required;
    if (!rq[key].is_number() || !std::isfinite(rq[key].get<double>())) return false;
    to = rq[key].get<double>();
    return true;
  };
  std::optional<double> distance;
  for (auto [key, to, required] : {std::tuple{"distance", &distance, true}, std::tuple{"time", &r.time, false},
                                   std::tuple{"vmax", &r.limits.vmax, false}, std::tuple{"amax", &r.limits.amax, false},
                                   std::tuple{"jmax", &r.limits.jmax, false}}) {
    if (!number(key, *to, required)) return bad(std::string{"request."} + key + " is missing or not a finite number");
  }
  r.distance = *distance;
  std::optional<double> robust;
  if (!number("robust", robust, false)) return bad("request.robust is not a finite number");
  r.robust = robust;
  if (!request_extras(rq, r, bad) || !request_modes(rq, r, bad)) return false;
  if (!j.contains("shaper") || !j["shaper"].is_object() || !j["shaper"].contains("impulses") ||
      !j["shaper"]["impulses"].is_array()) {
    return bad("no \"shaper\": {\"impulses\": [...]}");
  }
  const Json& imp = j["shaper"]["impulses"];
  if (imp.empty() || imp.size() > core::kMaxImpulses) {
    return bad("shaper.impulses must hold 1 to " + std::to_string(core::kMaxImpulses) + " impulses");
  }
  std::vector<double> amp, time;
  for (const Json& i : imp) {
    if (!i.is_object() || !i.contains("amplitude") || !i.contains("time") || !i["amplitude"].is_number() ||
        !i["time"].is_number()) {
      return bad("every shaper impulse needs numbers \"amplitude\" and \"time\"");
    }
    amp.push_back(i["amplitude"].get<double>());
    time.push_back(i["time"].get<double>());
  }
  // A tuned plan (settle tune) names its shaper in "candidate", designed for the tuned modes over
  // their intervals; a planned one (settle plan) in its request. Either way the shaper is designed
  // again from what the file says it is, never taken from the file: an edited impulse could steer
  // the axis anywhere.
  const bool tuned = j.contains("candidate");
  if (tuned && r.shaper != core::ShaperKind::none) return bad("request.shaper and candidate.shaper are both given");
  core::Move<double> planned{};  // a tuned plan's request is unshaped (checked above)
  if (const core::Status st = core::plan(r, planned); st != core::Status::ok) {
    return bad(std::string{"its request does not plan: "} + core::describe(st));
  }
  core::Shaper<double> claimed{};
  if (const core::Status st = core::custom_shaper(amp.data(), time.data(), amp.size(), claimed); st != core::Status::ok) {
    return bad(std::string{"its shaper is not valid: "} + core::describe(st));
  }
  core::Shaper<double> shaper = planned.shaper();
  if (tuned && !designed_shaper(j, shaper, err, option)) return false;
  if (shaper.count != claimed.count) return mismatch_err(err, option, "shaper.impulses (count)");
  for (std::size_t i = 0; i < shaper.count; ++i) {
    if (!close_to(shaper.amp[i], claimed.amp[i]) || !close_to(shaper.time[i], claimed.time[i])) {
      return mismatch_err(err, option, "shaper.impulses[" + std::to_string(i) + "]");
    }
  }
  const core::Move<double> m =
      tuned ? core::Move<double>{planned.profile(), shaper, core::shaped_peaks(planned.profile(), shaper, planned.peaks())}
            : planned;
  // The file's plan and the one planned again must be the same move.
  const Json again = plan_json(m);
  auto mismatch = [&](const std::string& what) { return mismatch_err(err, option, what); };
  if (!j.contains("profile") || j["profile"] != again["profile"]) return mismatch("profile");
  for (const char* key : {"distance", "duration", "profile_duration"}) {
    if (!j.contains(key) || !j[key].is_number() || !close_to(j[key].get<double>(), again[key].get<double>())) {
      return mismatch(key);
    }
  }
  if (!j.contains("params") || !j["params"].is_object() || j["params"].size() != again["params"].size()) {
    return mismatch("params");
  }
  for (const auto& [k, v] : again["params"].items()) {
    if (!j["params"].contains(k) || !j["params"][k].is_number() || !close_to(j["params"][k].get<double>(), v.get<double>())) {
      return mismatch("params." + k);
    }
  }
  out = m;
  return true;
}

}  // namespace settle::app
