// SPDX-License-Identifier: Apache-2.0
// A coordinated three-axis plan (issue 17, docs/multi_axis.md) against planning the same three axes
// alone, one after the other: what coordination costs. Path sync plans one path shaped for all
// three modes (one ZV per mode, or scurve's own design and two ZVs); time sync plans every axis
// twice (its shortest move, then stretched to the common duration). Measured, never asserted.
#include <benchmark/benchmark.h>

#include "settle/core/multi_axis.hpp"
#include "settle/core/planner.hpp"
#include "settle/core/profiles/registry.hpp"

using namespace settle::core;

namespace {

MultiAxisRequest three_axes(ProfileKind k, SyncMode sync) {
  MultiAxisRequest r{};
  r.base.profile = k;
  r.sync = sync;
  r.count = 3;
  const double d[3] = {0.1, 0.05, -0.2}, w[3] = {22.0, 30.0, 15.0}, z[3] = {0.0, 0.05, 0.1};
  const double a[3] = {20.0, 10.0, 40.0};
  for (std::size_t i = 0; i < 3; ++i) {
    r.axes[i].distance = d[i];
    r.axes[i].omega = w[i];
    r.axes[i].zeta = z[i];
    r.axes[i].limits.vmax = 1.0;
    r.axes[i].limits.amax = a[i];
    r.axes[i].limits.jmax = 800.0;
  }
  return r;
}

void BM_PlanThreeAxes(benchmark::State& state, ProfileKind k, SyncMode sync) {
  const MultiAxisRequest r = three_axes(k, sync);
  MultiAxisPlan p{};
  std::size_t culprit = 0;
  for (auto _ : state) {
    if (plan_axes(r, p, culprit) != Status::ok) state.SkipWithError("plan failed");
    benchmark::DoNotOptimize(p);
  }
}

// The same three axes planned alone, each for its own mode (the request's shaper: ZV).
void BM_PlanThreeSingleAxes(benchmark::State& state, ProfileKind k) {
  const MultiAxisRequest r = three_axes(k, SyncMode::time);
  MoveRequest q[3];
  for (std::size_t i = 0; i < 3; ++i) {
    q[i] = r.base;
    q[i].shaper = k == ProfileKind::jerk_limited ? ShaperKind::zv : ShaperKind::none;
    q[i].distance = r.axes[i].distance;
    q[i].limits = r.axes[i].limits;
    q[i].mode_count = 0;
    if (r.axes[i].omega) q[i].set_mode(*r.axes[i].omega, r.axes[i].zeta);
  }
  Move<double> m[3];
  for (auto _ : state) {
    for (std::size_t i = 0; i < 3; ++i) {
      if (plan(q[i], m[i]) != Status::ok) state.SkipWithError("plan failed");
    }
    benchmark::DoNotOptimize(m);
  }
}

void BM_PlanThreeAxesTimeZv(benchmark::State& state) {
  MultiAxisRequest r = three_axes(ProfileKind::jerk_limited, SyncMode::time);
  r.base.shaper = ShaperKind::zv;
  MultiAxisPlan p{};
  std::size_t culprit = 0;
  for (auto _ : state) {
    if (plan_axes(r, p, culprit) != Status::ok) state.SkipWithError("plan failed");
    benchmark::DoNotOptimize(p);
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_PlanThreeAxes, jerk_limited_path, ProfileKind::jerk_limited, SyncMode::path);
BENCHMARK_CAPTURE(BM_PlanThreeAxes, scurve_path, ProfileKind::scurve, SyncMode::path);
BENCHMARK_CAPTURE(BM_PlanThreeAxes, scurve_time, ProfileKind::scurve, SyncMode::time);
BENCHMARK(BM_PlanThreeAxesTimeZv);
BENCHMARK_CAPTURE(BM_PlanThreeSingleAxes, jerk_limited_zv, ProfileKind::jerk_limited);
BENCHMARK_CAPTURE(BM_PlanThreeSingleAxes, scurve, ProfileKind::scurve);
