// Support for the vcan suites: a monotonic clock, child processes (the peer node, candump)
// and the skip message when no vcan0 exists (run them through tools/with-vcan).
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <string>
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
