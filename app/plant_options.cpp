// SPDX-License-Identifier: Apache-2.0
#include "plant_options.hpp"

#include <cmath>
#include <initializer_list>
#include <string>
#include <vector>

#include "move_options.hpp"

namespace settle::app {

namespace {

// Of the options a combined condition depends on (a damping ratio from mass, stiffness and
// damping), the one to name: the last of them the user gave, else the first.
const char* given_of(const ParsedArgs& a, std::initializer_list<const char*> names) {
  const char* pick = *names.begin();
  for (const char* n : names) {
    if (a.has(n)) pick = n;
  }
  return pick;
}

// The option a rejected plant parameter came from, so the user is told what to change. The
// table has already checked each value alone; what is left are the conditions that combine
// several (a damping ratio of 1 or more, a beam whose modes cannot be found).
const char* plant_param(plant::SimStatus st, const std::string& kind, const ParsedArgs& a) {
  using plant::SimStatus;
  const bool damping_ratio = st == SimStatus::not_underdamped || st == SimStatus::negative_damping;
  if (kind == "sdof") {
    if (damping_ratio) return given_of(a, {"--damping", "--mass", "--stiffness", "--damping"});
    if (st == SimStatus::non_positive_mass) return "--mass";
    if (st == SimStatus::non_positive_stiffness) return "--stiffness";
  } else if (kind == "beam") {
    if (damping_ratio) return "--modal-damping";
    if (st == SimStatus::bad_mode_count || st == SimStatus::root_not_found) return "--modes";
    return given_of(a, {"--length", "--modulus", "--thickness", "--width", "--beam-mass", "--tip-mass"});
  } else if (kind == "belt") {
    if (damping_ratio) {
      return given_of(a, {"--belt-damping", "--inertia", "--belt-stiffness", "--pulley-r", "--pulley-R", "--ratio",
                          "--belt-damping"});
    }
    return given_of(a, {"--inertia", "--belt-stiffness", "--pulley-r", "--pulley-R", "--ratio"});
  } else if (kind == "modes") {
    return "--mode";
  }
  return "--plant";
}

bool sim_ok(plant::SimStatus st, const char* param, RequestError& err) {
  if (st == plant::SimStatus::ok) return true;
  err = {to_string(st), param, std::string{param} + ": " + describe(st)};
  return false;
}

// Each plant's own parameter options: one given for another plant would be silently ignored,
// so it is refused instead.
struct Owned {
  const char* option;
  const char* kind;
};
constexpr Owned kOwned[] = {{"--mass", "sdof"},          {"--stiffness", "sdof"},       {"--damping", "sdof"},
                            {"--length", "beam"},        {"--modulus", "beam"},         {"--thickness", "beam"},
                            {"--width", "beam"},         {"--beam-mass", "beam"},       {"--tip-mass", "beam"},
                            {"--modes", "beam"},         {"--modal-damping", "beam"},   {"--inertia", "belt"},
                            {"--belt-stiffness", "belt"}, {"--belt-damping", "belt"},   {"--pulley-r", "belt"},
                            {"--pulley-R", "belt"},      {"--ratio", "belt"},           {"--mode", "modes"}};

}  // namespace

bool parse_plant(const ParsedArgs& a, plant::ModalPlant& plant, RequestError& err) {
  const std::string kind = a.text_or_default("--plant");
  for (const Owned& o : kOwned) {
    if (kind != o.kind && a.has(o.option)) {
      err = {"option_not_for_plant", o.option, std::string{o.option} + ": does not apply to --plant " + kind};
      return false;
    }
  }
  plant::SimStatus st = plant::SimStatus::ok;
  if (kind == "sdof") {
    plant::SdofParams p{};
    p.mass = a.real("--mass", p.mass);
    p.stiffness = a.real("--stiffness", p.stiffness);
    p.damping = a.real("--damping", p.damping);
    st = plant::ModalPlant::make_sdof(p, plant);
  } else if (kind == "beam") {
    plant::BeamOptions o{};
    o.params.length = a.real("--length", o.params.length);
    o.params.modulus = a.real("--modulus", o.params.modulus);
    o.params.thickness = a.real("--thickness", o.params.thickness);
    o.params.width = a.real("--width", o.params.width);
    o.params.beam_mass = a.real("--beam-mass", o.params.beam_mass);
    o.params.tip_mass = a.real("--tip-mass", o.params.tip_mass);
    o.modes = static_cast<std::size_t>(a.integer("--modes", static_cast<long long>(o.modes)));
    o.modal_damping = a.real("--modal-damping", o.modal_damping);
    st = plant::ModalPlant::make_beam(o, plant);
  } else if (kind == "belt") {
    plant::BeltParams p{};
    p.inertia = a.real("--inertia", p.inertia);
    p.belt_stiffness = a.real("--belt-stiffness", p.belt_stiffness);
    p.belt_damping = a.real("--belt-damping", p.belt_damping);
    p.pulley_r = a.real("--pulley-r", p.pulley_r);
    p.pulley_R = a.real("--pulley-R", p.pulley_R);
    p.ratio = a.real("--ratio", p.ratio);
    st = plant::ModalPlant::make_belt(p, plant);
  } else {  // modes (the table admits no other name)
    std::vector<plant::Mode> modes;
    for (const std::vector<double>& v : a.lists("--mode")) {  // OMEGA,ZETA[,GAIN], each in range
      plant::Mode md{};
      md.omega = v[0];
      md.zeta = v[1];
      md.gain = v.size() > 2 ? v[2] : 1.0;  // as tune's --mode
      modes.push_back(md);
    }
    if (modes.empty()) {
      err = {"missing_option", "--mode", "--mode: OMEGA,ZETA[,GAIN] required (repeatable) for --plant modes"};
      return false;
    }
    st = plant::ModalPlant::make_modes(modes, 1.0, plant::PlantKind::modes, plant);
  }
  if (!sim_ok(st, plant_param(st, kind, a), err)) return false;
  // Parameters each in range can still combine into modes no computation should take.
  for (const plant::Mode& m : plant.modes()) {
    if (!std::isfinite(m.omega) || !(m.omega >= 1e-2 && m.omega <= 1e7) || !std::isfinite(m.gain) ||
        !std::isfinite(m.output)) {
      const char* p = plant_param(plant::SimStatus::non_finite_parameter, kind, a);
      err = {"plant_out_of_range", p,
             std::string{p} + ": the plant's natural frequencies must lie in [0.01, 1e7] rad/s (got " +
                 format_number(m.omega) + ")"};
      return false;
    }
  }
  return true;
}

bool plant_unit(const ParsedArgs& args, plant::PlantKind k, plant::PositionUnit& out, RequestError& err) {
  const plant::PositionUnit own = k == plant::PlantKind::belt ? plant::PositionUnit::rad : plant::PositionUnit::m;
  out = position_unit(args, own);
  if (k == plant::PlantKind::modes || out == own) return true;
  err = {"conflicting_options", "--unit",
         std::string{"--unit: the "} + to_string(k) + " plant's positions are in " + plant::to_string(own) +
             " (its parameters say so); --unit names the unit for --plant modes"};
  return false;
}

bool parse_drive(const ParsedArgs& a, const plant::ModalPlant& plant, testbed::DriveAxisConfig& cfg, RequestError& err) {
  testbed::DriveAxisConfig c{};
  if (plant.kind() == plant::PlantKind::belt) {
    c.scale.counts_per_unit = 65536.0 / (2.0 * 3.14159265358979323846);  // 2^16 counts per motor revolution
  }
  const long long period = a.integer("--period-us");  // 100..100000: the table's range
  c.scale.counts_per_unit = a.real("--counts-per-unit", c.scale.counts_per_unit);
  c.load_counts_per_unit = a.real("--load-counts-per-unit", c.load_counts_per_unit);
  c.model.bandwidth_hz = a.real("--bandwidth", c.model.bandwidth_hz);
  c.model.damping = a.real("--servo-damping", c.model.damping);
  c.interpolation = a.text_or_default("--interp") == "cubic" ? testbed::Interpolation::cubic : testbed::Interpolation::linear;
  c.model.servo = a.text_or_default("--drive") == "servo";
  c.scale.period_us = static_cast<std::uint32_t>(period);
  // Validate by building an axis once: the same checks the node will make.
  testbed::DriveAxis probe{};
  const plant::SimStatus st = testbed::DriveAxis::make(c, plant, 0, probe);
  if (st != plant::SimStatus::ok) {
    const char* p = st == plant::SimStatus::non_positive_scale ? "--counts-per-unit"
                    : st == plant::SimStatus::bad_drive_model  ? given_of(a, {"--bandwidth", "--servo-damping"})
                                                             : "--drive";
    return sim_ok(st, p, err);
  }
  cfg = c;
  return true;
}

}  // namespace settle::app
