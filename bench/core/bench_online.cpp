// SPDX-License-Identifier: Apache-2.0
// The cost of planning an online change (issue 17): a halt or a retarget of a running move, from
// its state at a tick: the mode memory of the running move plus the blend's search. The target is
// <= 20 us on the host, so that a halt asked for in one 1 kHz tick is ready for the next.
#include <benchmark/benchmark.h>

#include <array>
#include <optional>

#include "bench_request.hpp"
#include "settle/core/online.hpp"
#include "settle/core/planner.hpp"

using namespace settle::core;

namespace {

struct Setup {
  Move<double> move{};
  std::array<Mode, 2> modes{};
  OnlineLimits limits{};
};

// The seed-000 beam's move (scurve designed for 22.05 rad/s) or a jerk-limited move with a ZVD
// shaper, limits a little above the move's own peaks.
Setup setup(ProfileKind k) {
  const MoveRequest r =
      settle::bench::benchmark_request(k, k == ProfileKind::jerk_limited ? ShaperKind::zvd : ShaperKind::none);
  Setup s{};
  if (plan(r, s.move) != Status::ok) return s;
  s.modes = {Mode{r.omega(), r.zeta()}, Mode{3.0 * r.omega(), 0.02}};
  const Peaks<double>& pk = s.move.peaks();
  s.limits = {1.2 * pk.v, 1.2 * pk.a, std::isfinite(pk.j) ? 1.2 * pk.j : 100.0};
  return s;
}

// Cycles over 16 switch times spread across the move, so that every kind of state is timed.
void BM_PlanOnline(benchmark::State& state, ProfileKind k, std::size_t modes, bool retarget) {
  const Setup s = setup(k);
  std::size_t i = 0;
  for (auto _ : state) {
    const double t = s.move.duration() * (0.03 + 0.06 * static_cast<double>(i++ % 16));
    OnlineRequest r{};
    const std::optional<double> target = retarget ? std::optional<double>{0.5 * s.move.distance()} : std::nullopt;
    Status st = online_request(s.move, t, s.modes.data(), modes, s.limits, target, r);
    OnlinePlan p{};  // the whole choice (a halt may finish the move instead of blending)
    if (st == Status::ok) st = plan_online(r, p);
    if (st != Status::ok) state.SkipWithError(to_string(st));
    benchmark::DoNotOptimize(p);
  }
}

// The mode memory alone (the part that reads the running move).
void BM_ModeMemory(benchmark::State& state, ProfileKind k) {
  const Setup s = setup(k);
  std::size_t i = 0;
  for (auto _ : state) {
    const double t = s.move.duration() * (0.03 + 0.06 * static_cast<double>(i++ % 16));
    benchmark::DoNotOptimize(mode_memory(s.move, t, s.modes[0]));
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_PlanOnline, halt_scurve_1mode, ProfileKind::scurve, 1, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanOnline, halt_scurve_2modes, ProfileKind::scurve, 2, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanOnline, halt_jerk_limited_zvd_1mode, ProfileKind::jerk_limited, 1, false)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanOnline, retarget_scurve_1mode, ProfileKind::scurve, 1, true)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModeMemory, scurve, ProfileKind::scurve)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModeMemory, jerk_limited_zvd, ProfileKind::jerk_limited)->Unit(benchmark::kMicrosecond);
