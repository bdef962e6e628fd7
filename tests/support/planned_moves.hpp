// SPDX-License-Identifier: Apache-2.0
#pragma once
// Moves the sim tests plan by name, planned by core and checked to plan (one place for both the
// limits and the node tests).
#include <gtest/gtest.h>

#include "settle/core/planner.hpp"

namespace settle::testing {

inline core::Move<double> poly345(double distance, double time) {
  core::MoveRequest rq;
  rq.profile = core::ProfileKind::poly345;
  rq.distance = distance;
  rq.time = time;
  core::Move<double> m;
  EXPECT_EQ(core::plan(rq, m), core::Status::ok);
  return m;
}

inline core::Move<double> scurve(double distance, double time, double omega) {
  core::MoveRequest rq;
  rq.profile = core::ProfileKind::scurve;
  rq.distance = distance;
  rq.time = time;
  rq.set_mode(omega);
  core::Move<double> m;
  EXPECT_EQ(core::plan(rq, m), core::Status::ok);
  return m;
}

}  // namespace settle::testing
