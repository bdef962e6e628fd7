// SPDX-License-Identifier: Apache-2.0
#include "commissioning.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "io/modes_json.hpp"

#include "settle/testbed/drive_axis.hpp"
#include "settle/commission/identify_excitation.hpp"
#include "settle/plant/simulate.hpp"

namespace settle::app {

namespace {

// A double NaN: the NAN macro is a float, and assigning it promotes it.
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The excitation, settle identify's defaults spelled out (so that the noise level computed from
// it is the excitation's whatever the defaults become): 10 mm within 0.1 m/s, 5 m/s^2, 5000 m/s^3,
// after a train of its default length, then 4 s at rest.
constexpr double kExDistance = 0.01, kExVmax = 0.1, kExAmax = 5.0, kExJmax = 5000.0, kExHold = 4.0;
constexpr std::size_t kExTrain = commission::kDefaultTrainRoundTrips;
constexpr double kNoiseFraction = 0.01;  // of the excitation's peak load deflection
constexpr std::uint64_t kSeed = 7;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

bool number(const Json& j, const char* key, double& v) {
  if (!j.contains(key) || !j.at(key).is_number()) return false;
  v = j.at(key).get<double>();
  return std::isfinite(v);
}

bool status_ok(const std::optional<Json>& j) { return j && j->value("status", "") == "ok"; }

std::string failure_of(const char* step, const std::optional<Json>& j) {
  if (!j) return std::string{step} + ": no result";
  return std::string{step} + ": " + j->value("error", j->value("outcome", std::string{"not ok"})) +
         (j->contains("message") && j->at("message").is_string() ? " (" + j->at("message").get<std::string>() + ")"
                                                                   : std::string{});
}

}  // namespace

plant::SimStatus commissioning_scenario(CommissioningScenario& out) {
  CommissioningScenario s;
  s.id = "commissioning";
  s.label = "commissioning: identify -> tune -> stream";
  // A slow first mode (4 Hz, lightly damped) and a second at 11 Hz with four times its gain: see
  // the header for why both are measurable.
  s.modes = {{.omega = 25.0, .zeta = 0.02, .gain = 1.0}, {.omega = 70.0, .zeta = 0.05, .gain = 4.0}};
  plant::ModalPlant plant;
  if (const plant::SimStatus st = plant::ModalPlant::make_modes(s.modes, 1.0, plant::PlantKind::modes, plant);
      st != plant::SimStatus::ok) {
    return st;
  }
  const commission::IdentifyExcitation ex{
      .distance = kExDistance, .limits = {.vmax = kExVmax, .amax = kExAmax, .jmax = kExJmax}, .round_trips = kExTrain};
  core::Move<double> move{};
  if (commission::plan_identify_excitation(ex, move) != core::Status::ok) return plant::SimStatus::plan_failed;
  plant::SimOptions so{};
  so.tail = kExHold;
  plant::SimResult sr{};
  if (const plant::SimStatus st = plant::simulate(plant, plant::MoveCommand{move}, so, sr); st != plant::SimStatus::ok) {
    return st;
  }
  for (const plant::HistorySample& h : sr.history) s.peak_deflection = std::max(s.peak_deflection, std::fabs(h.deflection));
  s.noise_counts = kNoiseFraction * s.peak_deflection * testbed::DriveAxisConfig{}.load_counts_per_unit;
  s.seed = kSeed;
  s.plant = {"--plant", "modes"};
  for (const plant::Mode& m : s.modes) {
    s.plant.insert(s.plant.end(), {"--mode", fmt("%.9g", m.omega) + "," + fmt("%.9g", m.zeta) + "," + fmt("%.9g", m.gain)});
  }
  s.noise = {"--noise", fmt("%.6g", s.noise_counts), "--seed", std::to_string(s.seed)};
  s.identify = {"--max-modes", "3",  "--distance", fmt("%g", kExDistance), "--vmax", fmt("%g", kExVmax),
                "--amax", fmt("%g", kExAmax), "--jmax", fmt("%g", kExJmax), "--train", std::to_string(kExTrain),
                "--hold", fmt("%g", kExHold)};
  // The move: 0.1 m within 0.5 m/s, 5 m/s^2, 200 m/s^3, each mode's residual at most 1 % of an
  // unshaped step's over the whole identified band (so the plant's PRV is at most 1 % too).
  s.tune = {"--distance", "0.1", "--vmax", "0.5", "--amax", "5", "--jmax", "200", "--residual-max", "0.01"};
  out = std::move(s);
  return plant::SimStatus::ok;
}

Json to_json(const CommissioningScenario& s) {
  Json modes = Json::array();
  for (const plant::Mode& m : s.modes) modes.push_back(Json{{"omega", m.omega}, {"zeta", m.zeta}, {"gain", m.gain}});
  return Json{{"id", s.id},
              {"label", s.label},
              {"modes", modes},
              {"peak_deflection", s.peak_deflection},
              {"noise_counts", s.noise_counts},
              {"seed", s.seed},
              {"plant", s.plant},
              {"noise", s.noise},
              {"identify", s.identify},
              {"tune", s.tune},
              {"omega_tolerance", s.omega_tolerance},
              {"zeta_tolerance", s.zeta_tolerance},
              {"prv_max_percent", s.prv_max_percent}};
}

void judge(const CommissioningScenario& s, CommissioningResult& r) {
  r.modes.clear();
  r.modes_ok = false;
  r.prv_ok = false;
  r.prv_percent = kNaN;
  if (!r.error.empty()) return;
  if (!status_ok(r.identify)) {
    r.error = failure_of("settle identify", r.identify);
    return;
  }
  const Json& found = r.identify->value("modes", Json::array());
  bool all_within = found.is_array() && found.size() == s.modes.size();
  for (std::size_t j = 0; found.is_array() && j < found.size() && j < s.modes.size(); ++j) {
    ModeCheck c{};
    c.truth = s.modes[j];
    std::string why;
    const bool read = mode_from_json(found[j], true, c.found, why);
    c.omega_error = c.found.omega / c.truth.omega - 1.0;
    c.zeta_error = c.found.zeta - c.truth.zeta;
    c.within = read && std::fabs(c.omega_error) <= s.omega_tolerance && std::fabs(c.zeta_error) <= s.zeta_tolerance;
    all_within = all_within && c.within;
    r.modes.push_back(c);
  }
  r.modes_ok = all_within;
  if (!status_ok(r.tune)) {
    r.error = failure_of("settle tune", r.tune);
    return;
  }
  if (!status_ok(r.stream)) {
    r.error = failure_of("settle stream", r.stream);
    return;
  }
  double prv = kNaN;
  if (number(*r.stream, "prv_can_percent", prv)) r.prv_percent = prv;
  r.prv_ok = std::isfinite(r.prv_percent) && r.prv_percent <= s.prv_max_percent;
}

}  // namespace settle::app
