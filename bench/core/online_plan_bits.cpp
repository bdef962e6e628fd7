// SPDX-License-Identifier: Apache-2.0
// Every bit of a fixed set of online plans, one line each (status, choice, flags, rest time,
// segment length and the 24 jerks in hexadecimal floating point), for a change meant to make the
// planner cheaper without changing any result: build it before and after and compare the outputs
// (docs/online.md, "Each duration cheaper, the same bits"). The set: the four changes BM_PlanOnline
// times (online_setup.hpp) with one and two modes, halt and retarget, at 160 switch times under
// limits scaled in ten steps, and 3 000 seeded random requests (1 to kMaxOnlineModes modes, random
// states, memories and limits over four decades; plain halts, retargets and halts of a running
// command that ends at rest or does not). The bits depend on the C library's sin, cos and exp:
// compare outputs of one machine only. Usage: bench/core/settle_online_plan_bits > plans.txt
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "online_setup.hpp"

using namespace settle;

namespace {

std::uint64_t g_state = 88172645463325252ULL;

// xorshift64, in [0, 1).
double uniform() {
  g_state ^= g_state << 13;
  g_state ^= g_state >> 7;
  g_state ^= g_state << 17;
  return static_cast<double>(g_state >> 11) * 0x1p-53;
}

void print(const char* what, std::size_t i, core::Status s, const core::OnlinePlan& p) {
  std::printf("%s %zu status %d choice %d flags %d%d%d rest %a h %a", what, i, static_cast<int>(s),
              static_cast<int>(p.choice), p.fastest_passes_target, p.fastest_ends_later, p.ends_later, p.rest_after,
              p.blend.segment_length());
  for (std::size_t k = 0; k < core::kBlendSegments; ++k) std::printf(" %a", p.blend.jerk(k));
  std::printf("\n");
}

void benchmark_changes() {
  for (const core::ProfileKind kind : {core::ProfileKind::scurve, core::ProfileKind::jerk_limited}) {
    const bench::OnlineSetup s = bench::online_setup(kind);
    for (std::size_t modes = 1; modes <= 2; ++modes) {
      for (const bool retarget : {false, true}) {
        for (std::size_t i = 0; i < 160; ++i) {
          const double step = static_cast<double>(i / 16);
          const double f = 1.0 + 0.037 * step;
          core::OnlineLimits l = s.limits;
          l.vmax *= f;
          l.amax *= 2.0 - 0.05 * step;
          l.jmax *= f * f;
          const double t = s.move.duration() * (0.01 + 0.98 * static_cast<double>(i) / 159.0);
          const std::optional<double> target =
              retarget ? std::optional<double>{(0.2 + 0.1 * static_cast<double>(i % 9)) * s.move.distance()}
                       : std::nullopt;
          core::OnlineRequest r{};
          core::OnlinePlan p{};
          // The move's end memory taken once (online_setup), as the benchmark and the servo loop take it.
          core::Status st = core::online_request(s.move, s.end, t, s.modes.data(), modes, l, target, r);
          if (st == core::Status::ok) st = core::plan_online(r, p);
          char what[48];
          std::snprintf(what, sizeof what, "%s/%zu-modes/%s", kind == core::ProfileKind::scurve ? "scurve" : "zvd",
                        modes, retarget ? "retarget" : "halt");
          print(what, i, st, p);
        }
      }
    }
  }
}

void random_requests() {
  for (std::size_t i = 0; i < 3000; ++i) {
    core::OnlineRequest r{};
    r.mode_count = std::min<std::size_t>(1 + static_cast<std::size_t>(uniform() * 3.0), core::kMaxOnlineModes);
    const double scale = std::pow(10.0, -3.0 + 4.0 * uniform());
    r.limits.vmax = scale * (0.5 + uniform());
    r.limits.amax = scale * (2.0 + 20.0 * uniform());
    r.limits.jmax = scale * (50.0 + 2000.0 * uniform());
    r.start.p = scale * (uniform() - 0.5);
    r.start.v = r.limits.vmax * (1.6 * uniform() - 0.8);
    r.start.a = r.limits.amax * (1.6 * uniform() - 0.8);
    for (std::size_t m = 0; m < r.mode_count; ++m) {
      r.modes[m] = {std::pow(10.0, 0.3 + 2.2 * uniform()), 0.3 * uniform() * uniform()};
      r.memory[m] = {scale * 1e-3 * (uniform() - 0.5), scale * 1e-3 * (uniform() - 0.5)};
    }
    const double kind = uniform();
    if (kind < 1.0 / 3.0) {
      r.target = r.start.p + scale * (uniform() - 0.5);
    } else if (kind < 2.0 / 3.0) {
      r.running = core::OnlineRunning{0.0, r.start.p + scale * uniform(), 0.05 + uniform(), uniform() < 0.5};
    }
    core::OnlinePlan p{};
    print("random", i, core::plan_online(r, p), p);
  }
}

}  // namespace

int main() {
  benchmark_changes();
  random_requests();
  return 0;
}
