// SPDX-License-Identifier: Apache-2.0
// One line of a can-utils log file (`candump -L`, replayable with `canplayer`):
//   (1700000000.123456) vcan0 123#DEADBEEF      classic, standard id
//   (1700000000.123457) vcan0 12345678#01       extended id (eight hex digits)
//   (1700000000.123458) vcan0 123#R             remote request (R<len> when len > 0)
//   (1700000000.123459) vcan0 123##1DEADBEEF    FD; the digit after ## is the BRS/ESI flags
// Formatting and parsing only, no file access, so it runs wherever a bus log is written.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "settle/hal/can_frame.hpp"

namespace settle::hal {

inline constexpr std::size_t candump_line_max = 200;  // "(sec.usec) ifname id##f" + 128 hex digits
inline constexpr std::size_t candump_iface_max = 16;  // IFNAMSIZ, including the terminator

struct CandumpRecord {
  CanFrame frame{};  // frame.timestamp_us carries the log's timestamp
  std::array<char, candump_iface_max> iface{};  // NUL-terminated
};

// Writes the line without a newline or terminator; returns its length, or 0 when the frame
// is invalid, the interface name too long, or the buffer too small.
[[nodiscard]] std::size_t format_candump_line(const CanFrame& frame, const char* iface, std::span<char> out) noexcept;

// Parses one line (a trailing newline is allowed). Malformed lines give nullopt.
[[nodiscard]] std::optional<CandumpRecord> parse_candump_line(std::span<const char> line) noexcept;

}  // namespace settle::hal
