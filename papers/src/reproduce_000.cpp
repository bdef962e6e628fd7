// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <memory>

#include "settle/papers/reproduce.hpp"

namespace settle::papers {

namespace {

// The seven profiles of the comparison and every shaper, on the first beam mode (undamped), PRV against the
// frequency ratio from 0.5 to 2 and the 5 % width.
plant::SimStatus sensitivity_study(double w1, double tn, std::vector<Sensitivity000>& out) {
  const double d = 0.07, t = 2.0 * tn;
  // The paper's comparison set (its rows are this study's; a new registry profile is not added to it).
  const core::ProfileKind profiles[] = {core::ProfileKind::scurve,     core::ProfileKind::scurve_damped,
                                        core::ProfileKind::ramp_versine, core::ProfileKind::pseudopoly,
                                        core::ProfileKind::poly345,    core::ProfileKind::trapezoid,
                                        core::ProfileKind::jerk_limited};
  std::vector<std::pair<std::string, std::unique_ptr<plant::Command>>> cmds;
  for (const core::ProfileKind kind : profiles) {
    core::MoveRequest r;
    r.profile = kind;
    r.distance = d;
    r.time = t;
    r.set_mode(w1);
    if (kind == core::ProfileKind::pseudopoly) {
      // Seed 004's Table II pseudo-polynomial: not designed for any mode, a shape for comparison.
      r.gammas[0] = 4.5;
      r.gammas[1] = 6.2;
      r.gammas[2] = 8.4;
      r.gamma_count = 3;
    }
    if (kind == core::ProfileKind::jerk_limited) {
      // Limits loose enough for the stretch to T to be feasible: cruise at most 2 D/T.
      r.limits.vmax = 2.0 * d / t;
      r.limits.amax = 16.0 * d / (t * t);
      r.limits.jmax = 256.0 * d / (t * t * t);
    }
    core::Move<double> m;
    if (core::plan(r, m) != core::Status::ok) return plant::SimStatus::plan_failed;
    cmds.emplace_back(core::to_string(kind), std::make_unique<plant::MoveCommand>(m));
  }
  for (auto kind : {core::ShaperKind::zv, core::ShaperKind::zvd, core::ShaperKind::zvdd, core::ShaperKind::ei}) {
    core::Shaper<double> sh;
    if (core::design_shaper(kind, w1, 0.0, 0.05, sh) != core::Status::ok) return plant::SimStatus::plan_failed;
    cmds.emplace_back(std::string{"shaper:"} + core::to_string(kind), std::make_unique<plant::StepsCommand>(d, sh));
  }
  for (const auto& [name, cmd] : cmds) {
    Sensitivity000 s;
    s.name = name;
    s.duration = cmd->duration();
    plant::SimStatus st = plant::prv_on_mode(*cmd, w1, 0.0, s.prv_nominal);
    if (st == plant::SimStatus::ok) st = plant::insensitivity_width(*cmd, w1, 0.0, 5.0, s.width);
    if (st == plant::SimStatus::ok) st = plant::omega_sensitivity(*cmd, w1, 0.0, 0.5, 2.0, 151, s.curve);
    if (st != plant::SimStatus::ok) return st;
    out.push_back(std::move(s));
  }
  return plant::SimStatus::ok;
}

}  // namespace

plant::SimStatus reproduce_000(const Options000& o, Result000& out) {
  plant::ModalPlant beam;
  plant::SimStatus st = plant::ModalPlant::make_beam(plant::BeamOptions{}, beam);
  if (st != plant::SimStatus::ok) return st;
  Result000 res;
  st = plant::beam_modes(plant::BeamParams{}, 3, res.modes);
  if (st != plant::SimStatus::ok) return st;
  const double w1 = res.modes[0].omega;
  res.period = 6.283185307179586 / w1;

  for (double d : o.distances) {
    Run000 run;
    run.distance = d;
    for (double ratio : kTimeRatios000) {
      for (core::ProfileKind kind : {core::ProfileKind::scurve, core::ProfileKind::poly345}) {
        Row000 row;
        row.time_ratio = ratio;
        row.time = ratio * res.period;
        row.profile = kind;
        core::MoveRequest rq;
        rq.profile = kind;
        rq.distance = d;
        rq.time = row.time;
        if (kind == core::ProfileKind::scurve) {
          // Seed 000's planning rule: cruise at the actuator's limit when the time requires it.
          rq.limits.vmax = kVmax000;
          rq.set_mode(w1);
        }
        core::Move<double> mv;
        row.plan_status = core::plan(rq, mv);
        if (row.plan_status != core::Status::ok) {
          run.rows.push_back(std::move(row));
          continue;
        }
        if (const auto* rc = std::get_if<core::RampCycloid<double>>(&mv.profile().variant())) {
          row.cruise = rc->params().cruise;
        }
        row.peak_velocity = mv.peaks().v;
        row.peak_acceleration = mv.peaks().a;
        row.over_vmax = row.peak_velocity > kVmax000 * (1.0 + 1e-9);
        const plant::MoveCommand cmd{mv};
        plant::SimOptions so;
        so.dt = o.dt;
        so.record = o.history;
        // Every history ends at the same instant, two periods after the longest move.
        so.tail = (kTimeRatios000.back() + 2.0) * res.period - row.time;
        plant::SimResult sr;
        st = plant::simulate(beam, cmd, so, sr);
        if (st != plant::SimStatus::ok) return st;
        row.prv_mode1 = sr.metrics.mode_prv_percent[0];
        row.prv_tip = sr.metrics.prv_percent;
        row.residual_tip = sr.metrics.residual_amplitude;
        row.peak_deflection = sr.metrics.peak_deflection;
        row.history = std::move(sr.history);
        if (o.widths) {
          st = plant::insensitivity_width(cmd, w1, 0.0, 5.0, row.width);
          if (st != plant::SimStatus::ok) return st;
        }
        run.rows.push_back(std::move(row));
      }
    }
    res.runs.push_back(std::move(run));
  }
  if (o.sensitivity) {
    st = sensitivity_study(w1, res.period, res.sensitivity);
    if (st != plant::SimStatus::ok) return st;
  }
  out = std::move(res);
  return plant::SimStatus::ok;
}

}  // namespace settle::papers
