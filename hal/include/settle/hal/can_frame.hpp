// SPDX-License-Identifier: Apache-2.0
// Settle's own CAN frame: 11/29-bit identifier, RTR, classic (8 bytes) and FD (64 bytes).
// Protocol code and the bus interface speak only this type; it is converted to the kernel's
// struct can_frame / canfd_frame inside the SocketCAN adapter and nowhere else.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace settle::hal {

// Flag bits of CanFrame::flags. Kept separate from the id so that an id is always a plain
// number and cannot be confused with the kernel's flag-carrying can_id.
namespace can_flag {
inline constexpr std::uint8_t extended = 0x01;  // 29-bit identifier
inline constexpr std::uint8_t rtr = 0x02;       // remote transmission request (classic only)
inline constexpr std::uint8_t fd = 0x04;        // CAN FD frame format
inline constexpr std::uint8_t brs = 0x08;       // FD bit-rate switch
inline constexpr std::uint8_t esi = 0x10;       // FD error state indicator
inline constexpr std::uint8_t all = extended | rtr | fd | brs | esi;
}  // namespace can_flag

inline constexpr std::uint32_t can_standard_id_max = 0x7FF;
inline constexpr std::uint32_t can_extended_id_max = 0x1FFF'FFFF;
inline constexpr std::size_t can_classic_max_len = 8;
inline constexpr std::size_t can_fd_max_len = 64;

struct CanFrame {
  std::uint32_t id{0};
  std::uint8_t flags{0};
  // Payload length in bytes (for an RTR frame: the requested length, no payload is carried).
  std::uint8_t len{0};
  // Word-aligned (the frame's size is the same, 80 bytes): a driver moves a classic payload as two
  // 32-bit words, which a Cortex-M0 can only do on aligned addresses.
  // No default member initializer: `CanFrame f{}` (and every aggregate initialization) zeroes it,
  // `CanFrame f;` leaves it indeterminate, for classic_frame(), which writes only the eight bytes a
  // classic frame carries (zeroing all 64 was ~70 instructions per frame built on a Cortex-M0).
  alignas(4) std::array<std::uint8_t, can_fd_max_len> data;
  // Receive time in microseconds on the backend's clock; 0 when the backend has none.
  // Not part of the frame's identity: operator== ignores it.
  std::uint64_t timestamp_us{0};

  [[nodiscard]] constexpr bool is_extended() const noexcept { return (flags & can_flag::extended) != 0; }
  [[nodiscard]] constexpr bool is_rtr() const noexcept { return (flags & can_flag::rtr) != 0; }
  [[nodiscard]] constexpr bool is_fd() const noexcept { return (flags & can_flag::fd) != 0; }
  [[nodiscard]] constexpr std::span<const std::uint8_t> payload() const noexcept {
    return {data.data(), is_rtr() ? 0U : (len <= can_fd_max_len ? len : can_fd_max_len)};
  }
};

// Two frames are the same on the wire when id, flags, length and the carried bytes agree;
// bytes beyond len and the receive timestamp do not matter.
[[nodiscard]] constexpr bool operator==(const CanFrame& a, const CanFrame& b) noexcept {
  if (a.id != b.id || a.flags != b.flags || a.len != b.len) {
    return false;
  }
  const auto pa = a.payload();
  const auto pb = b.payload();
  for (std::size_t i = 0; i < pa.size(); ++i) {
    if (pa[i] != pb[i]) {
      return false;
    }
  }
  return true;
}

// A classic data frame with a standard id and `len` bytes (at most 8), all eight classic payload
// bytes zero for the encoder to fill; the bytes only an FD frame carries are left unwritten (they
// are beyond len: not part of the frame, operator==). Not for FD frames: make_frame.
[[nodiscard]] inline CanFrame classic_frame(std::uint32_t id, std::uint8_t len) noexcept {
  CanFrame f;  // id, flags, len and timestamp_us from their initializers; data as below
  f.id = id;
  f.len = len;
  for (std::size_t i = 0; i < can_classic_max_len; ++i) {
    f.data[i] = 0;
  }
  return f;
}

// Payload lengths an FD frame can carry (DLC 9..15 map to 12..64 bytes).
[[nodiscard]] constexpr bool is_valid_fd_len(std::size_t len) noexcept {
  return len <= 8 || len == 12 || len == 16 || len == 20 || len == 24 || len == 32 || len == 48 ||
         len == 64;
}

[[nodiscard]] constexpr std::uint8_t can_dlc_to_len(std::uint8_t dlc) noexcept {
  constexpr std::array<std::uint8_t, 16> table{0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  return table[dlc & 0x0FU];
}

// Smallest DLC whose length holds len bytes; callers pad the frame up to can_dlc_to_len of it.
[[nodiscard]] constexpr std::uint8_t can_len_to_dlc(std::size_t len) noexcept {
  std::uint8_t dlc = 0;
  while (dlc < 15 && can_dlc_to_len(dlc) < len) {
    ++dlc;
  }
  return dlc;
}

// A frame a backend may put on the wire: id fits its format, length fits the frame type,
// RTR only on classic frames, BRS/ESI only on FD frames.
[[nodiscard]] constexpr bool is_valid(const CanFrame& f) noexcept {
  if (f.flags == 0) {  // a classic data frame with a standard id: nearly every frame, decided first
    return f.id <= can_standard_id_max && f.len <= can_classic_max_len;
  }
  if ((f.flags & ~can_flag::all) != 0) {
    return false;
  }
  if (f.id > (f.is_extended() ? can_extended_id_max : can_standard_id_max)) {
    return false;
  }
  if (f.is_fd()) {
    return !f.is_rtr() && is_valid_fd_len(f.len);
  }
  return (f.flags & (can_flag::brs | can_flag::esi)) == 0 && f.len <= can_classic_max_len;
}

// Builds a data frame with a standard id: classic when the bytes fit in eight, FD otherwise
// (is_valid then still checks that the length is one FD can carry).
[[nodiscard]] constexpr CanFrame make_frame(std::uint32_t id, std::span<const std::uint8_t> bytes) noexcept {
  CanFrame f{};
  f.id = id;
  const std::size_t n = bytes.size() <= can_fd_max_len ? bytes.size() : can_fd_max_len;
  f.len = static_cast<std::uint8_t>(n);
  if (n > can_classic_max_len) {
    f.flags = can_flag::fd;
  }
  for (std::size_t i = 0; i < n; ++i) {
    f.data[i] = bytes[i];
  }
  return f;
}

}  // namespace settle::hal
