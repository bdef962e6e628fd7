// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/drive_axis.hpp"

#include <cmath>
#include <random>

namespace settle::testbed {

namespace {

std::int32_t to_counts(double units, double per_unit) {
  return static_cast<std::int32_t>(std::llround(units * per_unit));
}

}  // namespace

plant::SimStatus DriveAxis::make(const DriveAxisConfig& cfg, const plant::ModalPlant& plant, std::int32_t start_counts,
                          DriveAxis& out) {
  if (cfg.scale.period_us == 0) return plant::SimStatus::non_positive_step;
  if (!cfg.scale.valid() || !(cfg.load_counts_per_unit > 0.0) || !std::isfinite(cfg.load_counts_per_unit)) {
    return plant::SimStatus::non_positive_scale;
  }
  DriveAxis a{};
  a.cfg_ = cfg;
  a.plant_ = plant;
  if (!(cfg.load_noise_counts >= 0.0) || !std::isfinite(cfg.load_noise_counts)) return plant::SimStatus::non_finite_parameter;
  a.noise_rng_.seed(cfg.noise_seed);
  const double x0 = start_counts / cfg.scale.counts_per_unit;
  a.plant_.reset(x0);
  a.x_prev_ = a.x_prev2_ = x0;
  if (cfg.model.servo) {
    // A PD position loop with velocity feed-forward, x'' = w^2 (r - x) + 2 z w (r' - x'), is the
    // seed-001 spring-damper with m = 1, k = w^2, c = 2 z w: reuse that plant, exactly integrated.
    const double w = 2.0 * 3.14159265358979323846 * cfg.model.bandwidth_hz;
    if (!(w > 0.0) || !(cfg.model.damping > 0.0) || !(cfg.model.damping < 1.0)) return plant::SimStatus::bad_drive_model;
    const plant::SimStatus st = plant::ModalPlant::make_sdof(plant::SdofParams{1.0, w * w, 2.0 * cfg.model.damping * w}, a.servo_);
    if (st != plant::SimStatus::ok) return st;
    a.servo_.reset(x0);
  }
  a.update_feedback();
  out = std::move(a);
  return plant::SimStatus::ok;
}

plant::SimStatus DriveAxis::step(std::int32_t target_counts) { return advance_to(target_counts / cfg_.scale.counts_per_unit); }

plant::SimStatus DriveAxis::hold() { return advance_to(x_prev_); }

plant::SimStatus DriveAxis::advance_to(double x_new) {
  const double dt = cfg_.scale.period_s();
  plant::BasePolynomial ref{};
  if (cfg_.interpolation == Interpolation::cubic) {
    // Velocities from the setpoints themselves (backward differences), so the reference is C1
    // and uses only what the drive has already received.
    const double v0 = (x_prev_ - x_prev2_) / dt;
    const double v1 = (x_new - x_prev_) / dt;
    ref = plant::BasePolynomial::cubic_hermite(x_prev_, v0, x_new, v1, dt);
  } else {
    ref = plant::BasePolynomial::linear(x_prev_, x_new, dt);
  }
  x_prev2_ = x_prev_;
  x_prev_ = x_new;
  if (!cfg_.model.servo) {
    const plant::SimStatus st = plant_.advance(dt, ref);
    update_feedback();
    return st;
  }
  // The loop's output is not a polynomial; the machine follows its exact end states through a
  // quintic Hermite (error O(dt^6)), which keeps the mechanical integration exact per period.
  const plant::BaseState s0{servo_.position(), servo_.velocity(), servo_.acceleration()};
  plant::SimStatus st = servo_.advance(dt, ref);
  if (st != plant::SimStatus::ok) return st;
  const plant::BaseState s1{servo_.position(), servo_.velocity(), servo_.acceleration()};
  st = plant_.advance(dt, plant::BasePolynomial::quintic_hermite(s0, s1, dt));
  update_feedback();
  return st;
}

void DriveAxis::update_feedback() {
  const plant::BaseState& b = plant_.base();
  fb_.position_actual = to_counts(b.p, cfg_.scale.counts_per_unit);
  fb_.velocity_actual = to_counts(b.v, cfg_.scale.counts_per_unit);
  double load = plant_.position();
  if (cfg_.load_noise_counts > 0.0) {
    load += std::normal_distribution<double>{0.0, cfg_.load_noise_counts}(noise_rng_) / cfg_.load_counts_per_unit;
  }
  fb_.load_position = to_counts(load, cfg_.load_counts_per_unit);
}

}  // namespace settle::testbed
