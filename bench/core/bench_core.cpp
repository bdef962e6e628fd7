// SPDX-License-Identifier: Apache-2.0
// Per-tick evaluation cost of every profile (double and float, shaped and not, random access
// and stepping) and the cost of planning. Measured, never asserted: see the issue notes.
#include <benchmark/benchmark.h>

#include <variant>
#include <vector>

#include "bench_request.hpp"
#include "settle/core/planner.hpp"
#include "settle/core/stepper.hpp"

using namespace settle::core;

namespace {

using settle::bench::benchmark_request;

Move<double> planned(ProfileKind k, ShaperKind s) {
  Move<double> m{};
  if (plan(benchmark_request(k, s), m) != Status::ok) std::abort();
  return m;
}

// 1 kHz ticks across the move, so every segment is visited as in a servo loop.
template <typename T>
std::vector<T> tick_times(const Move<T>& m) {
  std::vector<T> ts;
  for (T t = 0; t < m.duration(); t += T(1e-3)) ts.push_back(t);
  return ts;
}

template <typename T>
void BM_Evaluate(benchmark::State& state, ProfileKind k, ShaperKind s) {
  const Move<T> m{planned(k, s)};
  const std::vector<T> ts = tick_times(m);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(m.at(ts[i]));
    if (++i == ts.size()) i = 0;
  }
}

// The bare piecewise evaluator under a planned move (PiecewiseJerk<T>::at of its jerk-limited
// or trapezoid shape, no Move, no Profile dispatch), at the same ticks as BM_Evaluate: what
// Move::at and the stepper cost beyond the maths is their time over this one.
template <typename T>
void BM_EvaluateBare(benchmark::State& state, ProfileKind k) {
  const Move<T> m{planned(k, ShaperKind::none)};
  const auto* bare = std::get_if<PiecewiseJerk<T>>(&m.profile().variant());
  if (bare == nullptr) std::abort();
  const std::vector<T> ts = tick_times(m);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(bare->at(ts[i]));
    if (++i == ts.size()) i = 0;
  }
}

// Random access as a loop makes it: each tick's time waits for the tick before (t + 0 * p cannot
// be folded: p may be NaN), as a stepper's state does. BM_Evaluate's independent calls overlap in
// the out-of-order core; a servo loop's one call per period does not (docs/planning.md).
template <typename T>
void BM_EvaluateChained(benchmark::State& state, ProfileKind k, ShaperKind s) {
  const Move<T> m{planned(k, s)};
  const std::vector<T> ts = tick_times(m);
  std::size_t i = 0;
  T last{};
  for (auto _ : state) {
    last = m.at(ts[i] + T(0) * last).p;
    benchmark::DoNotOptimize(last);
    if (++i == ts.size()) i = 0;
  }
}

template <typename T>
void BM_Step(benchmark::State& state, ProfileKind k, ShaperKind s) {
  const Move<T> m{planned(k, s)};
  const auto ticks = static_cast<std::int64_t>(m.duration() / T(1e-3));
  MoveStepper<T> st{m, T(1e-3)};
  std::int64_t n = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(st.step());
    if (++n == ticks) {
      st = MoveStepper<T>{m, T(1e-3)};
      n = 0;
    }
  }
}

void BM_EvaluateDouble(benchmark::State& st, ProfileKind k, ShaperKind s) { BM_Evaluate<double>(st, k, s); }
void BM_EvaluateFloat(benchmark::State& st, ProfileKind k, ShaperKind s) { BM_Evaluate<float>(st, k, s); }
void BM_EvaluateChainedDouble(benchmark::State& st, ProfileKind k, ShaperKind s) { BM_EvaluateChained<double>(st, k, s); }
void BM_EvaluateChainedFloat(benchmark::State& st, ProfileKind k, ShaperKind s) { BM_EvaluateChained<float>(st, k, s); }
void BM_EvaluateBareDouble(benchmark::State& st, ProfileKind k) { BM_EvaluateBare<double>(st, k); }
void BM_EvaluateBareFloat(benchmark::State& st, ProfileKind k) { BM_EvaluateBare<float>(st, k); }
void BM_StepDouble(benchmark::State& st, ProfileKind k, ShaperKind s) { BM_Step<double>(st, k, s); }
void BM_StepFloat(benchmark::State& st, ProfileKind k, ShaperKind s) { BM_Step<float>(st, k, s); }

void BM_Plan(benchmark::State& state, ProfileKind k, ShaperKind s) {
  const MoveRequest r = benchmark_request(k, s);
  Move<double> m{};
  for (auto _ : state) benchmark::DoNotOptimize(plan(r, m));
}

// The jerk-limited planner's phase solver alone: what BM_Plan/jerk_limited costs beyond it is
// plan()'s own (validation, peaks, building the Move).
void BM_JerkLimitedPhases(benchmark::State& state) {
  const MoveRequest r = benchmark_request(ProfileKind::jerk_limited);
  for (auto _ : state) benchmark::DoNotOptimize(jerk_limited_time_optimal(r.distance, *r.limits.vmax, *r.limits.amax, *r.limits.jmax));
}

// The floor of any plan() that hands back the phase solver's table: the solver, then one copy of
// its table into the result, entry by entry as PiecewiseJerk takes it. Nothing else: no
// validation, no limit check, no evaluation knots, no Move (docs/planning.md compares the three).
void BM_JerkLimitedPhasesCopied(benchmark::State& state) {
  const MoveRequest r = benchmark_request(ProfileKind::jerk_limited);
  PiecewiseJerkParams out;
  for (auto _ : state) {
    PiecewiseJerkParams p;
    jerk_limited_time_optimal(r.distance, *r.limits.vmax, *r.limits.amax, *r.limits.jmax, p);
    out.distance = p.distance;
    out.count = p.count;
    for (std::size_t i = 0; i < kMaxJerkSegments; ++i) {
      if (i == p.count) break;
      out.durations[i] = p.durations[i];
      out.accel0[i] = p.accel0[i];
      out.jerk[i] = p.jerk[i];
    }
    benchmark::DoNotOptimize(&out);
    benchmark::ClobberMemory();
  }
}

// The joint ZV shaper (one design for n modes, n + 1 impulses): Newton's method from a fixed set
// of starts; the modes of BM_PlanFastest/two_modes and /three_modes.
void BM_JointZvShaper(benchmark::State& state, std::size_t n) {
  const double w2[] = {22.0, 60.0}, z2[] = {0.0, 0.01};
  const double w3[] = {5.0, 23.0, 71.0}, z3[] = {0.02, 0.05, 0.01};
  Shaper<double> s{};
  for (auto _ : state) {
    benchmark::DoNotOptimize(n == 2 ? joint_zv_shaper(w2, z2, 2, s) : joint_zv_shaper(w3, z3, 3, s));
  }
}

// The two- and three-hump EI designs (shaper.cpp): closed forms undamped; with damping Newton's
// method continued in zeta, what `fastest --robust` pays per mode for each (docs/fastest.md).
void BM_MultiHumpEi(benchmark::State& state, std::size_t humps, double zeta) {
  Shaper<double> s{};
  for (auto _ : state) benchmark::DoNotOptimize(multi_hump_ei_shaper(humps, 22.0, zeta, 0.05, s));
}

void BM_PlanFastestScurve(benchmark::State& state, bool damped) {
  RampCycloidParams p{};
  for (auto _ : state) {
    benchmark::DoNotOptimize(plan_fastest_scurve(0.1, 1.0, 20.0, 800.0, 22.04871, 0.05, damped, p));
  }
}

}  // namespace

#define SETTLE_EVAL(K, S)                                                                        \
  BENCHMARK_CAPTURE(BM_EvaluateDouble, K##_##S##_double, ProfileKind::K, ShaperKind::S);       \
  BENCHMARK_CAPTURE(BM_EvaluateFloat, K##_##S##_float, ProfileKind::K, ShaperKind::S)

SETTLE_EVAL(scurve, none);
SETTLE_EVAL(scurve_damped, none);
SETTLE_EVAL(ramp_versine, none);
SETTLE_EVAL(pseudopoly, none);
SETTLE_EVAL(poly345, none);
SETTLE_EVAL(trapezoid, none);
SETTLE_EVAL(jerk_limited, none);
SETTLE_EVAL(scurve, zv);
SETTLE_EVAL(jerk_limited, zvd);
BENCHMARK_CAPTURE(BM_EvaluateChainedDouble, jerk_limited_none_double, ProfileKind::jerk_limited, ShaperKind::none);
BENCHMARK_CAPTURE(BM_EvaluateChainedFloat, jerk_limited_none_float, ProfileKind::jerk_limited, ShaperKind::none);
// Side by side: the bare piecewise evaluator, Move::at (BM_Evaluate above) and the stepper of the
// same jerk-limited and trapezoid moves.
BENCHMARK_CAPTURE(BM_EvaluateBareDouble, jerk_limited_double, ProfileKind::jerk_limited);
BENCHMARK_CAPTURE(BM_EvaluateBareFloat, jerk_limited_float, ProfileKind::jerk_limited);
BENCHMARK_CAPTURE(BM_EvaluateBareDouble, trapezoid_double, ProfileKind::trapezoid);
BENCHMARK_CAPTURE(BM_EvaluateBareFloat, trapezoid_float, ProfileKind::trapezoid);
BENCHMARK_CAPTURE(BM_StepDouble, jerk_limited_none_double, ProfileKind::jerk_limited, ShaperKind::none);
BENCHMARK_CAPTURE(BM_StepFloat, jerk_limited_none_float, ProfileKind::jerk_limited, ShaperKind::none);
BENCHMARK_CAPTURE(BM_StepDouble, trapezoid_none_double, ProfileKind::trapezoid, ShaperKind::none);
BENCHMARK_CAPTURE(BM_StepFloat, trapezoid_none_float, ProfileKind::trapezoid, ShaperKind::none);
BENCHMARK_CAPTURE(BM_StepDouble, scurve_none_double, ProfileKind::scurve, ShaperKind::none);
BENCHMARK_CAPTURE(BM_StepFloat, scurve_none_float, ProfileKind::scurve, ShaperKind::none);
BENCHMARK_CAPTURE(BM_StepDouble, scurve_damped_none_double, ProfileKind::scurve_damped, ShaperKind::none);
BENCHMARK_CAPTURE(BM_StepDouble, scurve_zv_double, ProfileKind::scurve, ShaperKind::zv);
BENCHMARK_CAPTURE(BM_Plan, scurve, ProfileKind::scurve, ShaperKind::none);
BENCHMARK_CAPTURE(BM_Plan, scurve_damped, ProfileKind::scurve_damped, ShaperKind::none);
BENCHMARK_CAPTURE(BM_Plan, ramp_versine, ProfileKind::ramp_versine, ShaperKind::none);
BENCHMARK_CAPTURE(BM_Plan, poly345, ProfileKind::poly345, ShaperKind::none);
BENCHMARK_CAPTURE(BM_Plan, jerk_limited, ProfileKind::jerk_limited, ShaperKind::none);
BENCHMARK_CAPTURE(BM_Plan, jerk_limited_zvd, ProfileKind::jerk_limited, ShaperKind::zvd);
BENCHMARK(BM_JerkLimitedPhases);
BENCHMARK(BM_JerkLimitedPhasesCopied);
BENCHMARK_CAPTURE(BM_JointZvShaper, two_modes, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_JointZvShaper, three_modes, 3)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_MultiHumpEi, two_humps, 2, 0.0);
BENCHMARK_CAPTURE(BM_MultiHumpEi, two_humps_damped, 2, 0.1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_MultiHumpEi, three_humps_damped, 3, 0.1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanFastestScurve, undamped, false);
BENCHMARK_CAPTURE(BM_PlanFastestScurve, damped, true);

// Profile `fastest` (docs/fastest.md): planning the reference case (one mode, undamped
// and damped), two modes, --robust 10, the commissioning plant and three modes; and its per-tick
// cost once planned.
namespace {

MoveRequest fastest_request(int which) {
  MoveRequest r{};
  r.profile = ProfileKind::fastest;
  r.distance = 0.1;
  r.limits.vmax = 1.0;
  r.limits.amax = 20.0;
  r.limits.jmax = 800.0;
  r.set_mode(22.0, which == 1 ? 0.05 : 0.0);
  if (which == 2) {
    (void)r.add_mode({60.0, 0.01});
  }
  if (which == 3) r.robust = 10.0;
  if (which == 6) r.robust = 35.0;  // held by the time-optimal move * two-hump EI
  if (which == 4) {  // the commissioning demo's plant and move (docs/fastest.md)
    r.limits.vmax = 0.5;
    r.limits.amax = 5.0;
    r.limits.jmax = 200.0;
    r.set_mode(25.0, 0.02);
    (void)r.add_mode({70.0, 0.05});
  }
  if (which == 5) {  // three modes: one ZV each would not fit; the joint ZV move seeds bang-coast
    r.distance = 1.0;
    r.set_mode(5.0, 0.02);
    (void)r.add_mode({23.0, 0.05});
    (void)r.add_mode({71.0, 0.01});
  }
  return r;
}

void BM_PlanFastest(benchmark::State& state, int which) {
  const MoveRequest r = fastest_request(which);
  Move<double> m{};
  for (auto _ : state) benchmark::DoNotOptimize(plan(r, m));
}

void BM_EvaluateFastest(benchmark::State& state) {
  Move<double> m{};
  if (plan(fastest_request(0), m) != Status::ok) std::abort();
  const double dt = m.duration() / 997.0;
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(m.at(t));
    t += dt;
    if (t > m.duration()) t = 0.0;
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_PlanFastest, one_mode, 0)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanFastest, one_damped_mode, 1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanFastest, two_modes, 2)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanFastest, robust_10, 3)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanFastest, robust_35, 6)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanFastest, commissioning, 4)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_PlanFastest, three_modes, 5)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_EvaluateFastest);
