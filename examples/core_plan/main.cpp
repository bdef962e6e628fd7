// SPDX-License-Identifier: Apache-2.0
// A 50 mm S-curve move designed for a 3.5 Hz mode, sampled at 10 points from start to rest.
#include <cstdio>

#include "settle/core/planner.hpp"

int main() {
  settle::core::MoveRequest request{};
  request.profile = settle::core::ProfileKind::scurve;
  request.distance = 0.05;  // m
  request.time = 0.6;       // s, the unshaped move
  request.set_mode(22.0);     // rad/s: the mode the move leaves at rest

  settle::core::Move<double> move{};
  if (const settle::core::Status status = settle::core::plan(request, move); status != settle::core::Status::ok) {
    std::fprintf(stderr, "plan failed: %s\n", settle::core::describe(status));
    return 1;
  }
  std::printf("%s move of %g m in %.6f s\n", settle::core::to_string(move.profile().kind()), move.distance(),
              move.duration());
  for (int i = 0; i < 10; ++i) {
    const double t = move.duration() * i / 9.0;
    const settle::core::Sample<double> s = move.at(t);
    std::printf("t %.4f s  p %.6f m  v %.5f m/s  a %.4f m/s^2\n", t, s.p, s.v, s.a);
  }
  return 0;
}
