#pragma once
// Small builders shared by the core suites.
#include <optional>

#include "settle/core/planner.hpp"

namespace settle::test {

inline core::MoveRequest timed(core::ProfileKind k, double d, double t, double omega = 0.0, double zeta = 0.0) {
  core::MoveRequest r{};
  r.profile = k;
  r.distance = d;
  r.time = t;
  if (omega > 0.0) r.omega = omega;
  r.zeta = zeta;
  return r;
}

inline core::Move<double> must_plan(const core::MoveRequest& r) {
  core::Move<double> m{};
  const core::Status st = core::plan(r, m);
  if (st != core::Status::ok) ADD_FAILURE() << "plan failed: " << core::to_string(st);
  return m;
}

}  // namespace settle::test
