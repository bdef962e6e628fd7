#pragma once
// Runs a helper program (gnuplot) without a shell: posix_spawnp with an argument vector (the PATH
// search is posix_spawnp's own), the input written to its standard input through a pipe, then
// waited for and its exit status checked. No string is ever interpreted by a shell, so a path or a
// title with quotes, spaces or semicolons is just bytes. The one place sim starts a process.
#include <cstdint>
#include <string>
#include <vector>

namespace settle::sim {

enum class SpawnStatus : std::uint8_t {
  ok = 0,         // it ran and exited with status 0
  not_found,      // no such program on the PATH, or not executable
  bad_request,    // an empty argument vector, or a working directory that is not a directory
  spawn_failed,   // the pipe or posix_spawnp failed otherwise (SpawnResult::error holds errno)
  input_failed,   // it exited 0 without reading all its input
  wait_failed,    // waitpid failed (SpawnResult::error)
  exit_nonzero,   // it exited with a non-zero status (SpawnResult::exit_code)
  killed,         // a signal ended it (SpawnResult::signal)
};
[[nodiscard]] const char* to_string(SpawnStatus s) noexcept;

// Where the program's standard output goes. Its standard error is always the caller's.
enum class SpawnOutput : std::uint8_t {
  to_stderr,  // to the caller's standard error: keeps the caller's stdout (JSON, tables) clean
  discard,    // to /dev/null
  inherit,    // the caller's standard output
};

struct SpawnOptions {
  std::string workdir;     // empty: the caller's working directory
  std::string input;       // written to its standard input, which is then closed
  SpawnOutput output{SpawnOutput::to_stderr};
};

struct SpawnResult {
  SpawnStatus status{SpawnStatus::ok};
  int exit_code{0};
  int signal{0};
  int error{0};  // errno of the failing call
};

// argv[0] is looked up on the PATH. Blocks until the program has ended.
[[nodiscard]] SpawnResult run_program(const std::vector<std::string>& argv, const SpawnOptions& opt);

}  // namespace settle::sim
