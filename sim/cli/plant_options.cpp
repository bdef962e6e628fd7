#include "plant_options.hpp"

#include <cmath>
#include <vector>

namespace settle::cli {

const std::set<std::string> kPlantValueOptions = {
    "--plant",     "--mass",      "--stiffness",      "--damping",      "--length",   "--modulus",
    "--thickness", "--width",     "--beam-mass",      "--tip-mass",     "--modes",    "--modal-damping",
    "--inertia",   "--belt-stiffness", "--belt-damping", "--pulley-r", "--pulley-R", "--ratio", "--mode"};

const std::set<std::string> kDriveValueOptions = {"--period-us", "--counts-per-unit", "--load-counts-per-unit",
                                                  "--interp",    "--drive",           "--bandwidth",
                                                  "--servo-damping"};

namespace {

bool sim_ok(sim::SimStatus st, const char* param, RequestError& err) {
  if (st == sim::SimStatus::ok) return true;
  err = {sim::to_string(st), param, std::string{param} + ": " + sim::describe(st)};
  return false;
}

// The option a rejected plant parameter came from, so the user is told what to change (the
// plant constructors check in this order, so the first offending option is the one named).
const char* plant_param(sim::SimStatus st, const std::string& kind, double first_of_pair) {
  using sim::SimStatus;
  if (kind == "sdof") {
    if (st == SimStatus::non_positive_mass) return "--mass";
    if (st == SimStatus::non_positive_stiffness) return "--stiffness";
    if (st == SimStatus::negative_damping || st == SimStatus::not_underdamped) return "--damping";
  } else if (kind == "beam") {
    if (st == SimStatus::non_positive_length) return "--length";
    if (st == SimStatus::non_positive_modulus) return "--modulus";
    if (st == SimStatus::non_positive_section) return first_of_pair > 0.0 ? "--width" : "--thickness";
    if (st == SimStatus::non_positive_mass) return "--beam-mass";
    if (st == SimStatus::negative_tip_mass) return "--tip-mass";
    if (st == SimStatus::negative_damping || st == SimStatus::not_underdamped) return "--modal-damping";
    if (st == SimStatus::bad_mode_count || st == SimStatus::root_not_found) return "--modes";
  } else if (kind == "belt") {
    if (st == SimStatus::non_positive_mass) return "--inertia";
    if (st == SimStatus::non_positive_stiffness) return "--belt-stiffness";
    if (st == SimStatus::negative_damping || st == SimStatus::not_underdamped) return "--belt-damping";
    if (st == SimStatus::non_positive_radius) return first_of_pair > 0.0 ? "--pulley-R" : "--pulley-r";
    if (st == SimStatus::non_positive_ratio) return "--ratio";
  }
  return "--plant";
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

bool parse_plant(const Args& a, sim::ModalPlant& plant, RequestError& err) {
  const std::string kind = a.get("--plant").value_or("beam");
  for (const Owned& o : kOwned) {
    if (kind != o.kind && (kind == "sdof" || kind == "beam" || kind == "belt" || kind == "modes") && a.get(o.option)) {
      err = {"option_not_for_plant", o.option, std::string{o.option} + " does not apply to --plant " + kind};
      return false;
    }
  }
  if (kind == "sdof") {
    sim::SdofParams p{};
    if (!read_number(a, "--mass", p.mass, err) || !read_number(a, "--stiffness", p.stiffness, err) ||
        !read_number(a, "--damping", p.damping, err)) {
      return false;
    }
    const sim::SimStatus st = sim::ModalPlant::make_sdof(p, plant);
    return sim_ok(st, plant_param(st, kind, 0.0), err);
  }
  if (kind == "beam") {
    sim::BeamOptions o{};
    double modes = static_cast<double>(o.modes);
    if (!read_number(a, "--length", o.params.length, err) || !read_number(a, "--modulus", o.params.modulus, err) ||
        !read_number(a, "--thickness", o.params.thickness, err) || !read_number(a, "--width", o.params.width, err) ||
        !read_number(a, "--beam-mass", o.params.beam_mass, err) || !read_number(a, "--tip-mass", o.params.tip_mass, err) ||
        !read_number(a, "--modes", modes, err) || !read_number(a, "--modal-damping", o.modal_damping, err)) {
      return false;
    }
    if (!(modes >= 1.0 && modes <= static_cast<double>(sim::kMaxBeamModes)) || modes != std::floor(modes)) {
      err = {"bad_mode_count", "--modes", "--modes: a whole number from 1 to " + std::to_string(sim::kMaxBeamModes)};
      return false;
    }
    o.modes = static_cast<std::size_t>(modes);
    const sim::SimStatus st = sim::ModalPlant::make_beam(o, plant);
    return sim_ok(st, plant_param(st, kind, o.params.thickness), err);
  }
  if (kind == "belt") {
    sim::BeltParams p{};
    if (!read_number(a, "--inertia", p.inertia, err) || !read_number(a, "--belt-stiffness", p.belt_stiffness, err) ||
        !read_number(a, "--belt-damping", p.belt_damping, err) || !read_number(a, "--pulley-r", p.pulley_r, err) ||
        !read_number(a, "--pulley-R", p.pulley_R, err) || !read_number(a, "--ratio", p.ratio, err)) {
      return false;
    }
    const sim::SimStatus st = sim::ModalPlant::make_belt(p, plant);
    return sim_ok(st, plant_param(st, kind, p.pulley_r), err);
  }
  if (kind == "modes") {
    std::vector<sim::Mode> modes;
    for (const std::string& m : a.all("--mode")) {
      std::vector<double> v;
      if (!parse_list(m, v) || v.size() != 3) {
        err = {"bad_number", "--mode", "--mode: expected OMEGA,ZETA,GAIN"};
        return false;
      }
      sim::Mode md{};
      md.omega = v[0];
      md.zeta = v[1];
      md.gain = v[2];
      modes.push_back(md);
    }
    if (modes.empty()) {
      err = {"missing_option", "--mode", "--mode OMEGA,ZETA,GAIN is required (repeatable) for --plant modes"};
      return false;
    }
    return sim_ok(sim::ModalPlant::make_modes(modes, 1.0, sim::PlantKind::modes, plant), "--mode", err);
  }
  err = {"unknown_plant", "--plant", "--plant: unknown plant '" + kind + "' (sdof, beam, belt, modes)"};
  return false;
}

bool parse_drive(const Args& a, const sim::ModalPlant& plant, sim::DriveAxisConfig& cfg, std::uint32_t& period_us,
                 RequestError& err) {
  sim::DriveAxisConfig c{};
  if (plant.kind() == sim::PlantKind::belt) {
    c.counts_per_unit = 65536.0 / (2.0 * 3.14159265358979323846);  // 2^16 counts per motor revolution
  }
  double period = 1000.0;
  if (!read_number(a, "--period-us", period, err) || !read_number(a, "--counts-per-unit", c.counts_per_unit, err) ||
      !read_number(a, "--load-counts-per-unit", c.load_counts_per_unit, err) ||
      !read_number(a, "--bandwidth", c.model.bandwidth_hz, err) || !read_number(a, "--servo-damping", c.model.damping, err)) {
    return false;
  }
  if (!(period >= 100.0 && period <= 100000.0) || period != std::floor(period)) {
    err = {"bad_number", "--period-us", "--period-us: a whole number of microseconds from 100 to 100000"};
    return false;
  }
  const std::string interp = a.get("--interp").value_or("linear");
  if (interp != "linear" && interp != "cubic") {
    err = {"bad_option", "--interp", "--interp: linear or cubic"};
    return false;
  }
  c.interpolation = interp == "cubic" ? sim::Interpolation::cubic : sim::Interpolation::linear;
  const std::string drive = a.get("--drive").value_or("ideal");
  if (drive != "ideal" && drive != "servo") {
    err = {"bad_option", "--drive", "--drive: ideal or servo"};
    return false;
  }
  c.model.servo = drive == "servo";
  c.period_s = period * 1e-6;
  // Validate by building an axis once: the same checks the node will make.
  sim::DriveAxis probe{};
  if (!sim_ok(sim::DriveAxis::make(c, plant, 0, probe), "--drive", err)) return false;
  cfg = c;
  period_us = static_cast<std::uint32_t>(period);
  return true;
}

}  // namespace settle::cli
