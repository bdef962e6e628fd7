#include "settle/sim/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace settle::sim {

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

void command_grid(const Command& cmd, double dt, std::vector<double>& times, std::vector<char>* is_break) {
  const double end = cmd.duration();
  std::vector<double> bp;
  cmd.breakpoints(bp);
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
}

SimStatus drive(ModalPlant& plant, const Command& cmd, double dt,
                const std::function<void(const ModalPlant&, const BaseState&)>& on_step) {
  if (!(dt > 0.0) || !std::isfinite(dt)) return SimStatus::non_positive_step;
  std::vector<double> grid;
  std::vector<char> brk;
  command_grid(cmd, dt, grid, &brk);
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

double free_settling_time(const ModalPlant& plant, double band) {
  if (envelope(plant, 0.0) <= band) return 0.0;
  double undamped = 0.0;
  double slowest_decay = kInf;
  double shortest_period = kInf;
  for (std::size_t j = 0; j < plant.modes().size(); ++j) {
    const Mode& m = plant.modes()[j];
    if (m.zeta == 0.0) undamped += std::fabs(m.output) * plant.mode_residual(j);
    if (m.zeta > 0.0) slowest_decay = std::min(slowest_decay, m.zeta * m.omega);
    shortest_period = std::min(shortest_period, kTwoPi / (m.omega * std::sqrt(1.0 - m.zeta * m.zeta)));
  }
  if (undamped > band) return kInf;
  // The envelope falls below the band by tau_b; the last excursion is before that. Scan the exact
  // free response at 1/64 of the shortest period and refine the last crossing by bisection.
  double lo = 0.0, hi = 1.0 / slowest_decay;
  while (envelope(plant, hi) > band) hi *= 2.0;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (envelope(plant, mid) > band ? lo : hi) = mid;
  }
  const double tau_b = hi;
  const double step = shortest_period / 64.0;
  constexpr double kMaxSamples = 4e6;
  const double h = std::max(step, tau_b / kMaxSamples);
  double last_out = -1.0;
  for (double tau = 0.0; tau <= tau_b; tau += h) {
    if (std::fabs(free_deflection(plant, tau)) > band) last_out = tau;
  }
  if (last_out < 0.0) return 0.0;
  double a = last_out, b = last_out + h;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (a + b);
    (std::fabs(free_deflection(plant, mid)) > band ? a : b) = mid;
  }
  return b;
}

SimStatus simulate(const ModalPlant& plant_in, const Command& cmd, const SimOptions& opt, SimResult& out) {
  if (!(opt.dt > 0.0) || !std::isfinite(opt.dt)) return SimStatus::non_positive_step;
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
  plant.reset(0.0);
  record(plant, BaseState{});
  SimStatus st = drive(plant, cmd, opt.dt, record);
  if (st != SimStatus::ok) return st;

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
  const double t_free = free_settling_time(plant, m.band);
  m.settling_time = t_free > 0.0 ? m.move_end + t_free : (outside ? m.move_end : settle);

  if (opt.record) {
    double tail = opt.tail;
    if (tail < 0.0) tail = 3.0 * kTwoPi / plant.fundamental().omega;
    const auto steps = static_cast<std::size_t>(std::ceil(tail / opt.dt));
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

}  // namespace settle::sim
