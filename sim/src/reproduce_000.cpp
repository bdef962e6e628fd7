#include <cmath>

#include "settle/sim/reproduce.hpp"

namespace settle::sim {

SimStatus reproduce_000(const Options000& o, Result000& out) {
  ModalPlant beam;
  SimStatus st = ModalPlant::make_beam(BeamOptions{}, beam);
  if (st != SimStatus::ok) return st;
  Result000 res;
  st = beam_modes(BeamParams{}, 3, res.modes);
  if (st != SimStatus::ok) return st;
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
          rq.vmax = kVmax000;
          rq.omega = w1;
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
        const MoveCommand cmd{mv};
        SimOptions so;
        so.dt = o.dt;
        so.record = o.history;
        // Every history ends at the same instant, two periods after the longest move.
        so.tail = (kTimeRatios000.back() + 2.0) * res.period - row.time;
        SimResult sr;
        st = simulate(beam, cmd, so, sr);
        if (st != SimStatus::ok) return st;
        row.prv_mode1 = sr.metrics.mode_prv_percent[0];
        row.prv_tip = sr.metrics.prv_percent;
        row.residual_tip = sr.metrics.residual_amplitude;
        row.peak_deflection = sr.metrics.peak_deflection;
        row.history = std::move(sr.history);
        if (o.widths) {
          st = insensitivity_width(cmd, w1, 0.0, 5.0, row.width);
          if (st != SimStatus::ok) return st;
        }
        run.rows.push_back(std::move(row));
      }
    }
    res.runs.push_back(std::move(run));
  }
  out = std::move(res);
  return SimStatus::ok;
}

}  // namespace settle::sim
