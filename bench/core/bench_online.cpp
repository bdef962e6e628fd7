// SPDX-License-Identifier: Apache-2.0
// The cost of planning an online change (issue 17): a halt or a retarget of a running move, from
// its state at a tick: the mode memory of the running move plus the blend's search (its memory at
// its end taken once per move, as the servo loop takes it at submit: online_setup.hpp). The target is
// <= 20 us on the host, so that a halt asked for in one 1 kHz tick is ready for the next.
#include <benchmark/benchmark.h>

#include "online_setup.hpp"

using namespace settle::core;
using settle::bench::online_setup;

namespace {

// Cycles over 16 switch times spread across the move (online_setup.hpp).
void BM_PlanOnline(benchmark::State& state, ProfileKind k, std::size_t modes, bool retarget) {
  const settle::bench::OnlineSetup s = online_setup(k);
  std::size_t i = 0;
  for (auto _ : state) {
    OnlinePlan p{};  // the whole choice (a halt may finish the move instead of blending)
    const Status st = settle::bench::plan_online_change(s, modes, retarget, i++, p);
    if (st != Status::ok) state.SkipWithError(to_string(st));
    benchmark::DoNotOptimize(p);
  }
}

// The mode memory alone (the part that reads the running move).
void BM_ModeMemory(benchmark::State& state, ProfileKind k) {
  const settle::bench::OnlineSetup s = online_setup(k);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(mode_memory(s.move, settle::bench::online_switch_time(s, i++), s.modes[0]));
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
