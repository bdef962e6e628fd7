#include "settle/sim/stream_check.hpp"

#include <cmath>

#include "settle/core/setpoints.hpp"

namespace settle::sim {

std::vector<std::int32_t> stream_setpoints(const core::Move<double>& move, std::uint32_t period_us,
                                           double counts_per_unit, std::int32_t origin) {
  std::vector<std::int32_t> out;
  core::SetpointStream<double> s{move, period_us, counts_per_unit, origin};
  for (bool last = false; !last;) out.push_back(s.next(last));
  return out;
}

SimStatus replay_stream(const DriveAxisConfig& cfg, const ModalPlant& plant, std::int32_t origin,
                        std::span<const std::int32_t> setpoints, std::size_t window, Replay& out) {
  if (setpoints.empty() || window == 0) return SimStatus::non_positive_step;
  DriveAxis axis{};
  SimStatus st = DriveAxis::make(cfg, plant, origin, axis);
  if (st != SimStatus::ok) return st;
  Replay r{};
  r.move_periods = setpoints.size();
  for (const std::int32_t sp : setpoints) {
    st = axis.step(sp);
    if (st != SimStatus::ok) return st;
    r.feedback.push_back(axis.feedback());
  }
  r.residual_state = axis.plant().residual_amplitude();
  r.load_after.push_back(axis.feedback().load_position);
  for (std::size_t i = 1; i < window; ++i) {
    st = axis.step(setpoints.back());
    if (st != SimStatus::ok) return st;
    r.feedback.push_back(axis.feedback());
    r.load_after.push_back(axis.feedback().load_position);
  }
  const double final_base = setpoints.back() / cfg.counts_per_unit;
  r.final_load = plant.rigid_gain() * final_base;
  r.step_residual = plant.step_residual((setpoints.back() - origin) / cfg.counts_per_unit);
  out = std::move(r);
  return SimStatus::ok;
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

SampledResidual sampled_residual(std::span<const std::int32_t> load_counts, double load_counts_per_unit,
                                 double final_load, double step_residual) noexcept {
  SampledResidual r{};
  for (const std::int32_t c : load_counts) {
    r.amplitude = std::fmax(r.amplitude, std::fabs(c / load_counts_per_unit - final_load));
  }
  r.samples = load_counts.size();
  r.prv_percent = step_residual > 0.0 ? 100.0 * r.amplitude / step_residual : 0.0;
  return r;
}

}  // namespace settle::sim
