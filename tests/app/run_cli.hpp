// SPDX-License-Identifier: Apache-2.0
#pragma once
// Runs the settle executable (path in SETTLE_CLI) with an argument vector, without a shell
// (posix_spawn), and returns its exit status, standard output and standard error. Shared by the
// CLI suites of every area.
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace settle::test {

struct CliResult {
  int status;          // exit status; -1 when killed by a signal or not started
  std::string out;     // stdout followed by stderr
  std::string stdout_text;
  std::string stderr_text;
};

inline CliResult run_cli_argv(const std::vector<std::string>& args) {
  std::vector<std::string> all{SETTLE_CLI};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  int out_pipe[2];
  int err_pipe[2];
  if (pipe(out_pipe) != 0) return {-1, {}, {}, {}};
  if (pipe(err_pipe) != 0) return {-1, {}, {}, {}};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, out_pipe[1], 1);
  posix_spawn_file_actions_adddup2(&fa, err_pipe[1], 2);
  posix_spawn_file_actions_addclose(&fa, out_pipe[0]);
  posix_spawn_file_actions_addclose(&fa, err_pipe[0]);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  close(out_pipe[1]);
  close(err_pipe[1]);
  CliResult r{-1, {}, {}, {}};
  std::array<pollfd, 2> fds{pollfd{out_pipe[0], POLLIN, 0}, pollfd{err_pipe[0], POLLIN, 0}};
  std::array<std::string*, 2> sinks{&r.stdout_text, &r.stderr_text};
  int open_fds = 2;
  while (rc == 0 && open_fds > 0) {
    if (poll(fds.data(), fds.size(), -1) < 0) break;
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if (fds[i].fd < 0 || fds[i].revents == 0) continue;
      char buf[4096];
      const ssize_t n = read(fds[i].fd, buf, sizeof buf);
      if (n > 0) {
        sinks[i]->append(buf, static_cast<std::size_t>(n));
      } else {
        close(fds[i].fd);
        fds[i].fd = -1;
        --open_fds;
      }
    }
  }
  for (const pollfd& p : fds) {
    if (p.fd >= 0) close(p.fd);
  }
  if (rc != 0) return r;
  int st = 0;
  waitpid(pid, &st, 0);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.out = r.stdout_text + r.stderr_text;
  return r;
}

// The arguments split at spaces (no quoting: nothing here goes through a shell).
inline CliResult run_cli(const std::string& args) {
  std::vector<std::string> v;
  std::istringstream in{args};
  for (std::string a; in >> a;) v.push_back(a);
  return run_cli_argv(v);
}

// Help text with every run of white space (line breaks of wrapped descriptions and notes, and the
// indentation after them) as one space, so that a phrase is found whatever the wrapping.
inline std::string collapse_whitespace(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const bool space = c == ' ' || c == '\n' || c == '\t';
    if (!space) {
      out += c;
    } else if (!out.empty() && out.back() != ' ') {
      out += ' ';
    }
  }
  return out;
}

// One option's entry in --help: its line and the wrapped lines under it, collapsed to one line.
inline std::string help_entry(const std::string& help, const std::string& option) {
  std::size_t at = help.find("\n  " + option + " ");
  if (at == std::string::npos) at = help.find("\n  -h," + option);
  if (at == std::string::npos) return {};
  std::size_t end = at + 1;
  // Further lines of the entry are indented past the option column (more than two spaces).
  while ((end = help.find('\n', end)) != std::string::npos && help.compare(end + 1, 3, "   ") == 0) ++end;
  return collapse_whitespace(help.substr(at + 1, (end == std::string::npos ? help.size() : end) - at - 1));
}

}  // namespace settle::test
