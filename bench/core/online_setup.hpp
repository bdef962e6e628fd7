// SPDX-License-Identifier: Apache-2.0
#pragma once
// The online changes the core benchmarks plan (bench_online.cpp) and settle_online_plan_instructions
// counts: a halt or a retarget of the seed-000 beam's move (scurve designed for 22.05 rad/s) or of a
// jerk-limited move with a ZVD shaper, limits a little above the move's own peaks, at 16 switch
// times spread across the move, so that every kind of state is planned.
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>

#include "bench_request.hpp"
#include "settle/core/online.hpp"
#include "settle/core/planner.hpp"

namespace settle::bench {

struct OnlineSetup {
  core::Move<double> move{};
  std::array<core::Mode, 2> modes{};
  core::OnlineLimits limits{};
  // Each mode's memory at the move's end, taken once per move as the servo loop takes it at submit
  // (core::end_memory): a request with the first mode alone reads its first entry.
  core::EndMemory end{};
};

inline OnlineSetup online_setup(core::ProfileKind k) {
  const core::MoveRequest r =
      benchmark_request(k, k == core::ProfileKind::jerk_limited ? core::ShaperKind::zvd : core::ShaperKind::none);
  OnlineSetup s{};
  if (core::plan(r, s.move) != core::Status::ok) return s;
  s.modes = {core::Mode{r.omega(), r.zeta()}, core::Mode{3.0 * r.omega(), 0.02}};
  const core::Peaks<double>& pk = s.move.peaks();
  s.limits = {1.2 * pk.v, 1.2 * pk.a, std::isfinite(pk.j) ? 1.2 * pk.j : 100.0};
  if (core::end_memory(s.move, s.modes.data(), s.modes.size(), s.end) != core::Status::ok) return {};
  return s;
}

// The i-th switch time (cycling over 16).
inline double online_switch_time(const OnlineSetup& s, std::size_t i) {
  return s.move.duration() * (0.03 + 0.06 * static_cast<double>(i % 16));
}

// The whole choice at the i-th switch time (plan_online(req, OnlinePlan&): a halt that finishes its
// move is a result, not an error), from the running move's state and mode memory at the switch
// (its memory at its end is the setup's).
inline core::Status plan_online_change(const OnlineSetup& s, std::size_t modes, bool retarget, std::size_t i,
                                       core::OnlinePlan& p) {
  core::OnlineRequest r{};
  const std::optional<double> target = retarget ? std::optional<double>{0.5 * s.move.distance()} : std::nullopt;
  core::Status st = core::online_request(s.move, s.end, online_switch_time(s, i), s.modes.data(), modes, s.limits,
                                              target, r);
  if (st == core::Status::ok) st = core::plan_online(r, p);
  return st;
}

}  // namespace settle::bench
