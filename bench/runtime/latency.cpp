// SPDX-License-Identifier: Apache-2.0
// Wake-up latency of the Linux servo loop: the loop and an ideal drive on the in-process bus,
// paced by the real periodic timer (clock_nanosleep, TIMER_ABSTIME, CLOCK_MONOTONIC) for a given
// time, SCHED_FIFO and mlockall when permitted, and the PM QoS request (/dev/cpu_dma_latency = 0
// held while it runs, as cyclictest does by default; pm_qos=0 leaves it, like `cyclictest
// --laptop`). Prints the histogram summary as JSON, to set next to
// `cyclictest -m -p <prio> -i <period> -D <seconds> -q` run the same way.
//   settle_latency [seconds=60] [period_us=1000] [priority=50] [pm_qos=1]
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "settle/runtime/linux/periodic.hpp"
#include "settle/runtime/servo_loop.hpp"
#include "settle/hal/testing/ideal_drive.hpp"

using namespace settle;

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 60.0;
  const auto period_us = static_cast<std::uint32_t>(argc > 2 ? std::atoi(argv[2]) : 1000);
  const int priority = argc > 3 ? std::atoi(argv[3]) : 50;
  const bool pm_qos = argc > 4 ? std::atoi(argv[4]) != 0 : true;
  const auto rt = runtime::linux_rt::request_realtime(priority);
  std::optional<runtime::linux_rt::CpuLatencyRequest> cpu_latency;
  if (pm_qos) cpu_latency.emplace();
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  hal::testing::IdealDrive<> drive{hub, hal::canopen::DriveNodeConfig{}};
  runtime::ServoLoop<double, 1, 4> loop{master, period_us};
  runtime::AxisConfig a{};
  a.scale.period_us = period_us;
  if (loop.add_axis(a) != runtime::LoopStatus::ok) return 1;
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.distance = 0.1;
  r.time = 0.5;
  r.set_mode(22.0);
  core::Move<double> there{}, back{};
  if (core::plan(r, there) != core::Status::ok) return 1;
  r.distance = -0.1;
  if (core::plan(r, back) != core::Status::ok) return 1;
  runtime::linux_rt::PeriodicTimer timer{period_us};
  drive.start(0);
  timer.start();
  loop.start(timer.now_us());
  const auto ticks = static_cast<std::uint64_t>(seconds * 1e6 / period_us);
  bool out = true;
  for (std::uint64_t i = 0; i < ticks; ++i) {
    (void)timer.wait();
    const std::uint64_t now = timer.now_us();
    hub.set_time_us(now);
    if (loop.ready(0) && loop.idle()) {
      (void)loop.submit(0, out ? there : back);
      out = !out;
    }
    loop.tick(now);
    drive.process(now);
  }
  const auto& h = timer.latency();
  std::printf("{\"seconds\":%.1f,\"period_us\":%u,\"sched_fifo\":%s,\"mlockall\":%s,\"pm_qos\":%s,\"samples\":%llu,"
              "\"min_ns\":%lld,\"p50_ns\":%lld,\"p99_ns\":%lld,\"max_ns\":%lld,\"overruns\":%llu,"
              "\"moves_completed\":%llu}\n",
              seconds, period_us, rt.fifo ? "true" : "false", rt.locked ? "true" : "false",
              cpu_latency && cpu_latency->held() ? "true" : "false",
              static_cast<unsigned long long>(h.count()), static_cast<long long>(h.min_ns()),
              static_cast<long long>(h.quantile_ns(0.5)), static_cast<long long>(h.quantile_ns(0.99)),
              static_cast<long long>(h.max_ns()), static_cast<unsigned long long>(timer.overruns()),
              static_cast<unsigned long long>(loop.axis_stats(0).moves_completed));
  return 0;
}
