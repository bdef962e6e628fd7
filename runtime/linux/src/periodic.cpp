// SPDX-License-Identifier: Apache-2.0
#include "settle/runtime/linux/periodic.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace settle::runtime::linux_rt {

std::uint64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000ULL + static_cast<std::uint64_t>(ts.tv_nsec);
}

RealtimeSetup request_realtime(int priority) noexcept {
  RealtimeSetup r{};
  sched_param sp{};
  sp.sched_priority = priority;
  if (sched_setscheduler(0, SCHED_FIFO, &sp) == 0) {
    r.fifo = true;
    r.fifo_priority = priority;
  } else {
    r.fifo_error = std::strerror(errno);
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    r.locked = true;
  } else {
    r.lock_error = std::strerror(errno);
  }
  return r;
}

CpuLatencyRequest::CpuLatencyRequest(std::int32_t max_latency_us, const char* path) noexcept {
  const int fd = ::open(path, O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    error_ = std::strerror(errno);
    return;
  }
  const ssize_t written = ::write(fd, &max_latency_us, sizeof max_latency_us);
  if (written != static_cast<ssize_t>(sizeof max_latency_us)) {
    error_ = written < 0 ? std::strerror(errno) : "short write";
    ::close(fd);
    return;
  }
  fd_ = fd;
}

CpuLatencyRequest::~CpuLatencyRequest() {
  if (fd_ >= 0) ::close(fd_);
}

void LatencyHistogram::add(std::int64_t ns) noexcept {
  if (ns < 0) ns = 0;
  ++count_;
  if (ns < min_) min_ = ns;
  if (ns > max_) max_ = ns;
  const std::int64_t us = ns / 1000;
  std::size_t bin;
  if (us < static_cast<std::int64_t>(kFine)) {
    bin = static_cast<std::size_t>(us);
  } else if (us < 100'000) {
    bin = kFine + static_cast<std::size_t>((us - 1000) / 100);
  } else {
    bin = kFine + kCoarse;
  }
  ++bins_[bin];
}

std::int64_t LatencyHistogram::quantile_ns(double q) const noexcept {
  if (count_ == 0) return 0;
  const auto want = static_cast<std::uint64_t>(q * static_cast<double>(count_) + 0.999999);
  std::uint64_t acc = 0;
  for (std::size_t i = 0; i < bins_.size(); ++i) {
    acc += bins_[i];
    if (acc >= want) {
      if (i < kFine) return static_cast<std::int64_t>(i + 1) * 1000;
      if (i < kFine + kCoarse) return (1000 + static_cast<std::int64_t>(i - kFine + 1) * 100) * 1000;
      return max_;
    }
  }
  return max_;
}

PeriodicTimer::PeriodicTimer(std::uint32_t period_us) noexcept : period_ns_{std::uint64_t{period_us} * 1000} {}

void PeriodicTimer::start() noexcept { next_ns_ = monotonic_ns() + period_ns_; }

std::uint64_t PeriodicTimer::wait() noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(next_ns_ / 1'000'000'000ULL);
  ts.tv_nsec = static_cast<long>(next_ns_ % 1'000'000'000ULL);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
  const std::uint64_t now = monotonic_ns();
  hist_.add(static_cast<std::int64_t>(now - next_ns_));
  std::uint64_t missed = 0;
  if (now >= next_ns_ + period_ns_) {
    // Late by whole periods: count one overrun, skip the periods already gone.
    missed = (now - next_ns_) / period_ns_;
    ++overruns_;
    skipped_ += missed;
  }
  const std::uint64_t this_deadline = next_ns_ + missed * period_ns_;
  next_ns_ = this_deadline + period_ns_;
  return missed;
}

}  // namespace settle::runtime::linux_rt
