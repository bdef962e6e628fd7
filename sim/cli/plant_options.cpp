#include "plant_options.hpp"

#include <cmath>
#include <map>
#include <vector>

namespace settle::cli {

namespace {

using sim::PlantKind;
using sim::SimStatus;

struct Param {
  const char* option;
  PlantKind kind;
};

// Each parameter option and the one plant it belongs to.
const Param kParams[] = {{"--mass", PlantKind::sdof},           {"--stiffness", PlantKind::sdof},
                         {"--damping", PlantKind::sdof},        {"--length", PlantKind::beam},
                         {"--modulus", PlantKind::beam},        {"--thickness", PlantKind::beam},
                         {"--width", PlantKind::beam},          {"--beam-mass", PlantKind::beam},
                         {"--tip-mass", PlantKind::beam},       {"--modes", PlantKind::beam},
                         {"--modal-damping", PlantKind::beam},  {"--inertia", PlantKind::belt},
                         {"--belt-stiffness", PlantKind::belt}, {"--belt-damping", PlantKind::belt},
                         {"--pulley-r", PlantKind::belt},       {"--pulley-R", PlantKind::belt},
                         {"--ratio", PlantKind::belt},          {"--mode", PlantKind::modes}};

bool number(const Args& a, const char* name, double& out, RequestError& err) {
  const auto s = a.get(name);
  if (!s) return true;
  if (!parse_double(*s, out)) {
    err = {"bad_number", name, std::string{name} + ": '" + *s + "' is not a number"};
    return false;
  }
  return true;
}

// The option a plant status is about, so the user is told what to change.
std::string param_of(SimStatus st, const sim::PlantSpec& s) {
  switch (s.kind) {
    case PlantKind::sdof:
      if (st == SimStatus::non_positive_mass) return "--mass";
      if (st == SimStatus::non_positive_stiffness) return "--stiffness";
      if (st == SimStatus::negative_damping || st == SimStatus::not_underdamped) return "--damping";
      if (!std::isfinite(s.sdof.mass)) return "--mass";
      if (!std::isfinite(s.sdof.stiffness)) return "--stiffness";
      return "--damping";
    case PlantKind::beam: {
      const auto& b = s.beam.params;
      if (st == SimStatus::non_positive_length) return "--length";
      if (st == SimStatus::non_positive_modulus) return "--modulus";
      if (st == SimStatus::non_positive_section) return b.thickness > 0.0 ? "--width" : "--thickness";
      if (st == SimStatus::non_positive_mass) return "--beam-mass";
      if (st == SimStatus::negative_tip_mass) return "--tip-mass";
      if (st == SimStatus::bad_mode_count || st == SimStatus::root_not_found) return "--modes";
      if (st == SimStatus::negative_damping || st == SimStatus::not_underdamped) return "--modal-damping";
      const std::pair<const char*, double> v[] = {{"--length", b.length},       {"--modulus", b.modulus},
                                                  {"--thickness", b.thickness}, {"--width", b.width},
                                                  {"--beam-mass", b.beam_mass}, {"--tip-mass", b.tip_mass}};
      for (const auto& [n, x] : v) {
        if (!std::isfinite(x)) return n;
      }
      return "--modal-damping";
    }
    case PlantKind::belt: {
      const auto& b = s.belt;
      if (st == SimStatus::non_positive_mass) return "--inertia";
      if (st == SimStatus::non_positive_stiffness) return "--belt-stiffness";
      if (st == SimStatus::negative_damping || st == SimStatus::not_underdamped) return "--belt-damping";
      if (st == SimStatus::non_positive_radius) return b.pulley_r > 0.0 ? "--pulley-R" : "--pulley-r";
      if (st == SimStatus::non_positive_ratio) return "--ratio";
      const std::pair<const char*, double> v[] = {{"--inertia", b.inertia},   {"--belt-stiffness", b.belt_stiffness},
                                                  {"--belt-damping", b.belt_damping}, {"--pulley-r", b.pulley_r},
                                                  {"--pulley-R", b.pulley_R}, {"--ratio", b.ratio}};
      for (const auto& [n, x] : v) {
        if (!std::isfinite(x)) return n;
      }
      return "--ratio";
    }
    case PlantKind::modes: return "--mode";
  }
  return "--plant";
}

}  // namespace

const std::set<std::string> kPlantValueOptions = [] {
  std::set<std::string> s{"--plant"};
  for (const Param& p : kParams) s.insert(p.option);
  return s;
}();

bool parse_plant(const Args& a, sim::PlantSpec& spec, sim::ModalPlant& plant, RequestError& err) {
  sim::PlantSpec s{};
  const auto kind = a.get("--plant");
  if (!kind) {
    err = {"missing_option", "--plant", "--plant is required (sdof, beam, belt, modes)"};
    return false;
  }
  const std::map<std::string, PlantKind> kinds{
      {"sdof", PlantKind::sdof}, {"beam", PlantKind::beam}, {"belt", PlantKind::belt}, {"modes", PlantKind::modes}};
  const auto it = kinds.find(*kind);
  if (it == kinds.end()) {
    err = {"unknown_plant", "--plant", "--plant: unknown plant '" + *kind + "' (sdof, beam, belt, modes)"};
    return false;
  }
  s.kind = it->second;
  for (const Param& p : kParams) {
    if (p.kind != s.kind && a.get(p.option)) {
      err = {"option_not_for_plant", p.option,
             std::string{p.option} + " does not apply to --plant " + sim::to_string(s.kind)};
      return false;
    }
  }
  double modes = 3.0;
  auto& b = s.beam.params;
  if (!number(a, "--mass", s.sdof.mass, err) || !number(a, "--stiffness", s.sdof.stiffness, err) ||
      !number(a, "--damping", s.sdof.damping, err) || !number(a, "--length", b.length, err) ||
      !number(a, "--modulus", b.modulus, err) || !number(a, "--thickness", b.thickness, err) ||
      !number(a, "--width", b.width, err) || !number(a, "--beam-mass", b.beam_mass, err) ||
      !number(a, "--tip-mass", b.tip_mass, err) || !number(a, "--modes", modes, err) ||
      !number(a, "--modal-damping", s.beam.modal_damping, err) || !number(a, "--inertia", s.belt.inertia, err) ||
      !number(a, "--belt-stiffness", s.belt.belt_stiffness, err) ||
      !number(a, "--belt-damping", s.belt.belt_damping, err) || !number(a, "--pulley-r", s.belt.pulley_r, err) ||
      !number(a, "--pulley-R", s.belt.pulley_R, err) || !number(a, "--ratio", s.belt.ratio, err)) {
    return false;
  }
  if (!(modes >= 1.0 && modes <= static_cast<double>(sim::kMaxBeamModes)) || modes != std::floor(modes)) {
    err = {sim::to_string(SimStatus::bad_mode_count), "--modes",
           "--modes: a whole number from 1 to " + std::to_string(sim::kMaxBeamModes)};
    return false;
  }
  s.beam.modes = static_cast<std::size_t>(modes);
  if (s.kind == PlantKind::modes) {
    const std::vector<std::string> list = a.all("--mode");
    if (list.empty()) {
      err = {"missing_option", "--mode", "--plant modes needs at least one --mode OMEGA,ZETA,GAIN"};
      return false;
    }
    for (const std::string& m : list) {
      std::vector<double> v;
      if (!parse_list(m, v) || v.size() != 3) {
        err = {"bad_number", "--mode", "--mode: expected OMEGA,ZETA,GAIN, got '" + m + "'"};
        return false;
      }
      sim::Mode mode;
      mode.omega = v[0];
      mode.zeta = v[1];
      mode.gain = v[2];
      s.modes.push_back(mode);
    }
  }
  sim::ModalPlant p;
  const SimStatus st = sim::make_plant(s, p);
  if (st != SimStatus::ok) {
    const std::string name = param_of(st, s);
    err = {sim::to_string(st), name, name + ": " + sim::describe(st)};
    return false;
  }
  spec = s;
  plant = std::move(p);
  return true;
}

}  // namespace settle::cli
