// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/sensitivity.hpp"

#include <algorithm>
#include <cmath>

#include "settle/plant/limits.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/plant/simulate.hpp"

namespace settle::plant {

SimStatus prv_on_mode(const Command& cmd, double omega, double zeta, double& prv_percent) {
  Mode m;
  m.omega = omega;
  m.zeta = zeta;
  ModalPlant plant;
  SimStatus st = ModalPlant::make_modes({m}, 1.0, PlantKind::modes, plant);
  if (st != SimStatus::ok) return st;
  // The grid only has to resolve the command (the plant is integrated exactly): 2000 pieces
  // over the move keep the quintic interpolation error far below any PRV worth printing.
  const double dt = std::max(cmd.duration(), 1e-9) / 2000.0;
  st = drive(plant, cmd, dt);
  if (st != SimStatus::ok) return st;
  const double step = plant.step_residual(cmd.final_position());
  prv_percent = step > 0.0 ? 100.0 * plant.residual_amplitude() / step : 0.0;
  return SimStatus::ok;
}

namespace {

template <typename F>
SimStatus sweep(F&& prv_at, double lo, double hi, std::size_t n, std::vector<SensitivityPoint>& out) {
  if (n < 2 || !(hi > lo) || !(lo > 0.0) || !std::isfinite(hi)) return SimStatus::bad_range;
  if (n > kMaxSweepPoints) return SimStatus::too_many_samples;
  std::vector<SensitivityPoint> pts;
  pts.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(n - 1);
    double prv = 0.0;
    const SimStatus st = prv_at(r, prv);
    if (st != SimStatus::ok) return st;
    pts.push_back({r, prv});
  }
  out = std::move(pts);
  return SimStatus::ok;
}

}  // namespace

SimStatus omega_sensitivity(const Command& cmd, double omega_design, double zeta_true, double lo, double hi,
                            std::size_t n, std::vector<SensitivityPoint>& out) {
  return sweep([&](double r, double& prv) { return prv_on_mode(cmd, r * omega_design, zeta_true, prv); }, lo, hi, n,
               out);
}

SimStatus zeta_sensitivity(const Command& cmd, double omega_true, double zeta_design, double lo, double hi,
                           std::size_t n, std::vector<SensitivityPoint>& out) {
  return sweep([&](double r, double& prv) { return prv_on_mode(cmd, omega_true, r * zeta_design, prv); }, lo, hi, n,
               out);
}

SimStatus insensitivity_width(const Command& cmd, double omega_design, double zeta_true, double threshold_percent,
                              InsensitivityWidth& out, double r_min, double r_max) {
  // The walks below take at most (r_max - r_min) / 0.005 steps, each a simulation: the range is
  // bounded (0.01 <= r_min < 1 < r_max <= 100).
  if (!(r_min >= 0.01) || !(r_min < 1.0) || !(r_max > 1.0) || !(r_max <= 100.0)) return SimStatus::bad_range;
  SimStatus st = SimStatus::ok;
  double last_prv = 0.0;
  auto over = [&](double r) {
    const SimStatus s = prv_on_mode(cmd, r * omega_design, zeta_true, last_prv);
    if (s != SimStatus::ok) {
      st = s;
      return true;  // a failed point ends the walk; the status is returned
    }
    // EI sits exactly on its tolerance at the nominal frequency: a relative slack keeps rounding
    // from deciding whether its nominal point counts.
    return last_prv > threshold_percent * (1.0 + 1e-9);
  };
  InsensitivityWidth w;
  if (over(1.0)) {
    if (st != SimStatus::ok) return st;
    out = w;
    return st;
  }
  // Walk out from 1 until the threshold is crossed, then bisect the crossing. Steps start at 0.005
  // and grow to 0.04 while PRV is far below the threshold: PRV curves are smooth on that scale,
  // and a flat profile would otherwise cost hundreds of simulations.
  auto edge = [&](double dir, double limit, bool& open) {
    double inside = 1.0;
    double step = 0.005;
    for (;;) {
      step = last_prv < 0.25 * threshold_percent ? std::min(2.0 * step, 0.04) : 0.005;
      const double r = inside + dir * step;
      if (dir > 0.0 ? r > limit : r < limit) {
        open = true;
        return limit;
      }
      if (over(r)) {
        double a = inside, b = r;
        for (int it = 0; it < 40; ++it) {
          const double m = 0.5 * (a + b);
          (over(m) ? b : a) = m;
        }
        return 0.5 * (a + b);
      }
      inside = r;
    }
  };
  w.hi = edge(+1.0, r_max, w.hi_open);
  if (st != SimStatus::ok) return st;
  over(1.0);  // the lower walk starts from the nominal's PRV again
  w.lo = edge(-1.0, r_min, w.lo_open);
  if (st != SimStatus::ok) return st;
  w.width = w.hi - w.lo;
  out = w;
  return st;
}

}  // namespace settle::plant
