// SPDX-License-Identifier: Apache-2.0
// Metrics as the literature defines them, checked on cases with closed forms: an unshaped step
// leaves 100 % PRV, a ZV-shaped step leaves |cos(pi r / 2)| on an undamped mode, the settling time
// of a damped step response, and the shape of the recorded history.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "rk4.hpp"
#include "settle/core/planner.hpp"
#include "settle/plant/sensitivity.hpp"
#include "settle/plant/simulate.hpp"

namespace settle::plant {
namespace {

ModalPlant one_mode(double omega, double zeta) {
  Mode m;
  m.omega = omega;
  m.zeta = zeta;
  ModalPlant p;
  EXPECT_EQ(ModalPlant::make_modes({m}, 1.0, PlantKind::modes, p), SimStatus::ok);
  return p;
}

TEST(Simulate, UnshapedStepLeavesOneHundredPercent) {
  const StepsCommand step{0.5, core::Shaper<double>{}};
  for (double z : {0.0, 0.1, 0.5}) {
    double prv = 0.0;
    ASSERT_EQ(prv_on_mode(step, 7.0, z, prv), SimStatus::ok);
    EXPECT_NEAR(prv, 100.0, 1e-10) << z;
  }
}

TEST(Simulate, ZvShapedStepOnAnUndampedModeLeavesCosine) {
  core::Shaper<double> s;
  ASSERT_EQ(core::design_shaper(core::ShaperKind::zv, 10.0, 0.0, 0.05, s), core::Status::ok);
  const StepsCommand c{1.0, s};
  for (double r : {0.7, 0.95, 1.0, 1.1, 1.6}) {
    double prv = 0.0;
    ASSERT_EQ(prv_on_mode(c, 10.0 * r, 0.0, prv), SimStatus::ok);
    EXPECT_NEAR(prv, 100.0 * std::fabs(std::cos(M_PI * r / 2.0)), 1e-9) << r;
  }
}

TEST(Simulate, SettlingTimeOfADampedStepResponse) {
  const double w = 20.0, z = 0.05, d = 1.0;
  const ModalPlant p = one_mode(w, z);
  const StepsCommand step{d, core::Shaper<double>{}};
  SimOptions o;
  o.band = 0.1;
  SimResult r;
  ASSERT_EQ(simulate(p, step, o, r), SimStatus::ok);
  // Independent: q = D e^{-z w t}(cos wd t - (z w / wd) sin wd t); the last instant |q| > band,
  // found by a dense scan of the closed form.
  const double wd = w * std::sqrt(1.0 - z * z);
  double last = 0.0;
  for (double t = 0.0; t < 20.0; t += 1e-6) {
    const double q = d * std::exp(-z * w * t) * (std::cos(wd * t) - z * w / wd * std::sin(wd * t));
    if (std::fabs(q) > 0.1) last = t;
  }
  EXPECT_NEAR(r.metrics.settling_time, last, 2e-6);
}

TEST(Simulate, UndampedModeWithResidualNeverSettles) {
  const ModalPlant p = one_mode(20.0, 0.0);
  SimResult r;
  ASSERT_EQ(simulate(p, StepsCommand{1.0, core::Shaper<double>{}}, SimOptions{}, r), SimStatus::ok);
  EXPECT_TRUE(std::isinf(r.metrics.settling_time));
}

TEST(Simulate, HistoryAndMetricsOfASdofMove) {
  ModalPlant p;
  ASSERT_EQ(ModalPlant::make_sdof({}, p), SimStatus::ok);
  const double d = 0.2, tt = 0.3;
  core::MoveRequest rq;
  rq.profile = core::ProfileKind::poly345;
  rq.distance = d;
  rq.time = tt;
  core::Move<double> m;
  ASSERT_EQ(core::plan(rq, m), core::Status::ok);
  SimOptions o;
  o.tail = 0.2;
  SimResult r;
  ASSERT_EQ(simulate(p, MoveCommand{m}, o, r), SimStatus::ok);
  ASSERT_FALSE(r.history.empty());
  EXPECT_DOUBLE_EQ(r.history.front().t, 0.0);
  EXPECT_NEAR(r.history.back().t, 0.5, 1e-9);
  for (std::size_t i = 1; i < r.history.size(); ++i) ASSERT_GT(r.history[i].t, r.history[i - 1].t);

  // Independent: RK4 on m x'' = k (y - x) + c (y' - x') with the 3-4-5 base in closed form
  // (seed 001's m = 1, k = 800, c = 9), no exponentials, no Hermite pieces.
  const double mass = 1.0, k = 800.0, c = 9.0;
  auto y = [&](double t, int der) {
    const double s = std::min(t / tt, 1.0);
    if (der == 0) return d * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
    return d / tt * s * s * (30.0 - 60.0 * s + 30.0 * s * s);
  };
  double peak = 0.0;
  const auto end = test::rk4_observed(
      [&](double t, double x, double v) { return (k * (y(t, 0) - x) + c * (y(t, 1) - v)) / mass; }, tt, 300'000,
      [&](double t, double x, double) { peak = std::max(peak, std::fabs(x - y(t, 0))); });
  // The simulator's peak is over its 1e-4 s grid, RK4's over 1e-6 s: equal to (w dt)^2 / 8.
  EXPECT_NEAR(r.metrics.peak_deflection, peak, 2e-6 * peak);
  EXPECT_LE(r.metrics.peak_deflection, peak * (1.0 + 1e-9));
  // At T the base rests at D: E = 1/2 m x'^2 + 1/2 k (x - D)^2.
  const double q = end[0] - d, dq = end[1];
  const double energy = 0.5 * mass * dq * dq + 0.5 * k * q * q;
  EXPECT_NEAR(r.metrics.final_energy, energy, 1e-8 * energy);
  // Residual: the free response's amplitude from (q, q') at T. An unshaped step of D leaves the
  // amplitude of q(0+) = -D, q'(0+) = c D / m (the damper's impulse; x itself cannot jump).
  const double w = std::sqrt(k / mass), z = c / (2.0 * std::sqrt(k * mass)), wd = w * std::sqrt(1.0 - z * z);
  const double residual = std::hypot(q, (dq + z * w * q) / wd);
  const double step = std::hypot(-d, (c * d / mass - z * w * d) / wd);
  EXPECT_NEAR(r.metrics.residual_amplitude, residual, 1e-8 * residual);
  EXPECT_NEAR(r.metrics.step_residual, step, 1e-12 * step);
  EXPECT_NEAR(r.metrics.prv_percent, 100.0 * residual / step, 1e-8 * r.metrics.prv_percent);
}

TEST(Simulate, RejectsANonPositiveStep) {
  SimResult r;
  SimOptions o;
  o.dt = 0.0;
  EXPECT_EQ(simulate(one_mode(1.0, 0.0), StepsCommand{1.0, core::Shaper<double>{}}, o, r), SimStatus::non_positive_step);
}

}  // namespace
}  // namespace settle::plant
