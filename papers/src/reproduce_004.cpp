// SPDX-License-Identifier: Apache-2.0
#include <algorithm>
#include <chrono>
#include <cmath>

#include "settle/papers/reproduce.hpp"

namespace settle::papers {

namespace {

constexpr double kPi = 3.14159265358979323846;

core::Status plan_pseudo(const commission::EnergyTarget& t, const std::vector<double>& g, core::Move<double>& mv) {
  core::MoveRequest rq;
  rq.profile = core::ProfileKind::pseudopoly;
  rq.distance = t.distance;
  rq.time = t.duration;
  rq.gamma_count = g.size();
  for (std::size_t i = 0; i < g.size() && i < core::kMaxGammas; ++i) rq.gammas[i] = g[i];
  return core::plan(rq, mv);
}

}  // namespace

plant::SimStatus reproduce_004(const Options004& o, Result004& out) {
  const plant::BeltParams bp{};
  plant::ModalPlant plant;
  plant::SimStatus st = plant::ModalPlant::make_belt(bp, plant);
  if (st != plant::SimStatus::ok) return st;
  Result004 res;
  res.target = commission::belt_energy_target(bp, 15.0 * 2.0 * kPi, 1.0);  // 15 motor revolutions in 1 s
  res.h_scale = commission::energy_scale(res.target);
  const std::vector<double> g345{3.0, 4.0, 5.0};
  const std::vector<double> paper{kPaperGammas004.begin(), kPaperGammas004.end()};
  if ((st = commission::energy_integrals(res.target, g345, res.initial)) != plant::SimStatus::ok) return st;
  if ((st = commission::energy_integrals(res.target, paper, res.paper)) != plant::SimStatus::ok) return st;

  const auto t0 = std::chrono::steady_clock::now();
  st = commission::optimise_exponents(res.target, g345, commission::OptimiserOptions{}, res.optimiser);
  const auto t1 = std::chrono::steady_clock::now();
  if (st != plant::SimStatus::ok) return st;
  res.optimiser_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  if ((st = commission::energy_integrals(res.target, res.optimiser.gammas, res.optimised)) != plant::SimStatus::ok) return st;

  core::Move<double> m345, mopt;
  if (plan_pseudo(res.target, g345, m345) != core::Status::ok ||
      plan_pseudo(res.target, res.optimiser.gammas, mopt) != core::Status::ok) {
    return plant::SimStatus::plan_failed;
  }
  // Boundary conditions of the optimised command, relative to Phi, Phi/T, Phi/T^2.
  {
    const plant::MoveCommand c{mopt};
    const double d = res.target.distance, tt = res.target.duration;
    const plant::BaseState s0 = c.at(0.0), s1 = c.at_left(tt);
    res.boundary_error = std::max({std::fabs(s0.p) / d, std::fabs(s0.v) * tt / d, std::fabs(s0.a) * tt * tt / d,
                                   std::fabs(s1.p - d) / d, std::fabs(s1.v) * tt / d, std::fabs(s1.a) * tt * tt / d});
  }

  // The same energies from the time-stepped plant: E(T) / h must agree with the quadrature.
  plant::SimOptions so;
  so.dt = o.dt;
  so.record = o.history;
  so.tail = 0.5;
  plant::SimResult r345, ropt;
  if ((st = plant::simulate(plant, plant::MoveCommand{m345}, so, r345)) != plant::SimStatus::ok) return st;
  if ((st = plant::simulate(plant, plant::MoveCommand{mopt}, so, ropt)) != plant::SimStatus::ok) return st;
  res.h_simulated_initial = r345.metrics.final_energy / res.h_scale;
  res.h_simulated_optimised = ropt.metrics.final_energy / res.h_scale;
  res.prv_initial = r345.metrics.prv_percent;
  res.prv_optimised = ropt.metrics.prv_percent;
  res.history_initial = std::move(r345.history);
  res.history_optimised = std::move(ropt.history);

  if (o.exponents) {
    // What more exponents buy. Every zero-energy solution still leaves a residual that grows
    // linearly with a frequency error; the slope is what the extra exponents can lower. From a few
    // starting points each, keep the zero-energy result (H <= 1e-6 H(3,4,5)) with the least slope.
    const double threshold = 0.1 * res.prv_initial;
    for (std::size_t n = 3; n <= 6; ++n) {
      Exponents004 best;
      best.count = n;
      best.slope = HUGE_VAL;
      for (double step : {1.0, 0.5, 1.5, 2.0}) {
        for (double first : {3.0, 4.0, 5.0, 6.0}) {
          std::vector<double> start;
          for (std::size_t i = 0; i < n; ++i) start.push_back(first + step * static_cast<double>(i));
          commission::OptimiserResult r;
          commission::OptimiserOptions oo;
          oo.retry = false;  // the starts here already span what a retry would try
          if (commission::optimise_exponents(res.target, start, oo, r) != plant::SimStatus::ok) continue;
          if (r.h_final <= 1e-6 * res.initial.h_index && r.slope < best.slope) {
            best.gammas = r.gammas;
            best.h_index = r.h_final;
            best.slope = r.slope;
          }
        }
      }
      if (best.gammas.empty()) continue;
      core::Move<double> mv;
      if (plan_pseudo(res.target, best.gammas, mv) != core::Status::ok) return plant::SimStatus::plan_failed;
      st = plant::insensitivity_width(plant::MoveCommand{mv}, res.target.omega, res.target.zeta, threshold, best.width);
      if (st != plant::SimStatus::ok) return st;
      res.exponents.push_back(std::move(best));
    }
  }
  out = std::move(res);
  return plant::SimStatus::ok;
}

}  // namespace settle::papers
