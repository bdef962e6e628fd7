// SPDX-License-Identifier: Apache-2.0
#include "paper_scenarios.hpp"

#include <cmath>
#include <cstdio>

#include "settle/commission/energy_optimiser.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/papers/reproduce.hpp"

namespace settle::app {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string list(const std::vector<double>& v) {
  std::string s;
  for (const double x : v) s += (s.empty() ? "" : ",") + fmt("%.9g", x);
  return s;
}

// For a person: "3.015, 4.694, 5.694".
std::string shown(const std::vector<double>& v) {
  std::string s;
  for (const double x : v) s += (s.empty() ? "" : ", ") + fmt("%.4g", x);
  return s;
}

}  // namespace

plant::SimStatus paper_scenarios(PaperScenarios& out) {
  using plant::SimStatus;
  PaperScenarios s;
  // Seed 000: the Table 1 beam with the 3 modes `settle plant --plant beam` simulates.
  plant::ModalPlant beam, sdof, belt;
  SimStatus st = plant::ModalPlant::make_beam(plant::BeamOptions{}, beam);
  if (st == SimStatus::ok) st = plant::ModalPlant::make_sdof(plant::SdofParams{}, sdof);
  if (st == SimStatus::ok) st = plant::ModalPlant::make_belt(plant::BeltParams{}, belt);
  if (st != SimStatus::ok) return st;
  s.beam_omega1 = beam.modes().front().omega;
  s.sdof_omega = sdof.modes().front().omega;
  s.sdof_zeta = sdof.modes().front().zeta;
  // Seed 004: 15 motor revolutions in 1 s, the exponents optimised from (3, 4, 5) as in
  // `settle reproduce 004`.
  const double d004 = 15.0 * 2.0 * kPi;
  const commission::EnergyTarget target = commission::belt_energy_target(plant::BeltParams{}, d004, 1.0);
  commission::OptimiserResult opt;
  if ((st = commission::optimise_exponents(target, {3.0, 4.0, 5.0}, commission::OptimiserOptions{}, opt)) != SimStatus::ok) {
    return st;
  }
  s.gammas_paper.assign(papers::kPaperGammas004.begin(), papers::kPaperGammas004.end());
  s.gammas_optimised = opt.gammas;

  s.papers = {
      {"Özokutan, Karadağ, Kapucu & Kütük: ramp-cycloid S-curve for an undamped flexible base-driven "
       "system",
       "a cantilever beam with a tip mass, moved " + fmt("%g", papers::kDistances000[0]) +
           " m; the residual is the tip's",
       "S-curve", "3-4-5 polynomial"},
      {"Kapucu & Kaplan (UMTS 2005): ramp + cycloid + versine command shaping for a lightly damped "
       "system",
       "a mass-spring-damper (" + fmt("%.4g", s.sdof_omega) + " rad/s, damping ratio " + fmt("%.3g", s.sdof_zeta) +
           "), moved 0.1 m; the residual is the mass's",
       "computed input", "arbitrary Y"},
      {"Incerti: pseudo-polynomial motion commands for a belt-driven rotary platform",
       "the platform, its motor turned 15 times in 1 s; the method's exponents optimised from 3, 4, 5 to " +
           shown(s.gammas_optimised) + "; the residual is the platform's",
       "optimised exponents", "3-4-5 polynomial"},
  };

  // Seed 000: D = 0.07 m (docs/simulation.md: the S-curve's peak velocity reaches the paper's
  // 1 m/s actuator limit at T = Tn/2, so every move here stays within it) at 0.8 and 1.75 times
  // the beam's first-mode period.
  const std::vector<std::string> plant_beam{"--plant", "beam"};
  const double tn = 2.0 * kPi / s.beam_omega1;
  const std::string d000 = fmt("%.9g", papers::kDistances000[0]);
  for (const double ratio : {papers::kTimeRatios000[0], papers::kTimeRatios000[2]}) {
    const std::string t = fmt("%.9f", ratio * tn);
    const std::string tag = fmt("%g", ratio);
    const std::string when = tag + " × the beam's period (" + fmt("%.3f", ratio * tn) + " s)";
    const std::string at = "beam " + fmt("%.3f", ratio * tn) + " s, ";
    s.scenarios.push_back({"000-scurve-" + tag, at + "S-curve", 0, false, when, "m", plant_beam,
                           {"--profile", "scurve", "--distance", d000, "--time", t, "--omega",
                            fmt("%.9g", s.beam_omega1)},
                           papers::kVmax000, papers::kDistances000[0]});
    s.scenarios.push_back({"000-poly345-" + tag, at + "3-4-5", 0, true, when, "m", plant_beam,
                           {"--profile", "poly345", "--distance", d000, "--time", t}, papers::kVmax000,
                           papers::kDistances000[0]});
  }
  // Seed 001: 0.1 m at tau = 0.167 s, the computed input against the paper's arbitrary Y.
  const std::vector<std::string> plant_sdof{"--plant", "sdof"};
  const std::vector<std::string> ramp{"--profile", "ramp-versine", "--distance", "0.1", "--time",
                                      fmt("%.9g", papers::kTaus001[0])};
  const std::string when001 = fmt("%g", papers::kTaus001[0]) + " s (the paper's τ)";
  auto with = [](std::vector<std::string> v, std::initializer_list<std::string> more) {
    v.insert(v.end(), more);
    return v;
  };
  s.scenarios.push_back({"001-computed", "mass-spring, computed input", 1, false, when001, "m", plant_sdof,
                         with(ramp, {"--omega", fmt("%.9g", s.sdof_omega), "--zeta", fmt("%.9g", s.sdof_zeta)}), 2.0,
                         0.1});
  s.scenarios.push_back({"001-arbitrary", "mass-spring, arbitrary Y", 1, true, when001, "m", plant_sdof,
                         with(ramp, {"--y", list({papers::kArbitraryY001.begin(), papers::kArbitraryY001.end()})}), 2.0,
                         0.1});
  // Seed 004: the belt platform (D in motor radians; the residual in platform radians, so the
  // move's size there is D lambda), the optimised exponents against 3-4-5.
  const std::vector<std::string> plant_belt{"--plant", "belt", "--load-counts-per-unit", "1e6"};
  const std::string d = fmt("%.7f", d004);
  const double scale004 = std::stod(d) * plant::belt_lambda(plant::BeltParams{});
  const std::string when004 = "15 motor turns (" + fmt("%.2f", d004) + " rad) in 1 s";
  s.scenarios.push_back({"004-optimised", "belt, optimised exponents", 2, false, when004, "rad", plant_belt,
                         {"--profile", "pseudopoly", "--distance", d, "--time", "1", "--gammas", list(s.gammas_optimised)},
                         200.0, scale004});
  s.scenarios.push_back({"004-poly345", "belt, 3-4-5", 2, true, when004, "rad", plant_belt,
                         {"--profile", "poly345", "--distance", d, "--time", "1"}, 200.0, scale004});
  out = std::move(s);
  return SimStatus::ok;
}

Json to_json(const PaperScenarios& s) {
  Json rows = Json::array();
  for (const PaperScenario& p : s.scenarios) {
    rows.push_back(Json{{"id", p.id},
                        {"label", p.label},
                        {"paper", p.paper},
                        {"role", p.baseline ? "baseline" : "method"},
                        {"when", p.when},
                        {"unit", p.unit},
                        {"plant", p.plant},
                        {"move", p.move},
                        {"axis_vmax", p.axis_vmax},
                        {"out_scale", p.out_scale}});
  }
  Json papers = Json::array();
  for (const Paper& p : s.papers) {
    papers.push_back(
        Json{{"title", p.title}, {"machine", p.machine}, {"method", p.method}, {"baseline", p.baseline}});
  }
  return Json{{"status", "ok"},
              {"papers", papers},
              {"beam_omega1", s.beam_omega1},
              {"sdof_omega", s.sdof_omega},
              {"sdof_zeta", s.sdof_zeta},
              {"gammas_paper", s.gammas_paper},
              {"gammas_optimised", s.gammas_optimised},
              {"scenarios", rows}};
}

}  // namespace settle::app
