// SPDX-License-Identifier: Apache-2.0
#pragma once
// The servo loop's Linux target: a periodic timer on CLOCK_MONOTONIC with absolute deadlines
// (clock_nanosleep TIMER_ABSTIME), real-time scheduling and locked memory when permitted, and
// the wake-up latency histogram the run reports. An overrun is counted and the missed periods
// are skipped (never caught up in a burst): the caller holds its last setpoint meanwhile.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace settle::runtime::linux_rt {

[[nodiscard]] std::uint64_t monotonic_ns() noexcept;

struct RealtimeSetup {
  bool fifo{false};        // SCHED_FIFO granted
  bool locked{false};      // mlockall(MCL_CURRENT | MCL_FUTURE) succeeded
  int fifo_priority{0};
  std::string fifo_error;  // why not, when not (strerror)
  std::string lock_error;
  bool pm_qos{false};      // a CpuLatencyRequest was held while the loop ran
  std::string pm_qos_error;  // why not, when asked for and not held ("off" when switched off)
};
// Asks for SCHED_FIFO at `priority` and for locked memory; failing either is reported, not fatal.
[[nodiscard]] RealtimeSetup request_realtime(int priority) noexcept;

// The CPU power-management QoS request (Documentation/power/pm_qos_interface): while the file
// /dev/cpu_dma_latency is held open with a value written to it, no CPU enters an idle state whose
// exit latency exceeds that many µs. At 0 the CPUs stay out of deep idle states, which is most of
// the wake-up latency a periodic loop sees on an idle machine (cyclictest holds it by default;
// `cyclictest --laptop` does not). Closing the file (destruction) withdraws the request.
class CpuLatencyRequest {
 public:
  static constexpr const char* kDevice = "/dev/cpu_dma_latency";
  // Opens `path` and writes `max_latency_us` as the binary 32-bit value the kernel expects.
  explicit CpuLatencyRequest(std::int32_t max_latency_us = 0, const char* path = kDevice) noexcept;
  ~CpuLatencyRequest();
  CpuLatencyRequest(const CpuLatencyRequest&) = delete;
  CpuLatencyRequest& operator=(const CpuLatencyRequest&) = delete;

  [[nodiscard]] bool held() const noexcept { return fd_ >= 0; }
  [[nodiscard]] const std::string& error() const noexcept { return error_; }  // strerror when not held

 private:
  int fd_{-1};
  std::string error_;
};

// Latency in ns, in fixed bins: 1 µs resolution to 1 ms, then 100 µs to 100 ms, then overflow.
class LatencyHistogram {
 public:
  void add(std::int64_t ns) noexcept;
  [[nodiscard]] std::uint64_t count() const noexcept { return count_; }
  [[nodiscard]] std::int64_t min_ns() const noexcept { return count_ != 0 ? min_ : 0; }
  [[nodiscard]] std::int64_t max_ns() const noexcept { return max_; }
  // Upper edge of the bin holding the q-quantile (0 < q <= 1).
  [[nodiscard]] std::int64_t quantile_ns(double q) const noexcept;

 private:
  static constexpr std::size_t kFine = 1000;   // 0..999 µs, 1 µs bins
  static constexpr std::size_t kCoarse = 999;  // 1..100 ms, 100 µs bins
  std::array<std::uint64_t, kFine + kCoarse + 1> bins_{};
  std::uint64_t count_{0};
  std::int64_t min_{INT64_MAX};  // from <cstdint>
  std::int64_t max_{0};
};

class PeriodicTimer {
 public:
  explicit PeriodicTimer(std::uint32_t period_us) noexcept;
  // Sets the first deadline one period from now.
  void start() noexcept;
  // Sleeps until the next deadline. Returns the number of periods that were missed (0 normally);
  // when late by one or more whole periods the deadline skips ahead past now.
  std::uint64_t wait() noexcept;
  [[nodiscard]] const LatencyHistogram& latency() const noexcept { return hist_; }
  [[nodiscard]] std::uint64_t overruns() const noexcept { return overruns_; }
  [[nodiscard]] std::uint64_t skipped_periods() const noexcept { return skipped_; }
  // Deadline of the period that wait() just started, in µs on the monotonic clock.
  [[nodiscard]] std::uint64_t now_us() const noexcept { return (next_ns_ - period_ns_) / 1000; }

 private:
  std::uint64_t period_ns_;
  std::uint64_t next_ns_{0};
  LatencyHistogram hist_{};
  std::uint64_t overruns_{0};
  std::uint64_t skipped_{0};
};

}  // namespace settle::runtime::linux_rt
