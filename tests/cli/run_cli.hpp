#pragma once
// Runs the settle executable (path in SETTLE_CLI) with arguments, as a user's shell would, and
// returns its exit status and combined output. Shared by the CLI suites of every area.
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace settle::test {

struct CliResult {
  int status;
  std::string out;
};

inline CliResult run_cli(const std::string& args) {
  const std::string cmd = std::string{SETTLE_CLI} + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  if (p == nullptr) return {-1, out};
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

}  // namespace settle::test
