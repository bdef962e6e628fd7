// SPDX-License-Identifier: Apache-2.0
// A capture of a SocketCAN interface as the bus saw it: one raw socket (every frame of every
// process on the interface, and of every other node on a real bus, except its own, of which it
// sends none), each frame stamped with the kernel's receive time (SO_TIMESTAMP, CLOCK_REALTIME,
// µs), written in the order the kernel queued it, as a candump log (candump_file.hpp). A thread
// of its own drains the socket's queue (16 MB asked for, SO_RCVBUFFORCE where permitted) into
// the file while the processes under test run, so the queue never has to hold a whole session;
// what the kernel still drops from a full queue is counted (SO_RXQ_OVFL) and reported, never
// lost silently. Host only (a thread, stdio).
//
// Complete up to stop(): on a virtual interface a frame reaches every socket within its sender's
// send call (Linux 5.18 and later deliver netif_rx's queue before returning), so once the
// processes that sent them have ended, stop()'s last drain takes every frame they sent.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "settle/hal/candump_file.hpp"
#include "settle/hal/socketcan_bus.hpp"

namespace settle::hal {

struct BusCaptureOptions {
  int receive_buffer_bytes{16 << 20};  // asked of the kernel (it doubles it and charges ~768 B a frame)
  std::uint32_t drain_interval_ms{20};  // 1..10000: the thread takes the queue this often (not per frame)
};

struct BusCaptureResult {
  std::uint64_t frames{0};         // lines written
  std::uint64_t kernel_drops{0};   // frames the kernel dropped from the capture's full queue
  std::uint64_t steps_back{0};     // frames stamped earlier than the frame before them
  std::uint64_t first_us{0}, last_us{0};  // the first and last frames' timestamps (0: none)
  std::string error;               // why the capture is incomplete: a receive or write failed
  [[nodiscard]] bool complete() const { return error.empty() && kernel_drops == 0; }
};

class BusCapture {
 public:
  BusCapture() = default;
  BusCapture(const BusCapture&) = delete;
  BusCapture& operator=(const BusCapture&) = delete;
  ~BusCapture();

  // Opens the socket on `iface` and the log at `path` and starts draining; "" when capturing,
  // otherwise why not (nothing then runs).
  [[nodiscard]] std::string start(const std::string& iface, const std::string& path,
                                  const BusCaptureOptions& options = {});
  [[nodiscard]] bool running() const { return thread_.joinable(); }
  // Takes what is queued, stops the thread and closes the log. Once only; later calls return the
  // same result.
  BusCaptureResult stop();

 private:
  void run();
  void drain();

  SocketCanBus bus_;
  CandumpFile file_;
  BusCaptureOptions options_{};
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_{false};  // under mutex_
  BusCaptureResult result_{};  // the thread's until it is joined
  bool failed_{false};
};

}  // namespace settle::hal
