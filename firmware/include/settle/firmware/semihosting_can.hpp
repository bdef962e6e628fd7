// SPDX-License-Identifier: Apache-2.0
#pragma once
// The semihosting end of the CAN log: a line sink for CandumpTapBus that buffers candump lines
// and writes them to a host file through semihosting (one SYS_WRITE per few KiB, not per frame:
// each call traps into the debugger or QEMU). hal stays I/O-free; this adapter is firmware's.
#include <array>
#include <cstddef>
#include <string_view>

#include "settle/firmware/candump_tap.hpp"
#include "settle/firmware/semihosting.hpp"

namespace settle::firmware {

class SemihostingLineSink {
 public:
  static constexpr std::size_t kBuffer = 512;

  // The path is relative to QEMU's working directory.
  [[nodiscard]] bool open(std::string_view path) {
    file_ = semihosting::File::open(path, semihosting::OpenMode::write);
    ok_ = file_.is_open();
    return ok_;
  }
  void line(std::string_view text) {
    if (size_ + text.size() > buf_.size()) flush();
    for (const char c : text) buf_[size_++] = c;  // a line is at most hal::candump_line_max + 1
  }
  void flush() {
    if (size_ != 0 && !file_.write(buf_.data(), size_)) ok_ = false;
    size_ = 0;
  }
  // Flushes and closes; true when every byte reached the host file.
  [[nodiscard]] bool close() {
    flush();
    if (!file_.close()) ok_ = false;
    return ok_;
  }

 private:
  semihosting::File file_{};
  std::array<char, kBuffer> buf_{};
  std::size_t size_{0};
  bool ok_{false};
};

using SemihostingCanBus = CandumpTapBus<SemihostingLineSink>;

}  // namespace settle::firmware
