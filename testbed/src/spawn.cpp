// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/spawn.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <utility>
#include <ctime>

extern char** environ;

namespace settle::testbed {

const char* to_string(SpawnStatus s) noexcept {
  switch (s) {
    case SpawnStatus::ok: return "ok";
    case SpawnStatus::not_found: return "not_found";
    case SpawnStatus::bad_request: return "bad_request";
    case SpawnStatus::spawn_failed: return "spawn_failed";
    case SpawnStatus::input_failed: return "input_failed";
    case SpawnStatus::wait_failed: return "wait_failed";
    case SpawnStatus::exit_nonzero: return "exit_nonzero";
    case SpawnStatus::killed: return "killed";
    case SpawnStatus::output_failed: return "output_failed";
  }
  return "unknown";
}

namespace {

// Owns the spawn attribute and file-action objects for the length of one call.
struct SpawnSetup {
  posix_spawn_file_actions_t actions{};
  posix_spawnattr_t attr{};
  bool have_actions{false}, have_attr{false};
  SpawnSetup() = default;
  SpawnSetup(const SpawnSetup&) = delete;
  SpawnSetup& operator=(const SpawnSetup&) = delete;
  ~SpawnSetup() {
    if (have_actions) posix_spawn_file_actions_destroy(&actions);
    if (have_attr) posix_spawnattr_destroy(&attr);
  }
};

void close_fd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

// Writes all of `data` to `fd` with SIGPIPE blocked in this thread, so a reader that exits early
// gives EPIPE instead of killing the caller; a SIGPIPE raised meanwhile is consumed before the
// mask is restored. False if not everything was written.
bool write_all_no_sigpipe(int fd, std::string_view data) {
  sigset_t pipe_set, old_set;
  sigemptyset(&pipe_set);
  sigaddset(&pipe_set, SIGPIPE);
  sigset_t pending;
  sigemptyset(&pending);
  sigpending(&pending);
  const bool was_pending = sigismember(&pending, SIGPIPE) == 1;
  pthread_sigmask(SIG_BLOCK, &pipe_set, &old_set);
  bool ok = true;
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ok = false;
      break;
    }
    done += static_cast<std::size_t>(n);
  }
  if (!ok && !was_pending) {
    const timespec zero{};
    while (sigtimedwait(&pipe_set, nullptr, &zero) == -1 && errno == EINTR) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old_set, nullptr);
  return ok;
}

}  // namespace

namespace {

// An output file of the child, opened here (close-on-exec; the child gets a dup2'd copy) so that
// a path that cannot be created is told apart from a program that cannot be found.
int open_output(const std::string& path) {
  int fd = -1;
  do {
    fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  } while (fd < 0 && errno == EINTR);
  return fd;
}

// The status of an ended child, as run_program reports it.
SpawnResult result_of(int wstatus, bool input_written) {
  SpawnResult r{};
  if (WIFSIGNALED(wstatus)) {
    r.status = SpawnStatus::killed;
    r.signal = WTERMSIG(wstatus);
  } else if (WIFEXITED(wstatus) && WEXITSTATUS(wstatus) != 0) {
    r.status = SpawnStatus::exit_nonzero;
    r.exit_code = WEXITSTATUS(wstatus);
  } else if (!input_written) {
    r.status = SpawnStatus::input_failed;
    r.error = EPIPE;
  }
  return r;
}

}  // namespace

SpawnResult start_program(const std::vector<std::string>& argv, const SpawnOptions& opt, ChildProcess& out) {
  SpawnResult r{};
  if (argv.empty() || argv[0].empty() || (opt.output == SpawnOutput::to_file && opt.output_file.empty())) {
    r.status = SpawnStatus::bad_request;
    r.error = EINVAL;
    return r;
  }
  if (!opt.workdir.empty()) {
    // Checked here so that a failing chdir in the child is not mistaken for a missing program.
    struct stat st{};
    if (::stat(opt.workdir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
      r.status = SpawnStatus::bad_request;
      r.error = ENOTDIR;
      return r;
    }
  }
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);

  int out_fd = -1, err_fd = -1;
  if (opt.output == SpawnOutput::to_file && (out_fd = open_output(opt.output_file)) < 0) {
    r.status = SpawnStatus::output_failed;
    r.error = errno;
    return r;
  }
  if (!opt.error_file.empty() && (err_fd = open_output(opt.error_file)) < 0) {
    r.status = SpawnStatus::output_failed;
    r.error = errno;
    close_fd(out_fd);
    return r;
  }
  int fds[2] = {-1, -1};
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    r.status = SpawnStatus::spawn_failed;
    r.error = errno;
    close_fd(out_fd);
    close_fd(err_fd);
    return r;
  }
  SpawnSetup s;
  int rc = posix_spawn_file_actions_init(&s.actions);
  s.have_actions = rc == 0;
  if (rc == 0) rc = posix_spawnattr_init(&s.attr);
  s.have_attr = s.have_actions && rc == 0;
  // The child's stdin is the pipe's read end (dup2 clears close-on-exec on the copy; both
  // originals close at exec). Its stderr is redirected before stdout may be made a copy of it.
  if (rc == 0) rc = posix_spawn_file_actions_adddup2(&s.actions, fds[0], STDIN_FILENO);
  if (rc == 0 && err_fd >= 0) rc = posix_spawn_file_actions_adddup2(&s.actions, err_fd, STDERR_FILENO);
  if (rc == 0 && opt.output == SpawnOutput::to_stderr) {
    rc = posix_spawn_file_actions_adddup2(&s.actions, STDERR_FILENO, STDOUT_FILENO);
  } else if (rc == 0 && opt.output == SpawnOutput::discard) {
    rc = posix_spawn_file_actions_addopen(&s.actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  } else if (rc == 0 && opt.output == SpawnOutput::to_file) {
    rc = posix_spawn_file_actions_adddup2(&s.actions, out_fd, STDOUT_FILENO);
  }
  if (rc == 0 && !opt.workdir.empty()) rc = posix_spawn_file_actions_addchdir_np(&s.actions, opt.workdir.c_str());
  // The child starts with no blocked signals and SIGPIPE at its default, whatever the caller set.
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  if (rc == 0) rc = posix_spawnattr_setsigmask(&s.attr, &none);
  if (rc == 0) rc = posix_spawnattr_setsigdefault(&s.attr, &defaults);
  if (rc == 0) rc = posix_spawnattr_setflags(&s.attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  pid_t pid = -1;
  if (rc == 0) rc = posix_spawnp(&pid, args[0], &s.actions, &s.attr, args.data(), environ);
  close_fd(fds[0]);
  close_fd(out_fd);
  close_fd(err_fd);
  if (rc != 0) {
    close_fd(fds[1]);
    r.status = rc == ENOENT || rc == EACCES || rc == ENOEXEC ? SpawnStatus::not_found : SpawnStatus::spawn_failed;
    r.error = rc;
    return r;
  }
  ChildProcess child;
  child.pid_ = pid;
  child.input_written_ = write_all_no_sigpipe(fds[1], opt.input);
  close_fd(fds[1]);
  out = std::move(child);
  return r;
}

SpawnResult run_program(const std::vector<std::string>& argv, const SpawnOptions& opt) {
  ChildProcess child;
  const SpawnResult r = start_program(argv, opt, child);
  if (r.status != SpawnStatus::ok) return r;
  return child.wait();
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && !ended_) {
    ::kill(pid_, SIGKILL);
    (void)wait();
  }
}

ChildProcess::ChildProcess(ChildProcess&& other) noexcept
    : pid_{other.pid_}, ended_{other.ended_}, input_written_{other.input_written_}, result_{other.result_} {
  other.pid_ = -1;
}

ChildProcess& ChildProcess::operator=(ChildProcess&& other) noexcept {
  if (this != &other) {
    if (pid_ > 0 && !ended_) {
      ::kill(pid_, SIGKILL);
      (void)wait();
    }
    pid_ = other.pid_;
    ended_ = other.ended_;
    input_written_ = other.input_written_;
    result_ = other.result_;
    other.pid_ = -1;
  }
  return *this;
}

bool ChildProcess::reap(int options) noexcept {
  if (pid_ <= 0 || ended_) return true;
  int wstatus = 0;
  pid_t w = -1;
  do {
    w = ::waitpid(pid_, &wstatus, options);
  } while (w < 0 && errno == EINTR);
  if (w == 0) return false;
  ended_ = true;
  result_ = w < 0 ? SpawnResult{SpawnStatus::wait_failed, 0, 0, errno} : result_of(wstatus, input_written_);
  return true;
}

bool ChildProcess::running() noexcept { return !reap(WNOHANG); }

void ChildProcess::signal(int sig) noexcept {
  if (pid_ > 0 && !ended_) ::kill(pid_, sig);
}

SpawnResult ChildProcess::wait() noexcept {
  (void)reap(0);
  return result_;
}

}  // namespace settle::testbed
