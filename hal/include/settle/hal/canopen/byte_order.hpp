// Little-endian field access, the byte order of every CANopen payload. Written with shifts
// so the same code is right on any host and any microcontroller.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

namespace settle::hal::canopen {

// Reads an unsigned value of `bytes` bytes (1..4) starting at bytes[0].
[[nodiscard]] constexpr std::uint32_t get_le(std::span<const std::uint8_t> bytes, std::size_t n) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = n; i > 0; --i) {
    v = (v << 8U) | bytes[i - 1];
  }
  return v;
}

constexpr void put_le(std::span<std::uint8_t> bytes, std::uint32_t value, std::size_t n) noexcept {
  for (std::size_t i = 0; i < n; ++i) {
    bytes[i] = static_cast<std::uint8_t>(value >> (8U * i));
  }
}

[[nodiscard]] constexpr std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8U));
}
[[nodiscard]] constexpr std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8U) |
         (static_cast<std::uint32_t>(p[2]) << 16U) | (static_cast<std::uint32_t>(p[3]) << 24U);
}
[[nodiscard]] constexpr std::int32_t get_i32(const std::uint8_t* p) noexcept {
  return static_cast<std::int32_t>(get_u32(p));
}
constexpr void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8U);
}
constexpr void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8U);
  p[2] = static_cast<std::uint8_t>(v >> 16U);
  p[3] = static_cast<std::uint8_t>(v >> 24U);
}
constexpr void put_i32(std::uint8_t* p, std::int32_t v) noexcept { put_u32(p, static_cast<std::uint32_t>(v)); }

// Sign-extends the low `bits` bits of a raw value (how an INTEGER8/16 arrives in a u32 cell).
[[nodiscard]] constexpr std::int32_t sign_extend(std::uint32_t raw, unsigned bits) noexcept {
  const std::uint32_t sign = 1U << (bits - 1U);
  const std::uint32_t mask = bits >= 32U ? 0xFFFF'FFFFU : ((1U << bits) - 1U);
  const std::uint32_t v = raw & mask;
  return static_cast<std::int32_t>((v ^ sign) - sign);
}

}  // namespace settle::hal::canopen
