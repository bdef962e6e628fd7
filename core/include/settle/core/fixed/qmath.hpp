#pragma once
// Integer building blocks of the fixed-point evaluators: the one product the tick path needs
// (a 64-bit value times a 32-bit factor, floor-shifted), rounding, saturation and shifts. Every
// operation has one exact definition, so x86-64, aarch64 and the Cortex-M images compute the same
// integers whichever code path (128-bit or 32x32->64 pieces) the compiler takes.
#include <cstdint>
#include <type_traits>

namespace settle::core::fixed {

// Exact floor(a * b / 2^sh) from 32x32->64 partial products (the form a Cortex-M0, which has no
// 64-bit multiply, can run): a = hi 2^32 + lo with lo unsigned, so a b = (hi b) 2^32 + lo b
// exactly, and nested floor divisions by powers of two are exact. The result must fit int64
// (callers guarantee it from their formats); shifts of 96 and more give the sign (0 or -1).
template <typename Factor>
[[nodiscard]] constexpr std::int64_t mul_shr_pieces(std::int64_t a, Factor b, unsigned sh) noexcept {
  static_assert(sizeof(Factor) == 4, "a 32-bit factor");
  const std::int64_t hi = (a >> 32) * static_cast<std::int64_t>(b);
  const std::int64_t lo = static_cast<std::int64_t>(static_cast<std::uint32_t>(a)) * static_cast<std::int64_t>(b);
  if (sh <= 32) {
    // Modular uint64 arithmetic: the true result fits int64, so the wrap-around cancels.
    const std::uint64_t h = static_cast<std::uint64_t>(hi) << (32U - sh);
    return static_cast<std::int64_t>(h + static_cast<std::uint64_t>(lo >> sh));
  }
  const std::int64_t top = hi + (lo >> 32);
  return sh - 32U >= 64U ? (top < 0 ? -1 : 0) : top >> (sh - 32U);
}

// The same value, with a 128-bit product where the compiler has one (x86-64, aarch64).
template <typename Factor>
[[nodiscard]] constexpr std::int64_t mul_shr(std::int64_t a, Factor b, unsigned sh) noexcept {
#if defined(__SIZEOF_INT128__)
  __extension__ typedef __int128 i128;
  if (sh >= 96U) {  // |a b| < 2^95: only the sign is left
    bool negative = a < 0;
    if constexpr (std::is_signed_v<Factor>) negative = negative != (b < 0);
    return negative && b != 0 ? -1 : 0;
  }
  return static_cast<std::int64_t>((static_cast<i128>(a) * b) >> sh);
#else
  return mul_shr_pieces(a, b, sh);
#endif
}

// a * b * 2^-sh for a signed shift: sh < 0 scales up (the caller guarantees the result fits).
template <typename Factor>
[[nodiscard]] constexpr std::int64_t mul_shift(std::int64_t a, Factor b, int sh) noexcept {
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
