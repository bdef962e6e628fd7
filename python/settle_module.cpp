// SPDX-License-Identifier: Apache-2.0
// The `settle` Python package's extension (settle._settle, re-exported by settle/__init__.py, typed
// in settle/__init__.pyi): core's planner and sim's simulator for analysis in notebooks.
//   settle.plan(**move)               the plan as a dict, as `settle plan --json` prints it
//   settle.sample(dt=..., **move)     numpy arrays t, position, velocity, acceleration, jerk
//   settle.simulate(plant=..., **move) the residual-vibration metrics of the move on a plant
// The move's keywords are the CLI's options without their dashes (profile, distance, time, vmax,
// amax, jmax, omega, zeta, gammas, y, shaper, vtol, robust); for profile 'fastest', omega and zeta
// may be lists, one per mode, as --omega and --zeta repeat. A bad value raises ValueError naming the
// keyword; an unknown keyword raises TypeError, as for any Python function.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "settle/core/planner.hpp"
#include "settle/plant/command.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/plant/move_vocabulary.hpp"
#include "settle/plant/simulate.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace settle::python {
namespace {

// ValueError("<keyword>: <reason>").
[[noreturn]] void bad(const std::string& keyword, const std::string& reason) {
  throw py::value_error(keyword + ": " + reason);
}

double number(const py::handle& v, const char* keyword) {
  if (py::isinstance<py::bool_>(v) || !(py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v) ||
                                        py::hasattr(v, "__float__"))) {
    bad(keyword, "expected a number, got " + std::string{py::str(py::type::of(v).attr("__name__"))});
  }
  const double x = v.cast<double>();
  if (!std::isfinite(x)) bad(keyword, "must be finite");
  return x;
}

// At most `most` numbers from a sequence or any iterable: an endless generator is refused after
// `most` + 1 items, before anything grows with it.
std::vector<double> numbers(const py::handle& v, const char* keyword, std::size_t most) {
  if (py::isinstance<py::str>(v) || !py::isinstance<py::iterable>(v)) bad(keyword, "expected a sequence of numbers");
  std::vector<double> out;
  for (const py::handle item : v) {
    if (out.size() == most) bad(keyword, "at most " + std::to_string(most) + " values");
    out.push_back(number(item, keyword));
  }
  return out;
}

// `x` within the range the CLI's option of the same name has (plant::move_range).
double in_range(double x, const plant::Range& r, const char* keyword) {
  if (!r.contains(x)) bad(keyword, "out of range: expected a number in " + r.text());
  return x;
}

std::string text(const py::handle& v, const char* keyword) {
  if (!py::isinstance<py::str>(v)) bad(keyword, "expected a string");
  return v.cast<std::string>();
}

constexpr const char* kMoveKeywords[] = {"profile", "distance", "time", "vmax",   "amax",   "jmax", "omega",
                                         "zeta",    "gammas",   "y",    "shaper", "vtol",   "robust"};

// A number, or a sequence of at most `most` numbers (its length checked before any is read).
std::vector<double> number_or_numbers(const py::handle& v, const char* keyword, std::size_t most) {
  if (!py::isinstance<py::sequence>(v) || py::isinstance<py::str>(v)) return {number(v, keyword)};
  if (py::len(v) > most) bad(keyword, "at most " + std::to_string(most) + " values");
  return numbers(v, keyword, most);
}

bool is_move_keyword(const std::string& k) {
  for (const char* m : kMoveKeywords) {
    if (k == m) return true;
  }
  return false;
}

// Every keyword must be a move keyword or one of `extra`.
void check_keywords(const py::kwargs& kw, std::initializer_list<const char*> extra) {
  for (const auto& [key, value] : kw) {
    const std::string k = py::str(key);
    bool known = is_move_keyword(k);
    for (const char* e : extra) known = known || k == e;
    if (!known) throw py::type_error("unexpected keyword argument '" + k + "'");
  }
}

core::MoveRequest move_request(const py::kwargs& kw) {
  core::MoveRequest r{};
  const std::string profile = kw.contains("profile") ? text(kw["profile"], "profile") : "";
  if (profile.empty()) bad("profile", "required (" + plant::profile_list() + ")");
  if (!core::parse_profile_kind(profile.c_str(), r.profile)) bad("profile", "unknown profile '" + profile + "'");
  if (!kw.contains("distance")) bad("distance", "required");
  r.distance = in_range(number(kw["distance"], "distance"), plant::move_range::distance, "distance");
  struct Optional {
    const char* name;
    std::optional<double>* field;
    plant::Range range;
  };
  const Optional optional_numbers[] = {{"time", &r.time, plant::move_range::time},
                                       {"vmax", &r.limits.vmax, plant::move_range::vmax},
                                       {"amax", &r.limits.amax, plant::move_range::amax},
                                       {"jmax", &r.limits.jmax, plant::move_range::jmax},
                                       {"robust", &r.robust, plant::move_range::robust}};
  for (const Optional& o : optional_numbers) {
    if (kw.contains(o.name) && !kw[o.name].is_none()) *o.field = in_range(number(kw[o.name], o.name), o.range, o.name);
  }
  // omega and zeta: a number, or (profile 'fastest') one per mode, as --omega and --zeta repeat.
  constexpr std::size_t kModes = core::kMaxModes;
  const std::vector<double> omegas =
      kw.contains("omega") && !kw["omega"].is_none() ? number_or_numbers(kw["omega"], "omega", kModes) : std::vector<double>{};
  const std::vector<double> zetas = kw.contains("zeta") ? number_or_numbers(kw["zeta"], "zeta", kModes) : std::vector<double>{};
  for (const double w : omegas) (void)in_range(w, plant::move_range::omega, "omega");
  for (const double z : zetas) (void)in_range(z, plant::move_range::zeta, "zeta");
  const char* option = nullptr;
  std::string message;
  if (!plant::set_design_modes(omegas, zetas, r, option, message)) bad(option + 2, message);
  if (kw.contains("vtol")) r.vtol = in_range(number(kw["vtol"], "vtol"), plant::move_range::vtol, "vtol");
  if (kw.contains("gammas") && !kw["gammas"].is_none()) {
    const std::vector<double> g = numbers(kw["gammas"], "gammas", core::kMaxGammas);
    for (std::size_t i = 0; i < g.size(); ++i) r.gammas[i] = in_range(g[i], plant::move_range::gamma, "gammas");
    r.gamma_count = g.size();
  }
  if (kw.contains("y") && !kw["y"].is_none()) {
    const std::vector<double> y = numbers(kw["y"], "y", 3);
    for (const double f : y) (void)in_range(f, plant::move_range::y, "y");
    if (y.size() != 3) bad("y", "expected three fractions Y1/L, Y2/L, Y3/L");
    r.y_fractions = std::array<double, 3>{y[0], y[1], y[2]};
  }
  if (kw.contains("shaper") && !kw["shaper"].is_none()) {
    const std::string s = text(kw["shaper"], "shaper");
    if (!plant::parse_shaper(s, r.shaper)) bad("shaper", "unknown shaper '" + s + "' (" + plant::shaper_list() + ")");
  }
  // A keyword the move would ignore (its profile and shaper do not use it: core's registry) is
  // refused, as the CLI refuses the option; so is a zeta without an omega.
  core::ParamSet given;
  for (std::size_t i = 0; i < core::kParamCount; ++i) {
    const auto p = static_cast<core::Param>(i);
    if (kw.contains(core::to_string(p)) && !kw[core::to_string(p)].is_none()) given = given | core::ParamSet{p};
  }
  core::Param unused{};
  if (!plant::check_params_used(r, given, {}, false, unused, message)) bad(core::to_string(unused), message);
  return r;
}

// The keyword a planner status is about: the CLI's option without its dashes.
const char* keyword_of(core::Status s, const core::MoveRequest& r) { return plant::option_of(s, r) + 2; }

core::Move<double> planned(const py::kwargs& kw, core::MoveRequest* request = nullptr) {
  const core::MoveRequest req = move_request(kw);
  if (request) *request = req;
  core::Move<double> move{};
  if (const core::Status st = core::plan(req, move); st != core::Status::ok) {
    bad(keyword_of(st, req), plant::reason_of(st, req) + " [" + core::to_string(st) + "]");
  }
  // Never a non-finite number back: the move's own numbers, every parameter and the velocity peak.
  bool finite = std::isfinite(move.duration()) && std::isfinite(move.distance()) && std::isfinite(move.peaks().v);
  for (const auto& [name, value] : plant::profile_params(move.profile())) finite = finite && std::isfinite(value);
  if (!finite) bad("distance", "the move's numbers overflow (distance, limits and time too far apart)");
  return move;
}

// The numbers that define the profile, named as `settle plan --json` names them.
py::dict profile_params(const core::Profile<double>& prof) {
  py::dict f;
  for (const auto& [name, value] : plant::profile_params(prof)) f[py::str(name)] = value;
  return f;
}

py::dict plan(const py::kwargs& kw) {
  check_keywords(kw, {});
  core::MoveRequest req{};
  const core::Move<double> m = planned(kw, &req);
  const auto& pk = m.peaks();
  py::list impulses;
  for (std::size_t i = 0; i < m.shaper().count; ++i) {
    impulses.append(py::dict("amplitude"_a = m.shaper().amp[i], "time"_a = m.shaper().time[i]));
  }
  py::dict out("status"_a = "ok", "profile"_a = core::to_string(m.profile().kind()), "distance"_a = m.distance(),
               "duration"_a = m.duration(), "profile_duration"_a = m.profile().duration(),
               "params"_a = profile_params(m.profile()),
               "peaks"_a = py::dict("velocity"_a = pk.v, "acceleration"_a = pk.a, "jerk"_a = pk.j,
                                    "velocity_step"_a = pk.velocity_step, "acceleration_step"_a = pk.acceleration_step),
               "shaper"_a = py::dict("impulses"_a = impulses));
  // The family that won, for a profile that plans several (fastest), as `settle plan` reports it.
  if (const std::string family = plant::profile_family(m.profile()); !family.empty()) out["family"] = family;
  // Whether a `fastest` move is proven the shortest, as `settle plan` reports it ("shortest").
  if (const auto c = plant::shortest_proof(m, req)) {
    const bool located = core::located(c->proof);
    out["shortest"] = py::dict("proven"_a = c->proof == core::FastestProof::proven, "reason"_a = core::to_string(c->proof),
                               "at"_a = located ? py::object(py::float_(c->at)) : py::object(py::none()),
                               "gap"_a = c->proof == core::FastestProof::proven || located ? py::object(py::float_(c->gap))
                                                                                          : py::object(py::none()));
  }
  return out;
}

py::dict sample(const py::kwargs& kw) {
  check_keywords(kw, {"dt"});
  if (!kw.contains("dt")) bad("dt", "required (sample period, s)");
  const double dt = number(kw["dt"], "dt");
  if (!std::isfinite(dt) || !(dt > 0.0)) bad("dt", "must be a positive, finite number of seconds");
  const core::Move<double> move = planned(kw);
  const double n_real = std::ceil(move.duration() / dt);
  if (!(n_real + 1.0 <= plant::kMaxSampleCount)) {
    bad("dt", "at most " + std::to_string(static_cast<long>(plant::kMaxSampleCount)) +
                  " samples (move duration / dt + 1), as settle sample");
  }
  const auto n = static_cast<py::ssize_t>(n_real) + 1;
  py::array_t<double> t(n), p(n), v(n), a(n), j(n);
  auto tt = t.mutable_unchecked<1>(), pp = p.mutable_unchecked<1>(), vv = v.mutable_unchecked<1>(),
       aa = a.mutable_unchecked<1>(), jj = j.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    if ((i & 0xFFFF) == 0xFFFF && PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C
    const double ti = std::min(static_cast<double>(i) * dt, move.duration());
    const core::Sample<double> s = move.at(ti);
    tt(i) = ti;
    pp(i) = s.p;
    vv(i) = s.v;
    aa(i) = s.a;
    jj(i) = s.j;
  }
  return py::dict("t"_a = t, "position"_a = p, "velocity"_a = v, "acceleration"_a = a, "jerk"_a = j);
}

plant::ModalPlant make_plant(const py::handle& spec) {
  plant::PlantSpec ps{};
  if (py::isinstance<py::str>(spec)) {
    const std::string kind = spec.cast<std::string>();
    if (kind == "sdof") {
      ps.kind = plant::PlantKind::sdof;
    } else if (kind == "beam") {
      ps.kind = plant::PlantKind::beam;
    } else if (kind == "belt") {
      ps.kind = plant::PlantKind::belt;
    } else {
      bad("plant", "unknown plant '" + kind + "' (sdof, beam, belt, or a list of (omega, zeta[, gain]) modes)");
    }
  } else if (py::isinstance<py::iterable>(spec)) {
    ps.kind = plant::PlantKind::modes;
    for (const py::handle m : spec) {
      if (ps.modes.size() == plant::kMaxModes) bad("plant", "at most " + std::to_string(plant::kMaxModes) + " modes");
      const std::vector<double> v = numbers(m, "plant", 3);
      if (v.size() < 2) bad("plant", "each mode is (omega, zeta) or (omega, zeta, gain)");
      plant::Mode mode{};
      mode.omega = v[0];
      mode.zeta = v[1];
      if (v.size() == 3) mode.gain = v[2];
      ps.modes.push_back(mode);
    }
  } else {
    bad("plant", "expected 'sdof', 'beam', 'belt' or a list of (omega, zeta[, gain]) modes");
  }
  plant::ModalPlant plant{};
  if (const plant::SimStatus st = plant::make_plant(ps, plant); st != plant::SimStatus::ok) {
    bad("plant", std::string{describe(st)} + " [" + to_string(st) + "]");
  }
  return plant;
}

py::dict simulate(const py::kwargs& kw) {
  check_keywords(kw, {"plant", "dt"});
  if (!kw.contains("plant")) bad("plant", "required ('sdof', 'beam', 'belt' or a list of (omega, zeta[, gain]) modes)");
  const plant::ModalPlant plant = make_plant(kw["plant"]);
  plant::SimOptions opt{};
  opt.record = false;
  if (kw.contains("dt")) {
    opt.dt = number(kw["dt"], "dt");
    if (!std::isfinite(opt.dt) || !(opt.dt > 0.0)) bad("dt", "must be a positive, finite number of seconds");
  }
  const core::Move<double> move = planned(kw);
  const plant::MoveCommand cmd{move};
  plant::SimResult result{};
  if (const plant::SimStatus st = plant::simulate(plant, cmd, opt, result); st != plant::SimStatus::ok) {
    bad("plant", std::string{describe(st)} + " [" + to_string(st) + "]");
  }
  const plant::SimMetrics& m = result.metrics;
  return py::dict("plant"_a = to_string(plant.kind()), "move_end"_a = m.move_end, "distance"_a = m.distance,
                  "residual_amplitude"_a = m.residual_amplitude, "step_residual"_a = m.step_residual,
                  "prv_percent"_a = m.prv_percent, "peak_deflection"_a = m.peak_deflection,
                  "final_energy"_a = m.final_energy, "settling_band"_a = m.band, "settling_time"_a = m.settling_time,
                  "mode_residual"_a = py::array_t<double>(py::ssize_t(m.mode_residual.size()), m.mode_residual.data()),
                  "mode_prv_percent"_a =
                      py::array_t<double>(py::ssize_t(m.mode_prv_percent.size()), m.mode_prv_percent.data()));
}

}  // namespace
}  // namespace settle::python

PYBIND11_MODULE(_settle, m) {
  const std::string profiles = settle::plant::profile_list();
  const std::string doc =
      "Settle: vibration-free point-to-point moves (planning, sampling, simulation).\n"
      "Every function takes the move as keywords, the `settle` CLI's options without their dashes:\n"
      "  profile (" + profiles + "),\n"
      "  distance, time (s) or vmax/amax/jmax, omega (rad/s) and zeta of the mode the move is for (profile\n"
      "  'fastest': lists, one per mode, and robust in %),\n"
      "  gammas (pseudopoly exponents), y (ramp-versine Y/L fractions), shaper (" + settle::plant::shaper_list() +
      "), vtol.\n"
      "A bad value raises ValueError('<keyword>: <reason>'). settle.PROFILES lists the profiles.";
  m.doc() = doc;
  py::tuple names(settle::core::kProfileCount);
  for (std::size_t i = 0; i < settle::core::kProfileCount; ++i) names[i] = settle::core::profile_names()[i];
  m.attr("PROFILES") = names;
  m.attr("__version__") = SETTLE_VERSION;  // the project's version, as `settle --version` prints it
  m.def("plan", &settle::python::plan,
        "plan(**move) -> dict: the planned move as `settle plan --json` prints it (status, profile, distance,\n"
        "duration, profile_duration, params, peaks, shaper.impulses); an infinite peak is math.inf.");
  m.def("sample", &settle::python::sample,
        "sample(dt=..., **move) -> dict of numpy arrays t, position, velocity, acceleration, jerk: the move at\n"
        "t = 0, dt, 2 dt, ... and at its end (as `settle sample --dt` prints).");
  m.def("simulate", &settle::python::simulate,
        "simulate(plant=..., dt=1e-4, **move) -> dict of residual-vibration metrics of the move on a plant:\n"
        "plant is 'sdof', 'beam', 'belt' (the papers' defaults) or a list of (omega, zeta[, gain]) modes.\n"
        "Keys: residual_amplitude, step_residual, prv_percent, peak_deflection, final_energy, settling_band,\n"
        "settling_time, move_end, distance, mode_residual and mode_prv_percent (numpy arrays, per mode).");
}
