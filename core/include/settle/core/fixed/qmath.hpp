// SPDX-License-Identifier: Apache-2.0
#pragma once
// Integer building blocks of the fixed-point evaluators: the one product the tick path needs
// (a 64-bit value times a 32-bit factor, floor-shifted), rounding, saturation and shifts. Every
// operation has one exact definition, so x86-64, aarch64 and the Cortex-M images compute the same
// integers whichever code path (128-bit or 32x32->64 pieces) the compiler takes.
#include <cstdint>
#include <type_traits>

namespace settle::core::fixed {

// Widening 32x32 -> 64 products. ARMv6-M (Cortex-M0) multiplies only 32x32 -> 32 and GCC turns
// a widening product into a call to the general 64x64 __aeabi_lmul; four 16x16 products inline
// cost half as much. Elsewhere the plain product is one instruction (UMULL, SMULL, IMUL).
// The cross products are added as 64-bit values shifted by 16, which Thumb-1 does with
// shifts and one ADDS/ADCS pair each (22 instructions, where summing 16-bit columns took 26).
[[nodiscard]] constexpr std::uint64_t umul_wide_halves(std::uint32_t a, std::uint32_t b) noexcept {
  const std::uint32_t al = a & 0xFFFFU, ah = a >> 16, bl = b & 0xFFFFU, bh = b >> 16;
  std::uint64_t p = (static_cast<std::uint64_t>(ah * bh) << 32) | (al * bl);
  p += static_cast<std::uint64_t>(al * bh) << 16;
  p += static_cast<std::uint64_t>(ah * bl) << 16;
  return p;
}

// Signed by unsigned and signed by signed from the unsigned halves product: a negative operand x
// enters as x + 2^32, so subtract the other operand times 2^32 (mod 2^64, exact).
[[nodiscard]] constexpr std::int64_t mul_wide_halves(std::int32_t a, std::uint32_t b) noexcept {
  std::uint64_t p = umul_wide_halves(static_cast<std::uint32_t>(a), b);
  if (a < 0) p -= static_cast<std::uint64_t>(b) << 32;
  return static_cast<std::int64_t>(p);
}
[[nodiscard]] constexpr std::int64_t mul_wide_halves(std::int32_t a, std::int32_t b) noexcept {
  std::uint64_t p = umul_wide_halves(static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b));
  if (a < 0) p -= static_cast<std::uint64_t>(static_cast<std::uint32_t>(b)) << 32;
  if (b < 0) p -= static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32;
  return static_cast<std::int64_t>(p);
}

// x w modulo 2^64 (int64 multiplication's bits, without its overflow) for a small factor w < 2^16,
// from three 32-bit products: x = hi 2^32 + mid 2^16 + low, and hi w matters only mod 2^32.
[[nodiscard]] constexpr std::int64_t mul_small_halves(std::int64_t x, std::uint32_t w) noexcept {
  const auto u = static_cast<std::uint64_t>(x);
  const auto hi = static_cast<std::uint32_t>(u >> 32U);
  const auto lo = static_cast<std::uint32_t>(u);
  const std::uint64_t low = std::uint64_t{(lo & 0xFFFFU) * w} + (std::uint64_t{(lo >> 16U) * w} << 16U);
  return static_cast<std::int64_t>((std::uint64_t{hi * w} << 32U) + low);
}

#if defined(__ARM_ARCH_6M__) || defined(SETTLE_FIXED_MUL_HALVES)
// GCC calls the general 64x64 __aeabi_lmul (~45 instructions with the call) for any int64 product.
[[nodiscard]] constexpr std::int64_t mul_small(std::int64_t x, std::uint32_t w) noexcept {
  return mul_small_halves(x, w);
}
[[nodiscard]] constexpr std::uint64_t umul_wide(std::uint32_t a, std::uint32_t b) noexcept {
  return umul_wide_halves(a, b);
}
[[nodiscard]] constexpr std::int64_t mul_wide(std::int32_t a, std::uint32_t b) noexcept { return mul_wide_halves(a, b); }
[[nodiscard]] constexpr std::int64_t mul_wide(std::int32_t a, std::int32_t b) noexcept { return mul_wide_halves(a, b); }
#else
[[nodiscard]] constexpr std::int64_t mul_small(std::int64_t x, std::uint32_t w) noexcept {
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(x) * w);
}
[[nodiscard]] constexpr std::uint64_t umul_wide(std::uint32_t a, std::uint32_t b) noexcept {
  return static_cast<std::uint64_t>(a) * b;
}
[[nodiscard]] constexpr std::int64_t mul_wide(std::int32_t a, std::uint32_t b) noexcept {
  return static_cast<std::int64_t>(a) * static_cast<std::int64_t>(b);
}
[[nodiscard]] constexpr std::int64_t mul_wide(std::int32_t a, std::int32_t b) noexcept {
  return static_cast<std::int64_t>(a) * b;
}
#endif

// Exact floor(a * b / 2^sh) from 32x32->64 partial products (the form a Cortex-M0, which has no
// 64-bit multiply, can run): a = hi 2^32 + lo with lo unsigned, so a b = (hi b) 2^32 + lo b
// exactly, and nested floor divisions by powers of two are exact. The result must fit int64
// (callers guarantee it from their formats); shifts of 96 and more give the sign (0 or -1).
template <typename Factor>
[[nodiscard]] constexpr std::int64_t mul_shr_pieces(std::int64_t a, Factor b, unsigned sh) noexcept {
  static_assert(sizeof(Factor) == 4, "a 32-bit factor");
  // Exact operand types: on arm-none-eabi std::uint32_t is unsigned long, not unsigned int.
  using Wide32 = std::conditional_t<std::is_signed_v<Factor>, std::int32_t, std::uint32_t>;
  const std::int64_t hi = mul_wide(static_cast<std::int32_t>(a >> 32), static_cast<Wide32>(b));
  const auto low = static_cast<std::uint32_t>(a);
  // lo b: below 2^64 unsigned for an unsigned factor, within int64 for a signed one.
  std::uint64_t lo_shifted = 0;  // floor(lo b / 2^min(sh, 32)) as a two's complement pattern
  std::int64_t lo_top = 0;       // floor(lo b / 2^32)
  if constexpr (std::is_signed_v<Factor>) {
    // low (unsigned) times b (signed): the unsigned product less 2^32 low when b < 0.
    std::uint64_t u = umul_wide(low, static_cast<std::uint32_t>(b));
    if (b < 0) u -= static_cast<std::uint64_t>(low) << 32;
    const auto lo = static_cast<std::int64_t>(u);
    lo_shifted = static_cast<std::uint64_t>(lo >> (sh < 32U ? sh : 32U));
    lo_top = lo >> 32;
  } else {
    const std::uint64_t lo = umul_wide(low, b);
    lo_shifted = lo >> (sh < 32U ? sh : 32U);
    lo_top = static_cast<std::int64_t>(lo >> 32);
  }
  if (sh <= 32U) {
    // Modular uint64 arithmetic: the true result fits int64, so the wrap-around cancels.
    return static_cast<std::int64_t>((static_cast<std::uint64_t>(hi) << (32U - sh)) + lo_shifted);
  }
  const std::int64_t top = hi + lo_top;
  return sh - 32U >= 64U ? (top < 0 ? -1 : 0) : top >> (sh - 32U);
}

// The same value, with a 128-bit product where the compiler has one (x86-64, aarch64). Define
// SETTLE_FIXED_NO_INT128 (and SETTLE_FIXED_MUL_HALVES) to run the host through the pieces (and
// the 16-bit halves), as a Cortex-M4 (and an M0) does.
template <typename Factor>
[[nodiscard]] constexpr std::int64_t mul_shr(std::int64_t a, Factor b, unsigned sh) noexcept {
#if defined(__SIZEOF_INT128__) && !defined(SETTLE_FIXED_NO_INT128)
  __extension__ typedef __int128 i128;
  if (sh >= 96U) {  // |a b| < 2^95: only the sign is left
    bool negative = a < 0;
    if constexpr (std::is_signed_v<Factor>) negative = negative != (b < 0);
    return negative && a != 0 && b != 0 ? -1 : 0;
  }
  return static_cast<std::int64_t>((static_cast<i128>(a) * b) >> sh);
#else
  return mul_shr_pieces(a, b, sh);
#endif
}

// a * b * 2^-sh for a signed shift: sh < 0 scales up (the caller guarantees the result fits).
// Beyond 32 the shift is split, floor(floor(ab / 2^32) / 2^(sh-32)) being the same floor: the
// product's high word is then a fixed shift and the rest a 64-bit one, far cheaper than a
// variable shift of a 128-bit product.
template <typename Factor>
[[nodiscard]] constexpr std::int64_t mul_shift(std::int64_t a, Factor b, int sh) noexcept {
  if (sh >= 32) {
    const std::int64_t high = mul_shr(a, b, 32U);
    return sh - 32 >= 64 ? (high < 0 ? -1 : 0) : high >> (sh - 32);
  }
  if (sh >= 0) return mul_shr(a, b, static_cast<unsigned>(sh));
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(mul_shr(a, b, 0U)) << static_cast<unsigned>(-sh));
}

// x * 2^-sh (floor) for a signed shift; a left shift is modular, so it never invokes UB.
[[nodiscard]] constexpr std::int64_t shift(std::int64_t x, int sh) noexcept {
  if (sh >= 0) return sh >= 64 ? (x < 0 ? -1 : 0) : x >> sh;
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(x) << static_cast<unsigned>(-sh));
}

// x / 2^sh rounded to nearest (halves up), 1 <= sh <= 62.
[[nodiscard]] constexpr std::int64_t round_shr(std::int64_t x, unsigned sh) noexcept {
  return (x + (std::int64_t{1} << (sh - 1U))) >> sh;
}

[[nodiscard]] constexpr std::int32_t saturate_i32(std::int64_t x) noexcept {
  if (x > INT32_MAX) return INT32_MAX;
  if (x < INT32_MIN) return INT32_MIN;
  return static_cast<std::int32_t>(x);
}

// A positive real factor kept as a normalised 32-bit mantissa and a shift, value = mant 2^-exp:
// block floating point, so that small rates such as (1/ticks)^5 keep 32 significant bits.
struct Factor {
  std::uint32_t mant{0};
  std::int16_t exp{0};
};

// x * f, with the result 2^extra times finer than x (extra may be negative).
[[nodiscard]] constexpr std::int64_t apply(std::int64_t x, Factor f, int extra = 0) noexcept {
  return mul_shift(x, f.mant, f.exp - extra);
}

}  // namespace settle::core::fixed
