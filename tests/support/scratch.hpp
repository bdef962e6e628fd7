// SPDX-License-Identifier: Apache-2.0
#pragma once
// Files a test writes (for a command to read, or a command writes for the test to read) go in one
// directory of this process's own under the system's temporary directory, removed with everything
// in it when the process exits: a run of the suites leaves nothing behind in /tmp.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace settle::test {

inline const std::filesystem::path& scratch_dir() {
  struct Dir {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("settle_test_" + std::to_string(::getpid()));
    Dir() { std::filesystem::create_directories(path); }
    Dir(const Dir&) = delete;
    Dir& operator=(const Dir&) = delete;
    ~Dir() {
      std::error_code ignored;  // a test that left a file open must not turn exit into a crash
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Dir dir;
  return dir.path;
}

// scratch_dir()/name as a string.
inline std::string scratch_path(const std::string& name) { return (scratch_dir() / name).string(); }

// Writes `text` (bytes as they are) to scratch_dir()/name and returns the path.
inline std::string write_scratch(const std::string& name, const std::string& text) {
  const std::string p = scratch_path(name);
  std::ofstream{p, std::ios::binary} << text;
  return p;
}

}  // namespace settle::test
