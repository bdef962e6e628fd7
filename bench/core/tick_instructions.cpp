// SPDX-License-Identifier: Apache-2.0
// Instructions per tick, for callgrind: the S-curve stepped (MoveStepper) against the
// jerk-limited profile at random access (Move::at), and, on the jerk-limited move, Move::at and
// the stepper against the bare piecewise evaluator (PiecewiseJerk::at) they wrap. Timings of these
// (settle_core_bench, BM_Step / BM_Evaluate / BM_EvaluateBare) differ by about 1 ns and scatter by
// about 1.5 ns on a shared machine; instruction counts do not scatter. Same requests
// (bench_request.hpp) and tick patterns as bench_core.cpp. Usage, from the build directory (one line):
//   valgrind --tool=callgrind --callgrind-out-file=/dev/null --collect-atstart=no
//   '--toggle-collect=void run_step*' bench/core/settle_tick_instructions double step 100000
// Modes and the function to collect: step (the S-curve) and step_jl (the jerk-limited move) run_step,
// at run_at, bare run_bare; `float` likewise. The instructions per tick are the difference between
// 200000 and 100000 ticks over 100000.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <variant>
#include <vector>

#include "bench_request.hpp"
#include "settle/core/planner.hpp"
#include "settle/core/stepper.hpp"

using namespace settle::core;

namespace {

volatile double g_sink;

}  // namespace

// Not static, not inlined: callgrind's --toggle-collect names them.
template <typename T>
__attribute__((noinline)) void run_step(const Move<T>& m, long n) {
  const auto ticks = static_cast<long>(m.duration() / T(1e-3));
  MoveStepper<T> st{m, T(1e-3)};
  long k = 0;
  for (long i = 0; i < n; ++i) {
    g_sink = static_cast<double>(st.step().p);
    if (++k == ticks) {
      st = MoveStepper<T>{m, T(1e-3)};
      k = 0;
    }
  }
}

// Random access at the move's ticks, n calls: `e` is a Move (run_at) or its bare piecewise evaluator
// (run_bare: PiecewiseJerk<T>::at, no Move, no Profile dispatch, no shaper, whose count is what
// Move::at and the stepper cost beyond the maths). Inlined into each, which callgrind names.
template <typename T, typename E>
__attribute__((always_inline)) inline void evaluate_at_ticks(const E& e, const std::vector<T>& ts, long n) {
  std::size_t j = 0;
  for (long i = 0; i < n; ++i) {
    g_sink = static_cast<double>(e.at(ts[j]).p);
    if (++j == ts.size()) j = 0;
  }
}

template <typename T>
__attribute__((noinline)) void run_at(const Move<T>& m, const std::vector<T>& ts, long n) {
  evaluate_at_ticks(m, ts, n);
}

template <typename T>
__attribute__((noinline)) void run_bare(const PiecewiseJerk<T>& pj, const std::vector<T>& ts, long n) {
  evaluate_at_ticks(pj, ts, n);
}

template <typename T>
int run(const char* mode, long n) {
  Move<double> scurve{}, jerk{};
  if (plan(settle::bench::benchmark_request(ProfileKind::scurve), scurve) != Status::ok ||
      plan(settle::bench::benchmark_request(ProfileKind::jerk_limited), jerk) != Status::ok) {
    std::fputs("settle_tick_instructions: planning failed\n", stderr);
    return 1;
  }
  const Move<T> s{scurve}, j{jerk};
  std::vector<T> ts;
  for (T t = 0; t < j.duration(); t += T(1e-3)) ts.push_back(t);
  if (std::strcmp(mode, "step") == 0) {
    run_step<T>(s, n);
  } else if (std::strcmp(mode, "at") == 0) {
    run_at<T>(j, ts, n);
  } else if (std::strcmp(mode, "step_jl") == 0) {
    run_step<T>(j, n);
  } else if (std::strcmp(mode, "bare") == 0) {
    const auto* bare = std::get_if<PiecewiseJerk<T>>(&j.profile().variant());
    if (bare == nullptr) {
      std::fputs("settle_tick_instructions: the jerk-limited move is not a PiecewiseJerk\n", stderr);
      return 1;
    }
    run_bare<T>(*bare, ts, n);
  } else {
    std::fputs("settle_tick_instructions: mode is step, at, step_jl or bare\n", stderr);
    return 2;
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fputs("usage: settle_tick_instructions double|float step|at|step_jl|bare TICKS\n", stderr);
    return 2;
  }
  const long n = std::strtol(argv[3], nullptr, 10);
  if (!(n > 0 && n <= 100000000)) {
    std::fputs("settle_tick_instructions: TICKS in 1..1e8\n", stderr);
    return 2;
  }
  if (std::strcmp(argv[1], "double") == 0) return run<double>(argv[2], n);
  if (std::strcmp(argv[1], "float") == 0) return run<float>(argv[2], n);
  std::fputs("settle_tick_instructions: type is double or float\n", stderr);
  return 2;
}
