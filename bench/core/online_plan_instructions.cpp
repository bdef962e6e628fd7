// SPDX-License-Identifier: Apache-2.0
// Instructions per online plan, for callgrind: the four changes BM_PlanOnline times
// (bench_online.cpp, online_setup.hpp), each planned whole (mode memory, the blend's duration
// search, a halt's choice) at the 16 switch times in turn. Timings of a plan scatter by a factor
// of two on a shared machine; instruction counts do not. Usage, from the build directory (one line):
//   valgrind --tool=callgrind --callgrind-out-file=cg.out --collect-atstart=no
//   '--toggle-collect=*plan_once*' bench/core/settle_online_plan_instructions halt_scurve_2modes 160
// The instructions per plan are the difference between 320 and 160 plans over 160 (a multiple of
// 16: whole cycles of switch times). The durations tried per blend are the calls of
// BlendFamily::feasible over those of plan_blend, both in `callgrind_annotate --tree=caller cg.out`.
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "online_setup.hpp"

using namespace settle;

namespace {

struct Case {
  const char* name;
  core::ProfileKind kind;
  std::size_t modes;
  bool retarget;
};

constexpr Case kCases[] = {
    {"halt_scurve_1mode", core::ProfileKind::scurve, 1, false},
    {"halt_scurve_2modes", core::ProfileKind::scurve, 2, false},
    {"halt_jerk_limited_zvd_1mode", core::ProfileKind::jerk_limited, 1, false},
    {"retarget_scurve_1mode", core::ProfileKind::scurve, 1, true},
};

volatile int g_sink;

}  // namespace

// Not static, not inlined: callgrind's --toggle-collect names it.
__attribute__((noinline)) core::Status plan_once(const bench::OnlineSetup& s, const Case& c, std::size_t i,
                                                 core::OnlinePlan& p) {
  return bench::plan_online_change(s, c.modes, c.retarget, i, p);
}

int main(int argc, char** argv) {
  const long plans = argc == 3 ? std::strtol(argv[2], nullptr, 10) : 0;
  const Case* c = nullptr;
  for (const Case& k : kCases) {
    if (argc == 3 && std::strcmp(argv[1], k.name) == 0) c = &k;
  }
  if (c == nullptr || plans <= 0) {
    std::fprintf(stderr, "usage: settle_online_plan_instructions");
    for (const Case& k : kCases) std::fprintf(stderr, " %s", k.name);
    std::fprintf(stderr, " PLANS\n");
    return 2;
  }
  const bench::OnlineSetup s = bench::online_setup(c->kind);
  for (long i = 0; i < plans; ++i) {
    core::OnlinePlan p{};
    if (plan_once(s, *c, static_cast<std::size_t>(i), p) != core::Status::ok) {
      std::fprintf(stderr, "%s: plan %ld failed\n", c->name, i);
      return 1;
    }
    g_sink = static_cast<int>(p.choice);
  }
  return 0;
}
