// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/candump_file.hpp"

#include <array>
#include <cstring>
#include <ctime>
#include <new>

#include "settle/hal/candump_log.hpp"

namespace settle::hal {

std::uint64_t realtime_us() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000U + static_cast<std::uint64_t>(ts.tv_nsec) / 1000U;
}

CandumpFile::~CandumpFile() {
  if (file_ != nullptr) (void)close();
}

bool CandumpFile::open(const char* path, const char* iface) noexcept {
  if (file_ != nullptr || path == nullptr || iface == nullptr || std::strlen(iface) >= sizeof iface_ || iface[0] == '\0') {
    return false;
  }
  buffer_.reset(new (std::nothrow) char[buffer_bytes]);
  if (!buffer_) return false;
  file_ = std::fopen(path, "w");
  if (file_ == nullptr) return false;
  if (std::setvbuf(file_, buffer_.get(), _IOFBF, buffer_bytes) != 0) {
    std::fclose(file_);
    file_ = nullptr;
    return false;
  }
  std::memcpy(iface_, iface, std::strlen(iface) + 1);
  lines_ = 0;
  lost_ = 0;
  ok_ = true;
  return true;
}

bool CandumpFile::write(const CanFrame& frame) noexcept {
  std::array<char, candump_line_max + 1> line{};
  const std::size_t n = format_candump_line(frame, iface_, std::span<char>{line.data(), candump_line_max});
  if (file_ == nullptr || n == 0) {
    ok_ = false;
    return false;
  }
  line[n] = '\n';
  if (std::fwrite(line.data(), 1, n + 1, file_) != n + 1) {
    ok_ = false;
    return false;
  }
  ++lines_;
  return true;
}

bool CandumpFile::close() noexcept {
  if (file_ == nullptr) return false;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  return closed && ok_ && lost_ == 0;
}

}  // namespace settle::hal
