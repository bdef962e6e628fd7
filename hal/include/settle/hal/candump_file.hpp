// SPDX-License-Identifier: Apache-2.0
// A candump log file (`candump -L` format, replayable with canplayer) written by the process that
// sends and receives the frames: with a RecordingBus in front of the process's bus, the log holds
// every frame the process sent and every frame it received, and says so when it could not (a
// full record ring, a failed write). Host only (stdio); the records are taken and written
// outside the timed servo tick.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/recording_bus.hpp"

namespace settle::hal {

// CLOCK_REALTIME in µs: the clock of SocketCanBus's receive timestamps (SO_TIMESTAMP), so the
// frames a process sends can be stamped on the same time base as those it receives.
[[nodiscard]] std::uint64_t realtime_us() noexcept;

class CandumpFile {
 public:
  CandumpFile() noexcept = default;
  CandumpFile(const CandumpFile&) = delete;
  CandumpFile& operator=(const CandumpFile&) = delete;
  ~CandumpFile();

  // Creates (truncates) the file; iface is the interface name written on every line. The file's
  // buffer (4 MB, about 100 000 lines) is allocated here, so writing lines between servo ticks
  // copies memory and reaches the file system only once in that many lines.
  [[nodiscard]] bool open(const char* path, const char* iface) noexcept;
  [[nodiscard]] bool is_open() const noexcept { return file_ != nullptr; }

  // One line per frame; false once anything failed to be written.
  bool write(const CanFrame& frame) noexcept;
  // Every record the bus holds, oldest first; also notes the records the bus could not keep.
  template <std::size_t N>
  bool write_records(RecordingBus<N>& bus) noexcept {
    for (RecordedFrame r{}; bus.take(r);) (void)write(r.frame);
    lost_ = bus.overflows();
    return ok_;
  }
  // Flushes and closes; true when every line was written and no record was lost.
  [[nodiscard]] bool close() noexcept;

  [[nodiscard]] std::uint64_t lines() const noexcept { return lines_; }
  [[nodiscard]] std::uint64_t records_lost() const noexcept { return lost_; }

 private:
  static constexpr std::size_t buffer_bytes = 4U << 20U;
  std::unique_ptr<char[]> buffer_;
  std::FILE* file_{nullptr};
  char iface_[16]{};
  std::uint64_t lines_{0};
  std::uint64_t lost_{0};
  bool ok_{true};
};

}  // namespace settle::hal
