// SPDX-License-Identifier: Apache-2.0
// Little-endian field access, the byte order of every CANopen payload. Written with shifts
// so the same code is right on any host and any microcontroller.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
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

// The same reads and writes at an address the caller knows to be aligned to Align bytes (a
// CanFrame's payload is word-aligned, so its byte k is aligned to the largest power of two that
// divides k, up to 4). On a little-endian target they are loads and stores of that width instead
// of single bytes: a Cortex-M0 cannot access an unaligned word and would assemble it byte by byte.
template <typename T, std::size_t Align>
[[nodiscard]] constexpr T load_le(const std::uint8_t* p) noexcept {
  static_assert(std::is_unsigned_v<T> && (sizeof(T) == 2 || sizeof(T) == 4));
  static_assert(Align == 1 || Align == 2 || Align == 4);
  if (std::is_constant_evaluated() || std::endian::native != std::endian::little) {
    return static_cast<T>(get_le({p, sizeof(T)}, sizeof(T)));
  }
  if constexpr (sizeof(T) == 4 && Align == 2) {  // two half-words (a library memcpy otherwise)
    return static_cast<T>(load_le<std::uint16_t, 2>(p) | (std::uint32_t{load_le<std::uint16_t, 2>(p + 2)} << 16U));
  } else {
    T v;
    std::memcpy(&v, __builtin_assume_aligned(p, Align), sizeof(T));
    return v;
  }
}
template <typename T, std::size_t Align>
constexpr void store_le(std::uint8_t* p, T v) noexcept {
  static_assert(std::is_unsigned_v<T> && (sizeof(T) == 2 || sizeof(T) == 4));
  static_assert(Align == 1 || Align == 2 || Align == 4);
  if (std::is_constant_evaluated() || std::endian::native != std::endian::little) {
    put_le({p, sizeof(T)}, v, sizeof(T));
    return;
  }
  if constexpr (sizeof(T) == 4 && Align == 2) {
    store_le<std::uint16_t, 2>(p, static_cast<std::uint16_t>(v));
    store_le<std::uint16_t, 2>(p + 2, static_cast<std::uint16_t>(v >> 16U));
  } else {
    std::memcpy(__builtin_assume_aligned(p, Align), &v, sizeof(T));
  }
}

// Sign-extends the low `bits` bits of a raw value (how an INTEGER8/16 arrives in a u32 cell).
[[nodiscard]] constexpr std::int32_t sign_extend(std::uint32_t raw, unsigned bits) noexcept {
  const std::uint32_t sign = 1U << (bits - 1U);
  const std::uint32_t mask = bits >= 32U ? 0xFFFF'FFFFU : ((1U << bits) - 1U);
  const std::uint32_t v = raw & mask;
  return static_cast<std::int32_t>((v ^ sign) - sign);
}

}  // namespace settle::hal::canopen
