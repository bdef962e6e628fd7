// SPDX-License-Identifier: Apache-2.0
// Support for the vcan suites: a monotonic clock, child processes (the peer node, candump)
// and the skip message when no vcan0 exists (run them through tools/with-vcan).
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "settle/hal/socketcan_bus.hpp"

extern char** environ;

namespace settle::hal::test {

inline constexpr const char* vcan_interface = "vcan0";
inline constexpr const char* vcan_missing =
    "vcan0 is not present: run the vcan suites through tools/with-vcan (it brings one up)";

inline bool vcan_present() { return CanInterface{vcan_interface}.exists(); }

inline std::uint64_t monotonic_us() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
          .count());
}

// Throughput through vcan is measured with flow control: vcan has none (a receiver that
// falls behind simply loses frames, counted as drops), so the sender keeps at most `window`
// frames unacknowledged and the receiver acknowledges every `ack_every` frames with its count.
struct FlowResult {
  std::uint64_t frames{0};
  std::uint64_t busy{0};
  double seconds{0};
  bool complete{false};
  [[nodiscard]] double frames_per_second() const { return seconds > 0 ? static_cast<double>(frames) / seconds : 0; }
};

inline constexpr std::uint64_t flow_window = 256;
inline constexpr std::uint64_t flow_ack_every = 64;

inline CanFrame counted_frame(std::uint32_t id, std::uint64_t n) {
  CanFrame f{};
  f.id = id;
  f.len = 8;
  std::memcpy(f.data.data(), &n, sizeof n);
  return f;
}

inline std::uint64_t count_of(const CanFrame& f) {
  std::uint64_t n = 0;
  std::memcpy(&n, f.data.data(), sizeof n);
  return n;
}

inline bool listen_only_to(CanBus& bus, std::uint32_t id) {
  const CanFilter only{id, 0x7FF, FrameFormat::standard};
  return bus.set_filters({&only, 1}) == BusStatus::ok;
}

inline FlowResult send_windowed(CanBus& bus, std::uint32_t data_id, std::uint32_t ack_id, std::uint64_t count) {
  FlowResult r{};
  if (!listen_only_to(bus, ack_id)) {
    return r;
  }
  std::uint64_t acked = 0;
  CanFrame ack{};
  const std::uint64_t t0 = monotonic_us();
  while (acked < count) {
    // Acknowledgements are read when half the window is out, not after every frame: each
    // poll is a system call, and under user-mode-linux system calls are what costs.
    if (r.frames - acked >= flow_window / 2) {
      while (bus.receive(ack) == ReceiveStatus::received) {
        acked = std::max(acked, count_of(ack));
      }
    }
    if (r.frames < count && r.frames - acked < flow_window) {
      const SendStatus s = bus.send(counted_frame(data_id, r.frames));
      if (s == SendStatus::sent) {
        ++r.frames;
      } else if (s == SendStatus::busy) {
        ++r.busy;
        std::this_thread::yield();
      } else {
        return r;
      }
    } else if (acked < count) {
      if (bus.receive(ack, 2'000'000) != ReceiveStatus::received) {
        return r;  // no progress for two seconds: frames were lost
      }
      acked = std::max(acked, count_of(ack));
    }
  }
  r.seconds = static_cast<double>(monotonic_us() - t0) * 1e-6;
  r.complete = true;
  return r;
}

inline FlowResult receive_acking(CanBus& bus, std::uint32_t data_id, std::uint32_t ack_id, std::uint64_t count) {
  FlowResult r{};
  if (!listen_only_to(bus, data_id)) {
    return r;
  }
  CanFrame f{};
  std::uint64_t t0 = 0;
  while (r.frames < count) {
    if (bus.receive(f, 2'000'000) != ReceiveStatus::received) {
      return r;
    }
    if (r.frames++ == 0) {
      t0 = monotonic_us();
    }
    if (r.frames % flow_ack_every == 0 || r.frames == count) {
      while (bus.send(counted_frame(ack_id, r.frames)) == SendStatus::busy) {
        ++r.busy;
        std::this_thread::yield();
      }
    }
  }
  r.seconds = static_cast<double>(monotonic_us() - t0) * 1e-6;
  r.complete = true;
  return r;
}

// A child process with its stdout in a file (so nothing can block on a full pipe).
class Child {
 public:
  Child() = default;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() { stop(SIGKILL); }

  bool start(const std::vector<std::string>& argv, const std::string& stdout_path) {
    std::vector<char*> args;
    for (const std::string& a : argv) {
      args.push_back(const_cast<char*>(a.c_str()));
    }
    args.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int rc = posix_spawnp(&pid_, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
      pid_ = -1;
    }
    return rc == 0;
  }

  // Sends the signal (unless 0) and reaps the child; returns its exit status or -signal.
  int stop(int signal) {
    if (pid_ <= 0) {
      return status_;
    }
    if (signal != 0) {
      ::kill(pid_, signal);
    }
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
    return status_;
  }
  int wait() { return stop(0); }

 private:
  pid_t pid_{-1};
  int status_{-1};
};

}  // namespace settle::hal::test
