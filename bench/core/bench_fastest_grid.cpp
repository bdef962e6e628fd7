// SPDX-License-Identifier: Apache-2.0
// Planning `fastest` on every problem of the reference grid (tests/core/data/fastest_reference_grid.txt,
// docs/fastest.md "Against the reference"): one benchmark per case, named by its id and number of
// modes, BM_PlanFastestGrid/<modes>_modes/case_<id>, so the distribution of planning times over the
// grid is one run: --benchmark_filter=PlanFastestGrid --benchmark_format=json.
#include <benchmark/benchmark.h>

#include <fstream>
#include <sstream>
#include <string>

#include "settle/core/planner.hpp"

namespace {

using namespace settle::core;

void plan_case(benchmark::State& state, MoveRequest r) {
  Move<double> m{};
  for (auto _ : state) benchmark::DoNotOptimize(plan(r, m));
  state.counters["duration_s"] = plan(r, m) == Status::ok ? m.duration() : 0.0;
}

// Registered before main runs: one benchmark per line of the grid file (comments skipped).
const int registered = [] {
  std::ifstream in(SETTLE_FASTEST_GRID_FILE);
  int n = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line.front() == '#') continue;
    std::istringstream s(line);
    int id = 0, modes = 0;
    MoveRequest r{};
    r.profile = ProfileKind::fastest;
    double d, v, a, j, w[3], z[3];
    s >> id >> d >> v >> a >> j >> modes >> w[0] >> z[0] >> w[1] >> z[1] >> w[2] >> z[2];
    if (!s || modes < 1 || modes > 3) continue;
    r.distance = d, r.limits.vmax = v, r.limits.amax = a, r.limits.jmax = j, r.set_mode(w[0], z[0]);
    for (std::size_t k = 1; k < static_cast<std::size_t>(modes); ++k) (void)r.add_mode({w[k], z[k]});
    const std::string name = "BM_PlanFastestGrid/" + std::to_string(modes) + "_modes/case_" + std::to_string(id);
    benchmark::RegisterBenchmark(name.c_str(), plan_case, r)->Unit(benchmark::kMicrosecond);
    ++n;
  }
  return n;
}();

}  // namespace
