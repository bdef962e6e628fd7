// SPDX-License-Identifier: Apache-2.0
// The drive master on Linux: plan a move, open a SocketCAN interface, start the drive (node 1)
// and stream the move at 1 kHz from a periodic timer, then report how the session ended.
#include <cstdio>

#include "settle/core/planner.hpp"
#include "settle/runtime/linux/periodic.hpp"
#include "settle/runtime/session.hpp"
#include "settle/hal/socketcan_bus.hpp"

namespace rt = settle::runtime;

// run_session's clock: wait() sleeps to the next period and returns the periods missed.
struct TimerClock {
  rt::linux_rt::PeriodicTimer timer;
  std::uint64_t wait() { return timer.wait(); }
  [[nodiscard]] std::uint64_t now_us() const { return timer.now_us(); }
};

int main(int argc, char** argv) {
  const char* interface = argc > 1 ? argv[1] : "vcan0";
  constexpr std::uint32_t period_us = 1000;

  settle::core::MoveRequest request{};
  request.distance = 0.05;  // m
  request.time = 0.3;       // s
  request.set_mode(22.0);     // rad/s, the mode to leave at rest
  settle::core::Move<double> move{};
  if (const auto status = settle::core::plan(request, move); status != settle::core::Status::ok) {
    std::fprintf(stderr, "linux_master: plan: %s\n", settle::core::describe(status));
    return 1;
  }

  settle::hal::SocketCanBus bus;
  if (const auto status = bus.open(interface); status != settle::hal::OpenStatus::ok) {
    std::fprintf(stderr, "linux_master: cannot open %s: %s\n", interface, settle::hal::to_string(status));
    return 1;
  }
  static rt::ServoLoop<double> loop{bus, period_us};  // static: the loop's queues stay off the stack
  rt::AxisConfig axis{};
  axis.drive.node = 1;
  axis.drive.sdo_timeout_us = 1'000'000;  // patient configuration: a busy host may stall for a while
  axis.feedback_timeout_periods = 250;     // a drive process on the same busy host, not a real drive (default 10)
  axis.scale = {1e6, period_us};  // 1 count = 1 µm, at the loop's period
  axis.vmax = 1.0;             // m/s
  if (loop.add_axis(axis) != rt::LoopStatus::ok) return 1;

  TimerClock clock{rt::linux_rt::PeriodicTimer{period_us}};
  clock.timer.start();
  rt::SessionConfig session{};
  session.settle_ticks = 200;
  // After each tick: here only the drive's feedback log is emptied (a real master would log it).
  const rt::SessionResult r =
      rt::run_session(loop, clock, &move, 1, session, [](std::uint64_t, bool) { loop.feedback_log(0).clear(); });
  std::printf("session %s after %llu ticks; drive at %d counts (target %d)\n", rt::to_string(r.outcome),
              static_cast<unsigned long long>(r.ticks), loop.record(0).position_actual, loop.record(0).target);
  return r.outcome == rt::SessionOutcome::completed ? 0 : 1;
}
