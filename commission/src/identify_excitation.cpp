// SPDX-License-Identifier: Apache-2.0
#include "settle/commission/identify_excitation.hpp"

#include <array>
#include <cmath>

#include "settle/core/planner.hpp"

namespace settle::commission {

double train_gap(std::size_t k) noexcept {
  // Fractional parts of (k + 1) times the golden ratio: spread over [0, 1) without repeating.
  constexpr double kGolden = 0.6180339887498949;
  const double f = static_cast<double>(k + 1) * kGolden;
  return 0.25 + 0.5 * (f - std::floor(f));
}

std::size_t train_round_trips(const core::Move<double>& excitation) noexcept {
  return (excitation.shaper().count - 1) / 2;
}

core::Status plan_identify_excitation(const IdentifyExcitation& ex, core::Move<double>& out) {
  if (ex.round_trips > kMaxTrainRoundTrips) return core::Status::too_many_impulses;
  core::MoveRequest req{};
  req.profile = core::ProfileKind::jerk_limited;
  req.distance = ex.distance;
  req.limits = core::as_optional(ex.limits);
  core::Move<double> move{};
  if (const core::Status st = core::plan(req, move); st != core::Status::ok) return st;
  if (ex.round_trips == 0) {
    out = move;
    return core::Status::ok;
  }
  const std::size_t n = 2 * ex.round_trips + 1;
  std::array<double, core::kMaxImpulses> amp{};
  std::array<double, core::kMaxImpulses> time{};
  const double t_move = move.duration();
  double t = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    amp[k] = k % 2 == 0 ? 1.0 : -1.0;
    time[k] = t;
    t += t_move * (1.0 + train_gap(k));
  }
  core::Shaper<double> train{};
  if (const core::Status st = core::custom_shaper(amp.data(), time.data(), n, train); st != core::Status::ok) return st;
  out = core::Move<double>{move.profile(), train, core::shaped_peaks(move.profile(), train, move.peaks())};
  return core::Status::ok;
}

}  // namespace settle::commission
