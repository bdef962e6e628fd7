// SPDX-License-Identifier: Apache-2.0
#pragma once
// Runs a program without a shell: posix_spawnp with an argument vector (the PATH search is
// posix_spawnp's own), the input written to its standard input through a pipe, its output to the
// caller, /dev/null or a file; then waited for and its exit status checked. Either to completion
// (run_program: gnuplot) or in the background (start_program: the demo's drive and loop
// processes). No string is ever interpreted by a shell, so a path or a title with quotes, spaces
// or semicolons is just bytes. The one place sim starts a process.
#include <cstdint>
#include <string>
#include <vector>

namespace settle::testbed {

enum class SpawnStatus : std::uint8_t {
  ok = 0,         // it ran and exited with status 0
  not_found,      // no such program on the PATH, or not executable
  bad_request,    // an empty argument vector, or a working directory that is not a directory
  spawn_failed,   // the pipe or posix_spawnp failed otherwise (SpawnResult::error holds errno)
  input_failed,   // it exited 0 without reading all its input
  wait_failed,    // waitpid failed (SpawnResult::error)
  exit_nonzero,   // it exited with a non-zero status (SpawnResult::exit_code)
  killed,         // a signal ended it (SpawnResult::signal)
  output_failed,  // SpawnOptions::output_file or error_file could not be created (SpawnResult::error)
};
[[nodiscard]] const char* to_string(SpawnStatus s) noexcept;

// Where the program's standard output goes. Its standard error is always the caller's.
enum class SpawnOutput : std::uint8_t {
  to_stderr,  // to the caller's standard error: keeps the caller's stdout (JSON, tables) clean
  discard,    // to /dev/null
  inherit,    // the caller's standard output
  to_file,    // to SpawnOptions::output_file, created or truncated
};

struct SpawnOptions {
  std::string workdir;     // empty: the caller's working directory
  std::string input;       // written to its standard input, which is then closed
  SpawnOutput output{SpawnOutput::to_stderr};
  std::string output_file{};  // SpawnOutput::to_file
  std::string error_file{};   // non-empty: its standard error goes to this file (created or truncated)
};

struct SpawnResult {
  SpawnStatus status{SpawnStatus::ok};
  int exit_code{0};
  int signal{0};
  int error{0};  // errno of the failing call
};

// argv[0] is looked up on the PATH. Blocks until the program has ended.
[[nodiscard]] SpawnResult run_program(const std::vector<std::string>& argv, const SpawnOptions& opt);

// A program started by start_program. It never outlives its owner: destroyed while it still runs,
// it is killed (SIGKILL) and reaped.
class ChildProcess {
 public:
  ChildProcess() = default;
  ~ChildProcess();
  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // True while it has not ended (an ended child is reaped here, its status kept for wait()).
  [[nodiscard]] bool running() noexcept;
  // Sends `sig` to it while it runs (SIGTERM: the drive process writes its summary and exits).
  void signal(int sig) noexcept;
  // Blocks until it has ended; how it ended, as run_program reports it. Repeated calls give the
  // same result; a ChildProcess never started gives bad_request.
  [[nodiscard]] SpawnResult wait() noexcept;
  [[nodiscard]] int pid() const noexcept { return pid_; }  // -1 when never started

 private:
  friend SpawnResult start_program(const std::vector<std::string>& argv, const SpawnOptions& opt, ChildProcess& out);
  // waitpid with `options` (0 blocks, WNOHANG polls): true once it has ended (its result kept),
  // or when it was never started.
  [[nodiscard]] bool reap(int options) noexcept;
  int pid_{-1};
  bool ended_{false};
  bool input_written_{true};
  SpawnResult result_{SpawnStatus::bad_request, 0, 0, 0};
};

// Starts the program and returns once its input has been written (and its standard input
// closed): status ok and `out` holds the running child, or the reason it could not start.
[[nodiscard]] SpawnResult start_program(const std::vector<std::string>& argv, const SpawnOptions& opt,
                                        ChildProcess& out);

}  // namespace settle::testbed
