// SPDX-License-Identifier: Apache-2.0
// settle simulate: plan a move with what the user believes (--omega/--zeta, or the plant's own
// fundamental mode when not given) and run it on the plant's true parameters.
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "figure_option.hpp"
#include "io/json.hpp"
#include "move_options.hpp"
#include "online_options.hpp"
#include "plant_options.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/papers/figures.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/online_command.hpp"
#include "settle/plant/sensitivity.hpp"
#include "settle/plant/simulate.hpp"

namespace settle::app {

namespace {

const char* units(plant::PositionUnit u) { return plant::to_string(u); }

// The energies' unit in words (plant::energy_suffix): J, or per unit modal mass for --plant modes.
const char* energy_units(plant::PlantKind k, plant::PositionUnit u) {
  const std::string_view e = plant::energy_suffix(k, u);
  return e == "j" ? "J" : e == "j_per_kg" ? "J/kg" : "J/(kg m^2)";
}

// The whole-plant figures of a simulation, in the order both outputs (one axis, --axes) print them.
void put_metrics(Json& j, const plant::SimMetrics& m) {
  j["residual_amplitude"] = m.residual_amplitude;
  j["prv_percent"] = m.prv_percent;
  j["step_residual"] = m.step_residual;
  j["peak_deflection"] = m.peak_deflection;
  j["final_energy"] = m.final_energy;
  j["settling_band"] = m.band;
  j["settling_time"] = finite_or_null(m.settling_time);
  j["settling"] = to_string(m.settling);
}

// What a halt chose (core::OnlinePlan): the fastest blend, a blend to the target, finishing the move.
const char* choice_name(core::OnlineChoice c) {
  return c == core::OnlineChoice::finish ? "finish" : c == core::OnlineChoice::to_target ? "to_target" : "blend";
}

// A halt or retarget as both outputs (one axis, --axes) report it.
Json online_json(const OnlineChange& c) {
  return Json{{"kind", c.target ? "retarget" : "halt"},
              {"at", c.at},
              {"choice", choice_name(c.choice)},
              {"blend_duration", c.blend.duration()},
              {"command_duration", c.switch_at + c.blend.duration()},
              {"end_position", c.blend.end_position()}};
}

// The largest Euclidean distance of the commands' point (p_1(t), ..., p_N(t)) from the straight
// line from the start to (D_1, ..., D_N), sampled at 20001 instants over [0, end]: after a halt or
// retarget, where core::line_deviation (the plan's) no longer applies.
double sampled_line_deviation(const std::vector<const plant::Command*>& cmds, const core::MultiAxisPlan& plan,
                              double end) {
  std::vector<double> p(cmds.size()), dir(cmds.size());
  for (std::size_t i = 0; i < cmds.size(); ++i) dir[i] = plan.distance(i);
  double worst = 0.0;
  for (int k = 0; k <= 20000; ++k) {
    const double t = end * k / 20000.0;
    for (std::size_t i = 0; i < cmds.size(); ++i) p[i] = cmds[i]->at(t).p;
    worst = std::fmax(worst, core::offset_from_line(p.data(), dir.data(), p.size()));
  }
  return worst;
}

// Every number simulate reports; the settling time is null when it never comes (an undamped
// mode), and the text output says "never".
// Whether the move (its profile or shaper), or the change of it, designs for the mode's damping:
// the zeta reported beside omega is then one the move was designed with (scurve's is not).
bool designs_for_zeta(const core::MoveRequest& req, const OnlineChange* change) {
  return change != nullptr || core::used_params(req).contains(core::Param::zeta);
}

Json result_json(const plant::ModalPlant& plant, const core::Move<double>& move, const core::MoveRequest& req,
                 const plant::SimMetrics& m, const plant::InsensitivityWidth* width, const OnlineChange* change,
                 plant::PositionUnit u) {
  Json j;
  j["status"] = "ok";
  j["plant"] = to_string(plant.kind());
  j["units"] = units(u);
  j["energy_units"] = energy_units(plant.kind(), u);
  j["profile"] = core::to_string(move.profile().kind());
  j["distance"] = move.distance();
  j["duration"] = move.duration();
  if (needs_mode(req)) {
    j["designed_omega"] = req.omega();
    if (designs_for_zeta(req, change)) j["designed_zeta"] = req.zeta();
  }
  // The residual below is the one after the change: the command is the move to `at`, then the blend.
  if (change != nullptr) j["online"] = online_json(*change);
  put_metrics(j, m);
  if (width != nullptr) {
    j["insensitivity_width"] = Json{{"threshold_percent", 5.0}, {"ratio_lo", width->lo}, {"ratio_hi", width->hi},
                                    {"width", width->width},    {"lo_open", width->lo_open}, {"hi_open", width->hi_open}};
  }
  Json modes = Json::array();
  for (std::size_t k = 0; k < plant.modes().size(); ++k) {
    const plant::Mode& md = plant.modes()[k];
    Json o{{"omega", md.omega}, {"zeta", md.zeta}, {"gain", md.gain}, {"output", md.output}};
    if (plant.kind() == plant::PlantKind::beam) {
      o["beta"] = md.beta;
      o["lambda"] = md.gain;
      o["phi_tip"] = md.output;
    }
    o["residual_amplitude"] = m.mode_residual[k];
    o["prv_percent"] = m.mode_prv_percent[k];
    modes.push_back(o);
  }
  j["modes"] = modes;
  return j;
}

void print_text(const plant::ModalPlant& plant, const core::Move<double>& move, const core::MoveRequest& req,
                const plant::SimMetrics& m, const plant::InsensitivityWidth* width, const OnlineChange* change,
                plant::PositionUnit unit) {
  const char* u = units(unit);
  std::printf("plant              %s (%zu mode%s)\n", to_string(plant.kind()), plant.modes().size(),
              plant.modes().size() == 1 ? "" : "s");
  for (std::size_t j = 0; j < plant.modes().size(); ++j) {
    const plant::Mode& md = plant.modes()[j];
    std::printf("  mode %zu  omega %.7g rad/s  zeta %.5g  gain %.7g", j + 1, md.omega, md.zeta, md.gain);
    if (plant.kind() == plant::PlantKind::beam) std::printf("  beta %.7f  phi(L) %.7g", md.beta, md.output);
    std::printf("  residual %.4e  PRV %.4g %%\n", m.mode_residual[j], m.mode_prv_percent[j]);
  }
  std::printf("move               %s, distance %.9g, duration %.9g s", core::to_string(move.profile().kind()),
              move.distance(), move.duration());
  if (needs_mode(req)) {
    std::printf(" (designed for omega %.7g", req.omega());
    if (designs_for_zeta(req, change)) std::printf(", zeta %.5g", req.zeta());
    std::printf(")");
  }
  if (change != nullptr) {
    std::printf("\n%-18s at %.9g s: %s %.9g s, at rest on %.9g %s at %.9g s", change->target ? "retarget" : "halt",
                change->at, choice_name(change->choice), change->blend.duration(), change->blend.end_position(), u,
                change->switch_at + change->blend.duration());
  }
  std::printf("\nresidual amplitude %.6e %s\n", m.residual_amplitude, u);
  std::printf("PRV                %.6g %% (of %.6e %s, an unshaped step's)\n", m.prv_percent, m.step_residual, u);
  std::printf("peak deflection    %.6e %s\n", m.peak_deflection, u);
  std::printf("final energy       %.6e %s\n", m.final_energy, energy_units(plant.kind(), unit));
  if (std::isfinite(m.settling_time)) {
    std::printf("settling time      %.6g s (band %.3e %s)\n", m.settling_time, m.band, u);
  } else if (m.settling == plant::Settling::beyond_horizon) {
    std::printf("settling time      not within %.0f s of the move's end (the decay is slower; band %.3e %s)\n",
                plant::kMaxSettlingTime, m.band, u);
  } else {
    std::printf("settling time      never (an undamped mode stays outside the %.3e %s band)\n", m.band, u);
  }
  if (width != nullptr) {
    std::printf("5 %% width          %.4f (true/designed frequency %.4f%s .. %.4f%s)\n", width->width, width->lo,
                width->lo_open ? " or less" : "", width->hi, width->hi_open ? " or more" : "");
  }
}

Json metrics_json(const plant::ModalPlant& plant, const plant::SimMetrics& m) {
  Json j;
  put_metrics(j, m);
  Json modes = Json::array();
  for (std::size_t k = 0; k < plant.modes().size(); ++k) {
    modes.push_back(Json{{"omega", plant.modes()[k].omega},
                         {"zeta", plant.modes()[k].zeta},
                         {"residual_amplitude", m.mode_residual[k]},
                         {"prv_percent", m.mode_prv_percent[k]}});
  }
  j["modes"] = modes;
  return j;
}

// settle simulate --axes N, in stages: the request and its plan (with any online change per axis),
// each axis's command, the simulation of each, and the report.
struct AxesRun {
  core::MultiAxisRequest req{};
  core::MultiAxisPlan plan{};
  std::vector<std::optional<OnlineChange>> changes;
  std::vector<core::Move<double>> moves;  // a changed axis's own command (core::axis_command)
  double end{0.0};                        // the last command's end (s)
  bool changed{false};
};

// The request, its plan and each axis's change. With a change, every changed axis runs its own
// command (core::axis_command) to the switch and then its blend; the others (and every axis without
// one) the plan's own. Exit status, or -1 to go on.
int plan_simulated_axes(const ParsedArgs& args, const plant::ModalPlant& plant, AxesRun& run) {
  const bool json = args.json();
  for (const char* o : {"--sensitivity", "--csv", "--png"}) {
    if (args.has(o)) {
      return report_bad_request({"conflicting_options", o, std::string{o} + ": one axis at a time; not with --axes"},
                                json);
    }
  }
  RequestError err;
  const DesignFallback fundamental{plant.fundamental().omega, plant.fundamental().zeta};
  if (!parse_axes_request(args, run.req, err, &fundamental)) return report_bad_request(err, json);
  if (!plan_axes(run.req, run.plan, err)) return report_bad_request(err, json);
  if (!parse_axes_online_change(args, run.req, run.plan, &plant, 0.0, run.changes, err)) {
    return report_bad_request(err, json);
  }
  run.moves.resize(run.plan.count());
  run.end = run.plan.duration();
  for (std::size_t i = 0; i < run.plan.count(); ++i) {
    if (!run.changes[i]) continue;
    run.changed = true;
    if (const core::Status st = core::axis_command(run.req, run.plan, i, run.moves[i]); st != core::Status::ok) {
      return report_bad_request({core::to_string(st), "--distance", "--distance: axis " + std::to_string(i + 1) + ": " +
                                                                       core::describe(st)},
                                json);
    }
    run.end = std::fmax(run.end, run.changes[i]->switch_at + run.changes[i]->blend.duration());
  }
  return -1;
}

// Each axis's command: its change's, `path` scaled to the axis (sync path: the commands refer to
// it, so it outlives them), or its own move.
std::vector<std::unique_ptr<plant::Command>> axis_commands(const AxesRun& run, const plant::MoveCommand& path) {
  std::vector<std::unique_ptr<plant::Command>> cmds;
  for (std::size_t i = 0; i < run.plan.count(); ++i) {
    if (run.changes[i]) {
      cmds.push_back(
          std::make_unique<plant::OnlineChangeCommand>(run.moves[i], run.changes[i]->switch_at, run.changes[i]->blend));
    } else if (run.plan.sync() == core::SyncMode::path) {
      cmds.push_back(std::make_unique<plant::ScaledCommand>(path, run.plan.distance(i)));
    } else {
      cmds.push_back(std::make_unique<plant::MoveCommand>(run.plan.axis_move(i)));
    }
  }
  return cmds;
}

// The move's line deviation; after a change, from the changed commands, with the spread of their
// ends (s), which says whether they stop together.
void line_deviation_json(const AxesRun& run, const std::vector<const plant::Command*>& cmd_of, Json& j) {
  std::array<double, core::kMaxAxes> per_axis{};
  j["line_deviation"] =
      run.changed ? sampled_line_deviation(cmd_of, run.plan, run.end) : core::line_deviation(run.plan, per_axis);
  if (run.changed) {
    double lo = run.end, hi = 0.0;
    for (std::size_t i = 0; i < run.plan.count(); ++i) {
      if (!run.changes[i]) continue;
      lo = std::fmin(lo, cmd_of[i]->duration());
      hi = std::fmax(hi, cmd_of[i]->duration());
    }
    j["online_end_spread"] = hi - lo;
  }
}

void print_simulated_axes(const plant::ModalPlant& plant, const AxesRun& run, const Json& j,
                          const std::vector<plant::SimMetrics>& metrics, plant::PositionUnit unit) {
  const char* u = units(unit);
  std::printf("plant              %s (%zu mode%s), one per axis\n", to_string(plant.kind()), plant.modes().size(),
              plant.modes().size() == 1 ? "" : "s");
  std::printf("move               %s, %zu axes (sync %s), duration %.9g s, line deviation %.3e %s%s\n",
              core::to_string(run.req.base.profile), run.plan.count(), core::to_string(run.plan.sync()),
              run.plan.duration(), j["line_deviation"].get<double>(), u,
              j.contains("online_end_spread") ? " (after the change)" : "");
  for (std::size_t i = 0; i < run.plan.count(); ++i) {
    const plant::SimMetrics& m = metrics[i];
    std::printf("axis %zu             distance %.9g %s: residual amplitude %.6e %s, PRV %.6g %%", i + 1,
                run.plan.distance(i), u, m.residual_amplitude, u, m.prv_percent);
    if (run.req.axes[i].omega) {
      std::printf(" (designed for omega %.7g, zeta %.5g)", *run.req.axes[i].omega, run.req.axes[i].zeta);
    }
    if (const std::optional<OnlineChange>& c = run.changes[i]) {
      std::printf("\n                   %s at %.9g s: %s %.9g s, at rest on %.9g %s at %.9g s",
                  c->target ? "retarget" : "halt", c->at, choice_name(c->choice), c->blend.duration(),
                  c->blend.end_position(), u, c->switch_at + c->blend.duration());
    }
    std::printf("\n");
  }
}

// settle simulate --axes N: every axis of the coordinated move on its own copy of the plant
// (docs/multi_axis.md). Without --omega, every axis is designed for the plant's fundamental when
// the profile or shaper designs for a mode, as with one axis.
int simulate_axes(const ParsedArgs& args, const plant::ModalPlant& plant, plant::PositionUnit unit) {
  const bool json = args.json();
  AxesRun run;
  if (const int rc = plan_simulated_axes(args, plant, run); rc >= 0) return rc;
  plant::SimOptions opt;
  opt.record = false;
  opt.dt = args.real_or_default("--dt");
  opt.band = args.real("--band", opt.band);
  opt.tail = args.real("--tail", opt.tail);
  const double work = run.end / opt.dt * static_cast<double>(plant.modes().size() * run.plan.count());
  if (!(work <= kMaxSimWork)) {
    return report_bad_request({"too_many_samples", "--dt",
                               "--dt: " + format_number(work) + " grid steps x modes x axes; at most 2e6"},
                              json);
  }
  Json j;
  j["status"] = "ok";
  j["plant"] = to_string(plant.kind());
  j["units"] = units(unit);
  j["energy_units"] = energy_units(plant.kind(), unit);
  j["profile"] = core::to_string(run.req.base.profile);
  j["axes"] = run.plan.count();
  j["sync"] = core::to_string(run.plan.sync());
  j["duration"] = run.plan.duration();
  const plant::MoveCommand path{run.plan.path()};
  const std::vector<std::unique_ptr<plant::Command>> cmds = axis_commands(run, path);
  std::vector<const plant::Command*> cmd_of;
  for (const auto& c : cmds) cmd_of.push_back(c.get());
  line_deviation_json(run, cmd_of, j);
  Json axes = Json::array();
  std::vector<plant::SimMetrics> metrics;
  for (std::size_t i = 0; i < run.plan.count(); ++i) {
    plant::SimResult res;
    const plant::SimStatus st = plant::simulate(plant, *cmd_of[i], opt, res);
    if (st != plant::SimStatus::ok) {
      return report_failure("simulate", plant::to_string(st),
                            "simulation of axis " + std::to_string(i + 1) + " failed: " + describe(st), args.json());
    }
    Json a = metrics_json(plant, res.metrics);
    a["distance"] = run.plan.distance(i);
    if (run.changes[i]) a["online"] = online_json(*run.changes[i]);
    if (run.req.axes[i].omega) {
      a["designed_omega"] = *run.req.axes[i].omega;
      a["designed_zeta"] = run.req.axes[i].zeta;
    }
    axes.push_back(a);
    metrics.push_back(res.metrics);
  }
  j["axis"] = axes;
  if (!all_finite(j)) {
    return report_bad_request({"non_finite_result", "--distance",
                               "--distance: the simulation's result is not finite for this move and plant"},
                              json);
  }
  if (json) {
    print_json(j);
  } else {
    print_simulated_axes(plant, run, j, metrics, unit);
  }
  return kExitOk;
}

// The --png figure: the history beside it (<stem>.csv) and gnuplot. Empty, or why not.
std::string write_png(const plant::ModalPlant& plant, const core::Move<double>& move, const plant::SimResult& res,
                      const FigurePath& png, plant::PositionUnit unit) {
  const std::string csv = png.stem + ".csv";
  if (papers::write_history_csv(res.history, (std::filesystem::path{png.dir} / csv).string(), plant.kind(), unit) !=
      plant::SimStatus::ok) {
    return "cannot write the figure's data beside " + png.png;
  }
  const plant::SimMetrics& m = res.metrics;
  papers::SimulateFigure f{};
  f.end = m.move_end;
  f.target = m.distance;
  f.residual = m.residual_amplitude;
  f.band = m.band;
  f.unit = unit;
  const std::string u = units(unit);
  const std::size_t n = plant.modes().size();
  f.title = std::string{core::to_string(move.profile().kind())} + " move of " + format_number(move.distance()) + " " +
            u + " in " + format_number(m.move_end) + " s on a " + to_string(plant.kind()) + " plant (" +
            std::to_string(n) + (n == 1 ? " mode" : " modes") + "): residual " +
            format_number(m.residual_amplitude) + " " + u + " (PRV " + format_number(m.prv_percent) + " %)";
  papers::FigureFiles files{};
  const plant::SimStatus st = papers::write_simulate_figure(png.dir, png.stem, csv, f, files);
  if (st != plant::SimStatus::ok) return "cannot write " + png.png + ": " + plant::describe(st);
  if (!files.gnuplot) {
    std::fprintf(stderr, "settle simulate: gnuplot not found; wrote %s.gp and %s only\n", png.stem.c_str(), csv.c_str());
  }
  return {};
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("simulate", argc, argv, args); rc >= 0) return rc;
  const bool json = args.json();
  plant::ModalPlant plant;
  RequestError err;
  if (!parse_plant(args, plant, err)) return report_bad_request(err, json);
  plant::PositionUnit unit{};
  if (!plant_unit(args, plant.kind(), unit, err)) return report_bad_request(err, json);
  if (wants_axes(args)) return simulate_axes(args, plant, unit);
  std::optional<FigurePath> png;
  if (const int rc = parse_png_option(args, png); rc >= 0) return rc;
  core::MoveRequest req{};
  // No belief given: design for the plant's own fundamental mode.
  const DesignFallback fundamental{plant.fundamental().omega, plant.fundamental().zeta};
  if (!parse_move_request(args, req, err, &fundamental)) return report_bad_request(err, json);
  plant::SimOptions opt;
  opt.record = args.has("--csv") || png.has_value();
  opt.dt = args.real_or_default("--dt");
  opt.band = args.real("--band", opt.band);
  opt.tail = args.real("--tail", opt.tail);
  core::Move<double> move{};
  if (!plan_move(req, move, err)) return report_bad_request(err, json);
  std::optional<OnlineChange> change;
  if (!parse_online_change(args, req, move, &plant, 0.0, change, err)) return report_bad_request(err, json);
  const double cmd_duration = change ? change->switch_at + change->blend.duration() : move.duration();
  // Sizes, before anything is allocated: the grid over the move, and with --csv or --png the rows of the
  // history (move + tail, the tail defaulting to 3 periods of the fundamental as sim does).
  const double tail = opt.record ? (opt.tail >= 0.0 ? opt.tail : 3.0 * 2.0 * M_PI / plant.fundamental().omega) : 0.0;
  if (cmd_duration + tail > kMaxSeconds) {
    return report_bad_request({"too_long", "--tail",
                               "--tail: move + tail would be " + format_number(cmd_duration + tail) +
                                   " s; at most 3600 s"},
                              json);
  }
  const double steps = (cmd_duration + tail) / opt.dt;
  const double work = steps * static_cast<double>(plant.modes().size());
  if (!(work <= kMaxSimWork) || (opt.record && !(steps <= kMaxCsvRows))) {
    return report_bad_request({"too_many_samples", "--dt",
                               "--dt: " + format_number(steps) + " grid steps x " +
                                   format_number(static_cast<double>(plant.modes().size())) +
                                   " modes; at most 2e6 (and 1e6 rows with --csv or --png)"},
                              json);
  }

  const plant::MoveCommand plain{move};
  std::optional<plant::OnlineChangeCommand> changed;
  if (change) changed.emplace(move, change->switch_at, change->blend);
  const plant::Command& cmd = changed ? static_cast<const plant::Command&>(*changed) : plain;
  plant::SimResult res;
  plant::SimStatus st = plant::simulate(plant, cmd, opt, res);
  if (st != plant::SimStatus::ok) {
    return report_failure("simulate", plant::to_string(st), std::string{"simulation failed: "} + describe(st), json);
  }
  plant::InsensitivityWidth width;
  const bool want_width = args.flag("--sensitivity");
  if (want_width) {
    const plant::Mode& f = plant.fundamental();
    const double designed = needs_mode(req) ? req.omega() : f.omega;
    st = plant::insensitivity_width(cmd, designed, f.zeta, 5.0, width);
    if (st != plant::SimStatus::ok) {
      return report_failure("simulate", plant::to_string(st), std::string{"sensitivity sweep failed: "} + describe(st),
                            json);
    }
  }
  const OnlineChange* ch = change ? &*change : nullptr;
  const Json j = result_json(plant, move, req, res.metrics, want_width ? &width : nullptr, ch, unit);
  if (!all_finite(j)) {
    return report_bad_request({"non_finite_result", "--distance",
                               "--distance: the simulation's result is not finite for this move and plant"},
                              json);
  }
  if (const auto csv = args.text("--csv")) {
    if (papers::write_history_csv(res.history, *csv, plant.kind(), unit) != plant::SimStatus::ok) {
      return report_failure("simulate", "write_failed", "cannot write " + *csv, json);
    }
  }
  if (png) {
    if (const std::string why = write_png(plant, move, res, *png, unit); !why.empty()) {
      return report_failure("simulate", "figure_failed", why, json);
    }
  }
  if (json) {
    print_json(j);
  } else {
    print_text(plant, move, req, res.metrics, want_width ? &width : nullptr, ch, unit);
  }
  return kExitOk;
}

}  // namespace settle::app
