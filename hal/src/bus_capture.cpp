// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/bus_capture.hpp"

#include <chrono>
#include <utility>

namespace settle::hal {

BusCapture::~BusCapture() { (void)stop(); }

std::string BusCapture::start(const std::string& iface, const std::string& path, const BusCaptureOptions& options) {
  if (running()) return "the capture is already running";
  if (options.drain_interval_ms < 1 || options.drain_interval_ms > 10'000) {
    return "the drain interval must be 1..10000 ms";
  }
  options_ = options;
  SocketCanOptions so{};
  so.receive_buffer_bytes = options.receive_buffer_bytes;
  so.timestamps = true;
  if (const OpenStatus st = bus_.open(iface.c_str(), so); st != OpenStatus::ok) {
    return "cannot open " + iface + ": " + to_string(st);
  }
  if (!file_.open(path.c_str(), iface.c_str())) {
    bus_.close();
    return "cannot write " + path;
  }
  result_ = BusCaptureResult{};
  failed_ = false;
  stopping_ = false;
  thread_ = std::thread{[this] { run(); }};
  return {};
}

BusCaptureResult BusCapture::stop() {
  if (!running()) return result_;
  {
    const std::lock_guard<std::mutex> lock{mutex_};
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
  // The thread's last drain found the queue empty: the drop count is exact.
  result_.kernel_drops = bus_.counters().rx_overflow_drops;
  if (!file_.close() && result_.error.empty()) result_.error = "the log could not be written";
  bus_.close();
  return result_;
}

// Drains, then waits for the interval (or stop) and drains again: one wake-up per interval
// however many frames arrived, so the capture takes little CPU from the processes it records;
// the socket's queue holds what arrives in between.
void BusCapture::run() {
  std::unique_lock<std::mutex> lock{mutex_};
  while (!stopping_ && !failed_) {
    lock.unlock();
    drain();
    lock.lock();
    (void)wake_.wait_for(lock, std::chrono::milliseconds{options_.drain_interval_ms}, [this] { return stopping_; });
  }
  lock.unlock();
  drain();  // what came before stop()
}

void BusCapture::drain() {
  CanFrame f{};
  for (;;) {
    const ReceiveStatus rs = bus_.receive(f, 0);
    if (rs == ReceiveStatus::empty) return;
    if (rs != ReceiveStatus::received) {
      if (result_.error.empty()) result_.error = "receive failed (errno " + std::to_string(bus_.last_errno()) + ")";
      failed_ = true;
      return;
    }
    if (result_.frames > 0 && f.timestamp_us < result_.last_us) ++result_.steps_back;
    if (result_.frames == 0) result_.first_us = f.timestamp_us;
    result_.last_us = f.timestamp_us;
    if (!file_.write(f)) {
      if (result_.error.empty()) result_.error = "the log could not be written";
      failed_ = true;
      return;
    }
    ++result_.frames;
  }
}

}  // namespace settle::hal
