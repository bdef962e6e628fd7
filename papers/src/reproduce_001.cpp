// SPDX-License-Identifier: Apache-2.0
#include <algorithm>
#include <cmath>
#include <memory>

#include "settle/papers/reproduce.hpp"

namespace settle::papers {

namespace {

const plant::SdofParams kSystem001{1.0, 800.0, 9.0};

core::Status plan_ramp_versine(double tau, double omega, double zeta, const std::array<double, 3>* y,
                               core::ShaperKind shaper, core::Move<double>& mv) {
  core::MoveRequest rq;
  rq.profile = core::ProfileKind::ramp_versine;
  rq.distance = 1.0;
  rq.time = tau;
  rq.set_mode(omega, zeta);
  if (y != nullptr) rq.y_fractions = *y;
  rq.shaper = shaper;
  return core::plan(rq, mv);
}

core::ShaperKind shaper_kind(const std::string& method) {
  return method == "zv" ? core::ShaperKind::zv : method == "zvd" ? core::ShaperKind::zvd : core::ShaperKind::ei;
}

// The commands of the robustness comparison, designed for (omega, zeta), unit distance, all for
// the move time tau: the proposed command, the ramp shaped by ZV/ZVD/EI, Sahinkaya's inverse
// dynamics (3-4-5 or cubic output in tau) and the hybrid (the proposed command shaped by ZV).
std::unique_ptr<plant::Command> design(const std::string& method, double tau, double omega, double zeta) {
  core::Move<double> mv;
  if (method == "proposed" || method == "hybrid") {
    const auto shaper = method == "hybrid" ? core::ShaperKind::zv : core::ShaperKind::none;
    if (plan_ramp_versine(tau, omega, zeta, nullptr, shaper, mv) != core::Status::ok) return nullptr;
    return std::make_unique<plant::MoveCommand>(mv);
  }
  if (method == "zv" || method == "zvd" || method == "ei") {
    if (plan_ramp_versine(tau, omega, zeta, &kRampY001, shaper_kind(method), mv) != core::Status::ok) return nullptr;
    return std::make_unique<plant::MoveCommand>(mv);
  }
  return std::make_unique<plant::InverseDynamicsCommand>(1.0, tau, omega, zeta, method == "sahinkaya-cubic" ? 3 : 5);
}

}  // namespace

plant::SimStatus referred_residual_001(const plant::Command& cmd, double dt, double t_ref, double& out) {
  // A residual relative to the distance needs a distance; a reference time has to be a time.
  if (!std::isfinite(t_ref) || !(std::fabs(cmd.final_position()) > 0.0)) return plant::SimStatus::bad_range;
  plant::ModalPlant p;
  plant::SimStatus st = plant::ModalPlant::make_sdof(kSystem001, p);
  if (st != plant::SimStatus::ok) return st;
  st = drive(p, cmd, dt);
  if (st != plant::SimStatus::ok) return st;
  // The free vibration of the true plant from the command's end on, extended to t_ref.
  const plant::Mode& m = p.modes()[0];
  const double r =
      p.residual_amplitude() * std::exp(m.zeta * m.omega * (cmd.duration() - t_ref)) / std::fabs(cmd.final_position());
  if (!std::isfinite(r)) return plant::SimStatus::non_finite_result;
  out = r;
  return plant::SimStatus::ok;
}

plant::SimStatus shaper_width(core::ShaperKind kind, double zeta, double threshold_percent, plant::InsensitivityWidth& out) {
  core::Shaper<double> sh;
  if (core::design_shaper(kind, 1.0, zeta, 0.05, sh) != core::Status::ok) return plant::SimStatus::plan_failed;
  return plant::insensitivity_width(plant::StepsCommand{1.0, sh}, 1.0, zeta, threshold_percent, out);
}

plant::SimStatus reproduce_001(const Options001& o, Result001& out) {
  plant::ModalPlant plant;
  plant::SimStatus st = plant::ModalPlant::make_sdof(kSystem001, plant);
  if (st != plant::SimStatus::ok) return st;
  Result001 res;
  res.omega = plant.modes()[0].omega;
  res.zeta = plant.modes()[0].zeta;

  plant::SimOptions so;
  so.dt = o.dt;
  so.record = o.history;
  so.tail = 0.5;
  for (double tau : kTaus001) {
    Case001 c;
    c.tau = tau;
    core::Move<double> arb, comp;
    if (plan_ramp_versine(tau, res.omega, res.zeta, &kArbitraryY001, core::ShaperKind::none, arb) != core::Status::ok ||
        plan_ramp_versine(tau, res.omega, res.zeta, nullptr, core::ShaperKind::none, comp) != core::Status::ok) {
      return plant::SimStatus::plan_failed;
    }
    const auto& rv = std::get<core::RampVersine<double>>(comp.profile().variant()).params();
    c.y_computed = {rv.y1, rv.y2, rv.y3};
    plant::SimResult ra, rc;
    st = plant::simulate(plant, plant::MoveCommand{arb}, so, ra);
    if (st == plant::SimStatus::ok) st = plant::simulate(plant, plant::MoveCommand{comp}, so, rc);
    if (st != plant::SimStatus::ok) return st;
    c.residual_arbitrary = ra.metrics.residual_amplitude;
    c.residual_computed = rc.metrics.residual_amplitude;
    c.history_arbitrary = std::move(ra.history);
    c.history_computed = std::move(rc.history);
    res.cases.push_back(std::move(c));
  }

  const double tau = kTaus001[0];
  const std::vector<std::string> methods{"proposed", "zv", "zvd", "ei", "sahinkaya", "sahinkaya-cubic", "hybrid"};
  if (o.grids) {
    const std::size_t n = std::max<std::size_t>(o.grid_points, 2);
    for (const std::string& m : methods) {
      Grid001 g;
      g.method = m;
      for (std::size_t i = 0; i < n; ++i) g.eps.push_back(-0.2 + 0.4 * static_cast<double>(i) / static_cast<double>(n - 1));
      for (double ew : g.eps) {
        for (double ez : g.eps) {
          const auto cmd = design(m, tau, res.omega * (1.0 + ew), res.zeta * (1.0 + ez));
          if (!cmd) return plant::SimStatus::plan_failed;
          double r = 0.0;
          st = referred_residual_001(*cmd, o.dt, res.residual_at, r);
          if (st != plant::SimStatus::ok) return st;
          g.residual.push_back(r);
          g.worst = std::max(g.worst, r);
        }
      }
      const auto nominal = design(m, tau, res.omega, res.zeta);
      if (!nominal) return plant::SimStatus::plan_failed;
      st = referred_residual_001(*nominal, o.dt, res.residual_at, g.nominal);
      if (st != plant::SimStatus::ok) return st;
      g.duration = nominal->duration();
      res.grids.push_back(std::move(g));
    }
  }

  // Widths in the frequency ratio at 5 %: the textbook shapers shaping a step on an undamped mode
  // (about 0.06, 0.29 and 0.40 for ZV, ZVD and EI).
  for (const char* m : {"zv", "zvd", "ei"}) {
    Width001 w;
    w.method = m;
    w.zeta = 0.0;
    st = shaper_width(shaper_kind(m), 0.0, 5.0, w.width);
    if (st != plant::SimStatus::ok) return st;
    res.widths.push_back(w);
  }
  out = std::move(res);
  return plant::SimStatus::ok;
}

}  // namespace settle::papers
