// SPDX-License-Identifier: Apache-2.0
#pragma once
// The request the core benchmarks plan (and settle_tick_instructions counts): the seed-000
// beam's move, 0.1 m designed for 22.05 rad/s, in 0.5 s, or under vmax 0.5, amax 5, jmax 100
// for the jerk-limited profile; shaped by s.
#include "settle/core/planner.hpp"

namespace settle::bench {

inline core::MoveRequest benchmark_request(core::ProfileKind k, core::ShaperKind s = core::ShaperKind::none) {
  core::MoveRequest r{};
  r.profile = k;
  r.distance = 0.1;
  r.set_mode(22.04871, k == core::ProfileKind::scurve ? 0.0 : 0.05);
  r.shaper = s;
  if (k == core::ProfileKind::jerk_limited) {
    r.limits.vmax = 0.5;
    r.limits.amax = 5.0;
    r.limits.jmax = 100.0;
  } else {
    r.time = 0.5;
  }
  if (k == core::ProfileKind::pseudopoly) {
    r.gammas = {3.024, 4.565, 5.874};
    r.gamma_count = 3;
  }
  return r;
}

}  // namespace settle::bench
