// SPDX-License-Identifier: Apache-2.0
#pragma once
// Progress of a long command (identify, drive scan) on stderr, only when stderr is a terminal: a
// person watching sees it is working; a pipe, a file or a test sees nothing extra.
#include <unistd.h>

#include <cstdarg>
#include <cstdio>

namespace settle::app {

class Progress {
 public:
  Progress() : on_{isatty(STDERR_FILENO) == 1} {}
  // One line, replacing the previous progress line ("\r", cleared to its end).
  [[gnu::format(printf, 2, 3)]] void say(const char* format, ...) const {
    if (!on_) return;
    std::va_list args;
    va_start(args, format);
    std::fputs("\r\033[K", stderr);
    std::vfprintf(stderr, format, args);
    va_end(args);
    std::fflush(stderr);
  }
  // Clears the progress line before the command's own output.
  void done() const {
    if (on_) std::fputs("\r\033[K", stderr);
  }
  [[nodiscard]] bool on() const { return on_; }

 private:
  bool on_;
};

}  // namespace settle::app
