// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/stream_check.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "settle/core/setpoints.hpp"

namespace settle::testbed {

plant::SimStatus stream_setpoints(const core::Move<double>& move, const core::AxisScale& scale, std::int32_t origin,
                           std::vector<std::int32_t>& out) {
  if (scale.period_us == 0) return plant::SimStatus::non_positive_step;
  if (!scale.valid()) return plant::SimStatus::non_positive_scale;
  // Ticks 0 .. stream_ticks (which saturates above core's own bound, and for a NaN duration).
  const std::int64_t ticks = core::stream_ticks(move, scale.period_us);
  if (ticks < 0 || static_cast<std::uint64_t>(ticks) >= plant::kMaxSamples) return plant::SimStatus::too_many_samples;
  std::vector<std::int32_t> sp;
  sp.reserve(static_cast<std::size_t>(ticks) + 1);
  core::SetpointStream<double> s{move, scale, origin};
  for (bool last = false; !last && sp.size() <= static_cast<std::size_t>(ticks);) sp.push_back(s.next(last));
  out = std::move(sp);
  return plant::SimStatus::ok;
}

plant::SimStatus replay_stream(const DriveAxisConfig& cfg, const plant::ModalPlant& plant, std::int32_t origin,
                        std::span<const std::int32_t> setpoints, std::size_t window, Replay& out) {
  if (setpoints.empty() || window == 0) return plant::SimStatus::non_positive_step;
  if (setpoints.size() > plant::kMaxSamples || window > plant::kMaxSamples - setpoints.size()) return plant::SimStatus::too_many_samples;
  DriveAxis axis{};
  plant::SimStatus st = DriveAxis::make(cfg, plant, origin, axis);
  if (st != plant::SimStatus::ok) return st;
  Replay r{};
  r.move_periods = setpoints.size();
  r.feedback.reserve(setpoints.size() + window);
  r.load_after.reserve(window);
  for (const std::int32_t sp : setpoints) {
    st = axis.step(sp);
    if (st != plant::SimStatus::ok) return st;
    r.feedback.push_back(axis.feedback());
  }
  r.load_after.push_back(axis.feedback().load_position);
  for (std::size_t i = 1; i < window; ++i) {
    st = axis.step(setpoints.back());
    if (st != plant::SimStatus::ok) return st;
    r.feedback.push_back(axis.feedback());
    r.load_after.push_back(axis.feedback().load_position);
  }
  const double final_base = setpoints.back() / cfg.scale.counts_per_unit;
  r.final_load = plant.rigid_gain() * final_base;
  r.step_residual = plant.step_residual((setpoints.back() - origin) / cfg.scale.counts_per_unit);
  out = std::move(r);
  return plant::SimStatus::ok;
}

std::optional<std::size_t> align_feedback(std::span<const std::int32_t> measured_positions,
                                          const Replay& replay) noexcept {
  const std::size_t n = replay.feedback.size();
  if (n == 0 || measured_positions.size() < n) return std::nullopt;
  for (std::size_t o = 0; o + n <= measured_positions.size(); ++o) {
    std::size_t i = 0;
    while (i < n && measured_positions[o + i] == replay.feedback[i].position_actual) ++i;
    if (i == n) return o;
  }
  return std::nullopt;
}

plant::SimStatus fitted_residual(std::span<const std::int32_t> load_counts, double load_counts_per_unit, double final_load,
                          double dt, const plant::ModalPlant& plant, double step_residual, SampledResidual& out) {
  SampledResidual r{};
  r.samples = load_counts.size();
  std::vector<const plant::Mode*> modes;
  for (const plant::Mode& m : plant.modes()) {
    if (m.omega * std::sqrt(1.0 - m.zeta * m.zeta) * dt < 3.14159265358979323846 * 0.95) modes.push_back(&m);
  }
  if (!modes.empty() && load_counts.size() > plant::kMaxFitEntries / (2 * modes.size())) return plant::SimStatus::too_many_samples;
  const auto n = static_cast<Eigen::Index>(load_counts.size());
  const auto k = static_cast<Eigen::Index>(2 * modes.size());
  if (n < k + 1 || k == 0) {
    out = r;
    return plant::SimStatus::ok;
  }
  Eigen::MatrixXd basis(n, k);
  Eigen::VectorXd e(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    e(i) = load_counts[static_cast<std::size_t>(i)] / load_counts_per_unit - final_load;
    for (std::size_t j = 0; j < modes.size(); ++j) {
      const double wd = modes[j]->omega * std::sqrt(1.0 - modes[j]->zeta * modes[j]->zeta);
      const double env = std::exp(-modes[j]->zeta * modes[j]->omega * t);
      basis(i, static_cast<Eigen::Index>(2 * j)) = env * std::cos(wd * t);
      basis(i, static_cast<Eigen::Index>(2 * j + 1)) = env * std::sin(wd * t);
    }
  }
  const Eigen::VectorXd c = basis.colPivHouseholderQr().solve(e);
  for (std::size_t j = 0; j < modes.size(); ++j) {
    r.amplitude += std::hypot(c(static_cast<Eigen::Index>(2 * j)), c(static_cast<Eigen::Index>(2 * j + 1)));
  }
  r.fit_rms = std::sqrt((basis * c - e).squaredNorm() / static_cast<double>(n));
  r.prv_percent = step_residual > 0.0 ? 100.0 * r.amplitude / step_residual : 0.0;
  out = r;
  return plant::SimStatus::ok;
}

}  // namespace settle::testbed
