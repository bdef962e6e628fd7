// settle simulate: plan a move with what the user believes (--omega/--zeta, or the plant's own
// fundamental mode when not given) and run it on the plant's true parameters.
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include "commands.hpp"
#include "json.hpp"
#include "move_options.hpp"
#include "plant_options.hpp"
#include "settle/sim/figures.hpp"
#include "settle/sim/sensitivity.hpp"
#include "settle/sim/simulate.hpp"

namespace settle::cli {

namespace {

// Whether planning uses the mode (mirrors core's rule): only then do we fill --omega/--zeta from
// the plant, and only then are they reported as what the move was designed for.
bool needs_mode(const core::MoveRequest& r) {
  return r.shaper != core::ShaperKind::none || r.profile == core::ProfileKind::scurve ||
         r.profile == core::ProfileKind::scurve_damped ||
         (r.profile == core::ProfileKind::ramp_versine && !r.y_fractions);
}

const char* units(sim::PlantKind k) { return k == sim::PlantKind::belt ? "rad" : "m"; }

bool positive_option(const Args& a, const char* name, double& out, RequestError& err) {
  const auto s = a.get(name);
  if (!s) return true;
  double v = 0.0;
  if (!parse_double(*s, v) || !std::isfinite(v) || !(v > 0.0)) {
    err = {"bad_number", name, std::string{name} + ": must be a positive, finite number"};
    return false;
  }
  out = v;
  return true;
}

void print_json(const sim::ModalPlant& plant, const core::Move<double>& move, const core::MoveRequest& req,
                const sim::SimMetrics& m, const sim::InsensitivityWidth* width) {
  JsonWriter w{stdout};
  w.begin_object()
      .field("status", "ok")
      .field("plant", sim::to_string(plant.kind()))
      .field("units", units(plant.kind()))
      .field("profile", core::to_string(move.profile().kind()))
      .field("distance", move.distance())
      .field("move_duration", move.duration());
  if (needs_mode(req)) w.field("designed_omega", *req.omega).field("designed_zeta", req.zeta);
  w.field("residual_amplitude", m.residual_amplitude)
      .field("prv_percent", m.prv_percent)
      .field("step_residual", m.step_residual)
      .field("peak_deflection", m.peak_deflection)
      .field("final_energy", m.final_energy)
      .field("settling_band", m.band)
      .field("settling_time", m.settling_time);
  if (width != nullptr) {
    w.key("insensitivity_width")
        .begin_object()
        .field("threshold_percent", 5.0)
        .field("ratio_lo", width->lo)
        .field("ratio_hi", width->hi)
        .field("width", width->width)
        .field("lo_open", width->lo_open)
        .field("hi_open", width->hi_open)
        .end_object();
  }
  w.key("modes").begin_array();
  for (std::size_t j = 0; j < plant.modes().size(); ++j) {
    const sim::Mode& md = plant.modes()[j];
    w.begin_object().field("omega", md.omega).field("zeta", md.zeta).field("gain", md.gain).field("output", md.output);
    if (plant.kind() == sim::PlantKind::beam) w.field("beta", md.beta).field("lambda", md.gain).field("phi_tip", md.output);
    w.field("residual_amplitude", m.mode_residual[j]).field("prv_percent", m.mode_prv_percent[j]).end_object();
  }
  w.end_array().end_object().finish();
}

void print_text(const sim::ModalPlant& plant, const core::Move<double>& move, const core::MoveRequest& req,
                const sim::SimMetrics& m, const sim::InsensitivityWidth* width) {
  const char* u = units(plant.kind());
  std::printf("plant              %s (%zu mode%s)\n", sim::to_string(plant.kind()), plant.modes().size(),
              plant.modes().size() == 1 ? "" : "s");
  for (std::size_t j = 0; j < plant.modes().size(); ++j) {
    const sim::Mode& md = plant.modes()[j];
    std::printf("  mode %zu  omega %.7g rad/s  zeta %.5g  gain %.7g", j + 1, md.omega, md.zeta, md.gain);
    if (plant.kind() == sim::PlantKind::beam) std::printf("  beta %.7f  phi(L) %.7g", md.beta, md.output);
    std::printf("  residual %.4e  PRV %.4g %%\n", m.mode_residual[j], m.mode_prv_percent[j]);
  }
  std::printf("move               %s, distance %.9g, duration %.9g s", core::to_string(move.profile().kind()),
              move.distance(), move.duration());
  if (needs_mode(req)) std::printf(" (designed for omega %.7g, zeta %.5g)", *req.omega, req.zeta);
  std::printf("\nresidual amplitude %.6e %s\n", m.residual_amplitude, u);
  std::printf("PRV                %.6g %% (of %.6e %s, an unshaped step's)\n", m.prv_percent, m.step_residual, u);
  std::printf("peak deflection    %.6e %s\n", m.peak_deflection, u);
  std::printf("final energy       %.6e J\n", m.final_energy);
  if (std::isfinite(m.settling_time)) {
    std::printf("settling time      %.6g s (band %.3e %s)\n", m.settling_time, m.band, u);
  } else {
    std::printf("settling time      never (an undamped mode stays outside the %.3e %s band)\n", m.band, u);
  }
  if (width != nullptr) {
    std::printf("5 %% width          %.4f (true/designed frequency %.4f%s .. %.4f%s)\n", width->width, width->lo,
                width->lo_open ? " or less" : "", width->hi, width->hi_open ? " or more" : "");
  }
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  std::set<std::string> values = kMoveValueOptions;
  values.insert(kPlantValueOptions.begin(), kPlantValueOptions.end());
  for (const char* o : {"--csv", "--dt", "--band", "--tail"}) values.insert(o);
  std::set<std::string> flags = kMoveFlagOptions;
  flags.insert("--sensitivity");
  const Args args{argc, argv, values, flags};
  const bool json = args.flag("--json");
  if (!args.ok()) return report_bad_request({"bad_option", args.error_param(), args.error()}, json);

  sim::ModalPlant plant;
  RequestError err;
  if (!parse_plant(args, plant, err)) return report_bad_request(err, json);
  core::MoveRequest req{};
  if (!parse_move_request(args, req, err)) return report_bad_request(err, json);
  if (needs_mode(req) && !args.get("--omega")) {
    // No belief given: design for the plant's own fundamental mode.
    req.omega = plant.fundamental().omega;
    if (!args.get("--zeta")) req.zeta = plant.fundamental().zeta;
  }
  sim::SimOptions opt;
  opt.record = args.get("--csv").has_value();
  if (!positive_option(args, "--dt", opt.dt, err) || !positive_option(args, "--band", opt.band, err) ||
      !positive_option(args, "--tail", opt.tail, err)) {
    return report_bad_request(err, json);
  }
  core::Move<double> move{};
  if (!plan_move(req, move, err)) return report_bad_request(err, json);
  if (move.duration() / opt.dt > 1e8) {
    return report_bad_request({"too_many_samples", "--dt", "--dt: more than 1e8 steps over the move"}, json);
  }

  const sim::MoveCommand cmd{move};
  sim::SimResult res;
  sim::SimStatus st = sim::simulate(plant, cmd, opt, res);
  if (st != sim::SimStatus::ok) {
    std::fprintf(stderr, "settle: simulation failed: %s\n", sim::describe(st));
    return kExitFailure;
  }
  sim::InsensitivityWidth width;
  const bool want_width = args.flag("--sensitivity");
  if (want_width) {
    const sim::Mode& f = plant.fundamental();
    const double designed = needs_mode(req) ? *req.omega : f.omega;
    st = sim::insensitivity_width(cmd, designed, f.zeta, 5.0, width);
    if (st != sim::SimStatus::ok) {
      std::fprintf(stderr, "settle: sensitivity sweep failed: %s\n", sim::describe(st));
      return kExitFailure;
    }
  }
  if (const auto csv = args.get("--csv")) {
    if (sim::write_history_csv(res.history, *csv) != sim::SimStatus::ok) {
      std::fprintf(stderr, "settle: cannot write %s\n", csv->c_str());
      return kExitFailure;
    }
  }
  if (json) {
    print_json(plant, move, req, res.metrics, want_width ? &width : nullptr);
  } else {
    print_text(plant, move, req, res.metrics, want_width ? &width : nullptr);
  }
  return kExitOk;
}

}  // namespace settle::cli
