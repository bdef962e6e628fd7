// SPDX-License-Identifier: Apache-2.0
// Instructions per full servo tick on the host, for callgrind: ServoLoop::tick on one axis against
// an IdealDrive on the loopback bus, moves submitted back to back (start-up, streaming and each
// move's finishing ticks, in the proportions a run of S-curves has). Only tick_once() is
// collected: submit(), service() and the drive's side are not. Modes:
//   double        ServoLoop<double> (online changes on, none asked)
//   double_change the same, every move retargeted at its 150th tick and its blend halted 60 later
//   float         ServoLoop<float> on FloatEvaluation<float> (online off: a Cortex-M4F's loop)
//   fixed         ServoLoop on FixedEvaluation (online off: a Cortex-M0's loop)
// Usage, from the build directory (one line):
//   valgrind --tool=callgrind --callgrind-out-file=/dev/null --collect-atstart=no
//   '--toggle-collect=void tick_once*' bench/runtime/settle_loop_tick_instructions double 20000
// The instructions per tick are the difference between 40000 and 20000 ticks over 20000.
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "settle/hal/testing/ideal_drive.hpp"
#include "settle/runtime/servo_loop.hpp"

using namespace settle;

// Not static, not inlined: callgrind's --toggle-collect names it.
template <typename Loop>
__attribute__((noinline)) void tick_once(Loop& loop, std::uint64_t now) {
  loop.tick(now);
}

namespace {

constexpr std::uint32_t kPeriod = 1000;

template <typename Loop>
int run(long ticks, bool change) {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  hal::canopen::DriveNodeConfig dc{};
  hal::testing::IdealDrive<> drive{hub, dc};
  Loop loop{master, kPeriod};
  runtime::AxisConfig a{};
  a.drive.node = hal::canopen::NodeId{1};
  a.scale = {1e6, kPeriod};
  a.vmax = 2.0;
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.distance = 0.1;
  r.time = 0.5;
  r.set_mode(22.0);
  core::Move<double> m{};
  if (loop.add_axis(a) != runtime::LoopStatus::ok || core::plan(r, m) != core::Status::ok) return 1;
  if constexpr (Loop::kOnlineChanges) {
    runtime::OnlineConfig c{};
    c.modes[0] = {22.0, 0.0};
    c.mode_count = 1;
    c.limits = {1.2 * m.peaks().v, 1.2 * m.peaks().a, 1.2 * m.peaks().j};
    if (loop.configure_online(0, c) != runtime::LoopStatus::ok) return 1;
  }
  std::uint64_t now = 0;
  drive.start(now);
  loop.start(now);
  long since_submit = 0;
  for (long t = 0, counted = 0; counted < ticks; ++t) {
    if (t > 100000) return 2;  // never came up
    if (loop.ready(0)) {
      if (loop.idle()) {
        if (loop.submit(0, m) != runtime::LoopStatus::ok) return 3;
        since_submit = 0;
      }
      if constexpr (Loop::kOnlineChanges) {
        if (change && (since_submit == 150 || since_submit == 210)) {
          if (!(since_submit == 150 ? loop.retarget(0, 0.06) : loop.halt(0))) return 4;
          if (loop.service() != runtime::LoopStatus::ok) return 5;
        }
      }
      ++since_submit;
      ++counted;
    }
    now += kPeriod;
    hub.set_time_us(now);
    tick_once(loop, now);
    drive.process(now);
    for (runtime::LoopEvent e{}; loop.events().pop(e);) {
    }
  }
  if constexpr (Loop::kOnlineChanges) {
    if (change && loop.online_switches(0) == 0) return 6;  // the changes were never switched in
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s double|double_change|float|fixed TICKS\n", argv[0]);
    return 2;
  }
  const long n = std::strtol(argv[2], nullptr, 10);
  using Fixed = runtime::ServoLoop<double, 1, 4, runtime::FixedEvaluation>;
  const char* mode = argv[1];
  int rc = 2;
  if (std::strcmp(mode, "double") == 0) rc = run<runtime::ServoLoop<double, 1, 4>>(n, false);
  if (std::strcmp(mode, "double_change") == 0) rc = run<runtime::ServoLoop<double, 1, 4>>(n, true);
  if (std::strcmp(mode, "float") == 0) rc = run<runtime::ServoLoop<float, 1, 4>>(n, false);
  if (std::strcmp(mode, "fixed") == 0) rc = run<Fixed>(n, false);
  if (rc != 0) std::fprintf(stderr, "%s: failed (%d)\n", mode, rc);
  return rc;
}
