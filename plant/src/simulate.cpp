// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace settle::plant {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTwoPi = 6.283185307179586476925286766559;

// Deviation of the deflection from rest, tau seconds after now, with the base held still.
double free_deflection(const ModalPlant& plant, double tau) {
  double acc = 0.0;
  for (std::size_t j = 0; j < plant.modes().size(); ++j) {
    const Mode& m = plant.modes()[j];
    const double wd = m.omega * std::sqrt(1.0 - m.zeta * m.zeta);
    const double q = plant.mode_q(j);
    const double s = (plant.mode_dq(j) + m.zeta * m.omega * q) / wd;
    acc += m.output * std::exp(-m.zeta * m.omega * tau) * (q * std::cos(wd * tau) + s * std::sin(wd * tau));
  }
  return acc;
}

double envelope(const ModalPlant& plant, double tau) {
  double acc = 0.0;
  for (std::size_t j = 0; j < plant.modes().size(); ++j) {
    const Mode& m = plant.modes()[j];
    acc += std::fabs(m.output) * plant.mode_residual(j) * std::exp(-m.zeta * m.omega * tau);
  }
  return acc;
}

}  // namespace

const char* to_string(Settling s) noexcept {
  switch (s) {
    case Settling::settled: return "settled";
    case Settling::undamped: return "undamped";
    case Settling::beyond_horizon: return "beyond_horizon";
  }
  return "unknown";
}

SimStatus command_grid(const Command& cmd, double dt, std::vector<double>& times, std::vector<char>* is_break) {
  if (!(dt > 0.0) || !std::isfinite(dt)) return SimStatus::non_positive_step;
  const double end = cmd.duration();
  if (!(end >= 0.0) || !std::isfinite(end)) return SimStatus::too_long;
  std::vector<double> bp;
  cmd.breakpoints(bp);
  // Checked in double, before the conversion and before the grid is allocated.
  const double points = std::floor(end / dt) + 1.0 + static_cast<double>(bp.size()) + 1.0;
  if (!(points <= static_cast<double>(kMaxSamples))) return SimStatus::too_many_samples;
  bp.push_back(end);
  std::sort(bp.begin(), bp.end());
  const auto n = static_cast<std::size_t>(std::floor(end / dt));
  // Merge the uniform points with the breakpoints. Points closer than a millionth of a step are
  // one point: a breakpoint wins over a grid point, and two breakpoints that differ only by
  // rounding are the same instant.
  const double tol = 1e-6 * dt;
  times.clear();
  times.reserve(n + bp.size() + 2);
  std::vector<char> flags;
  flags.reserve(n + bp.size() + 2);
  auto add = [&](double t, bool brk) {
    if (!times.empty() && t - times.back() <= tol) {
      if (brk) {
        times.back() = t;
        flags.back() = 1;
      }
      return;
    }
    times.push_back(t);
    flags.push_back(brk ? 1 : 0);
  };
  std::size_t k = 0, b = 0;
  while (k <= n || b < bp.size()) {
    const double tk = k <= n ? static_cast<double>(k) * dt : HUGE_VAL;
    const double tb = b < bp.size() ? bp[b] : HUGE_VAL;
    if (tb <= tk) {
      if (tb >= 0.0 && tb <= end) add(tb, true);
      ++b;
    } else {
      if (tk <= end) add(tk, false);
      ++k;
    }
  }
  if (is_break != nullptr) *is_break = std::move(flags);
  return SimStatus::ok;
}

SimStatus drive(ModalPlant& plant, const Command& cmd, double dt,
                const std::function<void(const ModalPlant&, const BaseState&)>& on_step) {
  std::vector<double> grid;
  std::vector<char> brk;
  const SimStatus gs = command_grid(cmd, dt, grid, &brk);
  if (gs != SimStatus::ok) return gs;
  plant.reset(0.0);
  BaseState s1{};
  for (std::size_t i = 0; i + 1 < grid.size(); ++i) {
    const double t0 = grid[i], t1 = grid[i + 1];
    const double h = t1 - t0;
    // Where the command is smooth its left and right values coincide: reuse the last sample.
    const BaseState s0 = (i == 0 || brk[i] != 0) ? cmd.at(t0) : s1;
    s1 = cmd.at_left(t1);
    const SimStatus st = plant.advance(h, BasePolynomial::quintic_hermite(s0, s1, h));
    if (st != SimStatus::ok) return st;
    if (on_step) on_step(plant, s1);
  }
  // The command rests from its end on: a last zero-length "step" applies any jump at the end
  // (a velocity step there is an impulse on the modes).
  plant.linear().jump_base(cmd.at(cmd.duration()));
  return SimStatus::ok;
}

FreeSettling free_settling_time(const ModalPlant& plant, double band) {
  if (!(envelope(plant, 0.0) > band)) return {Settling::settled, 0.0};
  double undamped = 0.0;
  double shortest_period = kInf;
  for (std::size_t j = 0; j < plant.modes().size(); ++j) {
    const Mode& m = plant.modes()[j];
    if (m.zeta == 0.0) undamped += std::fabs(m.output) * plant.mode_residual(j);
    shortest_period = std::min(shortest_period, kTwoPi / (m.omega * std::sqrt(1.0 - m.zeta * m.zeta)));
  }
  if (undamped > band) return {Settling::undamped, kInf};
  // The envelope decreases; past the horizon nothing is searched (a denormal damping ratio makes
  // the decay time overflow to infinity, and a search towards it would never end).
  if (!(envelope(plant, kMaxSettlingTime) <= band)) return {Settling::beyond_horizon, kInf};
  // tau_b: where the envelope falls below the band; the last excursion is before that.
  double lo = 0.0, hi = kMaxSettlingTime;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (envelope(plant, mid) > band ? lo : hi) = mid;
  }
  const double tau_b = hi;
  // Scan the exact free response backwards from tau_b, at 1/64 of the shortest period, for the
  // last sample outside the band, and refine that crossing by bisection. The scan's work is
  // bounded: at most 4e6 samples, fewer for many modes (each sample costs one term per mode).
  const double max_samples =
      std::min(4e6, 6.4e7 / static_cast<double>(std::max<std::size_t>(plant.modes().size(), 1)));
  const double h = std::max(shortest_period / 64.0, tau_b / max_samples);
  const auto last_k = static_cast<std::size_t>(std::floor(tau_b / h));  // <= max_samples
  bool found = false;
  double last_out = 0.0;
  for (std::size_t k = last_k + 1; k-- > 0;) {
    const double tau = static_cast<double>(k) * h;
    if (std::fabs(free_deflection(plant, tau)) > band) {
      found = true;
      last_out = tau;
      break;
    }
  }
  if (!found) return {Settling::settled, 0.0};
  double a = last_out, b = last_out + h;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (a + b);
    (std::fabs(free_deflection(plant, mid)) > band ? a : b) = mid;
  }
  return {Settling::settled, b};
}

SimStatus simulate(const ModalPlant& plant_in, const Command& cmd, const SimOptions& opt, SimResult& out) {
  if (!(opt.dt > 0.0) || !std::isfinite(opt.dt)) return SimStatus::non_positive_step;
  if (plant_in.modes().empty()) return SimStatus::bad_mode_count;
  // Sizes first, in double, before any conversion or allocation (limits.hpp).
  const double duration = cmd.duration();
  if (!(duration >= 0.0) || !(duration <= kMaxSimulatedTime)) return SimStatus::too_long;
  double tail = 0.0;
  if (opt.record) {
    tail = opt.tail < 0.0 ? 3.0 * kTwoPi / plant_in.fundamental().omega : opt.tail;
    if (!(duration + tail <= kMaxSimulatedTime)) return SimStatus::too_long;  // also NaN
  }
  const double tail_steps = std::ceil(tail / opt.dt);
  if (!(duration / opt.dt + tail_steps <= static_cast<double>(kMaxSamples))) return SimStatus::too_many_samples;
  ModalPlant plant = plant_in;
  SimResult res;
  SimMetrics& m = res.metrics;
  m.move_end = cmd.duration();
  m.distance = cmd.final_position();
  m.step_residual = plant.step_residual(m.distance);
  m.band = opt.band >= 0.0 ? opt.band : 0.05 * m.step_residual;
  const double final_pos = plant.rigid_gain() * m.distance;
  // The settling time is the first grid instant after the last one spent outside the band.
  bool outside = false;
  double settle = 0.0;
  auto record = [&](const ModalPlant& p, const BaseState& c) {
    m.peak_deflection = std::max(m.peak_deflection, std::fabs(p.deflection()));
    if (std::fabs(p.position() - final_pos) > m.band) {
      outside = true;
    } else if (outside) {
      outside = false;
      settle = p.time();
    }
    if (opt.record) {
      res.history.push_back(
          {p.time(), c, p.deflection(), p.position(), p.velocity(), p.acceleration(), p.energy()});
    }
  };
  if (opt.record) {
    // Grid points (multiples of dt plus a few breakpoints) and tail steps: allocated once, here.
    res.history.reserve(static_cast<std::size_t>(duration / opt.dt + tail_steps) + 64);
  }
  plant.reset(0.0);
  record(plant, BaseState{});
  SimStatus st = drive(plant, cmd, opt.dt, record);
  if (st != SimStatus::ok) return st;
  if (!plant.linear().state().allFinite() || !std::isfinite(plant.position())) return SimStatus::non_finite_result;

  m.residual_amplitude = plant.residual_amplitude();
  m.prv_percent = m.step_residual > 0.0 ? 100.0 * m.residual_amplitude / m.step_residual : 0.0;
  for (std::size_t j = 0; j < plant.modes().size(); ++j) {
    const double r = plant.mode_residual(j);
    const double s = plant.mode_step_residual(j, m.distance);
    m.mode_residual.push_back(r);
    m.mode_prv_percent.push_back(s > 0.0 ? 100.0 * r / s : 0.0);
  }
  const Energy e = plant.energy();
  m.final_energy = e.kinetic + e.potential;

  // Settling: within the move from the grid, after it from the closed-form free response.
  const FreeSettling free = free_settling_time(plant, m.band);
  m.settling = free.status;
  if (free.status != Settling::settled) {
    m.settling_time = kInf;
  } else {
    m.settling_time = free.time > 0.0 ? m.move_end + free.time : (outside ? m.move_end : settle);
  }

  if (opt.record) {
    const auto steps = static_cast<std::size_t>(tail_steps);
    const BasePolynomial rest = BasePolynomial::constant(plant.base().p);
    for (std::size_t k = 0; k < steps; ++k) {
      st = plant.advance(opt.dt, rest);
      if (st != SimStatus::ok) return st;
      res.history.push_back({plant.time(), plant.base(), plant.deflection(), plant.position(), plant.velocity(),
                             plant.acceleration(), plant.energy()});
    }
  }
  out = std::move(res);
  return SimStatus::ok;
}

}  // namespace settle::plant
