// SPDX-License-Identifier: Apache-2.0
#pragma once
// Files a CLI test writes for the command to read, in a directory of the suite's own (per process).
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace settle::test {

inline std::filesystem::path scratch_dir(const std::string& suite) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("settle_" + suite + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

// Writes `text` to scratch_dir(suite)/name and returns the path.
inline std::string write_scratch(const std::string& suite, const std::string& name, const std::string& text) {
  const std::filesystem::path p = scratch_dir(suite) / name;
  std::ofstream{p} << text;
  return p.string();
}

}  // namespace settle::test
