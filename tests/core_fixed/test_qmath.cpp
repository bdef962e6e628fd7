// SPDX-License-Identifier: Apache-2.0
// The integer helpers are exact by definition: the 32x32-piece product (what a Cortex-M0 runs)
// must equal the true floor of the 96-bit product, and so must the 128-bit path the host uses.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "settle/core/fixed/format.hpp"
#include "settle/core/fixed/qmath.hpp"

using namespace settle::core::fixed;

namespace {

__extension__ typedef __int128 i128;

// floor(a b / 2^sh) in 128 bits, written independently of qmath.hpp.
std::int64_t exact(std::int64_t a, i128 b, unsigned sh) {
  const i128 p = static_cast<i128>(a) * b;
  if (sh >= 127U) return p < 0 ? -1 : 0;
  i128 q = p >> sh;  // arithmetic: floor
  return static_cast<std::int64_t>(q);
}

// A value whose product with b, shifted by sh, fits int64 (the contract of mul_shr).
std::int64_t fitting(std::mt19937_64& rng, unsigned sh) {
  const std::int64_t a = static_cast<std::int64_t>(rng());
  const unsigned room = sh >= 32U ? 62U : 30U + sh;  // |a| < 2^room keeps |a b| >> sh < 2^62
  return a >> (63U - room);
}

}  // namespace

TEST(FixedQmath, PieceProductIsTheExactFloorForEveryShift) {
  std::mt19937_64 rng{1};
  for (int i = 0; i < 400000; ++i) {
    const unsigned sh = static_cast<unsigned>(rng() % 128U);
    const std::int64_t a = fitting(rng, sh);
    const auto bu = static_cast<std::uint32_t>(rng());
    const auto bs = static_cast<std::int32_t>(rng());
    ASSERT_EQ(mul_shr_pieces(a, bu, sh), exact(a, bu, sh)) << a << " * " << bu << " >> " << sh;
    ASSERT_EQ(mul_shr_pieces(a, bs, sh), exact(a, bs, sh)) << a << " * " << bs << " >> " << sh;
    ASSERT_EQ(mul_shr(a, bu, sh), exact(a, bu, sh));
    ASSERT_EQ(mul_shr(a, bs, sh), exact(a, bs, sh));
  }
}

TEST(FixedQmath, ExtremesAndSigns) {
  for (unsigned sh : {0U, 1U, 31U, 32U, 33U, 63U, 64U, 95U, 96U, 127U}) {
    for (std::int64_t a : {std::int64_t{0}, std::int64_t{1}, std::int64_t{-1}, std::int64_t{INT32_MAX},
                           std::int64_t{INT32_MIN}, std::int64_t{1} << 40, -(std::int64_t{1} << 40)}) {
      for (std::int32_t b : {0, 1, -1, INT32_MAX, INT32_MIN}) {
        if (sh < 32U && (a > INT32_MAX || a < INT32_MIN)) continue;  // would not fit
        EXPECT_EQ(mul_shr_pieces(a, b, sh), exact(a, b, sh)) << a << " " << b << " " << sh;
        EXPECT_EQ(mul_shr(a, b, sh), exact(a, b, sh)) << a << " " << b << " " << sh;
      }
    }
  }
}

TEST(FixedQmath, ShiftsRoundingAndSaturation) {
  EXPECT_EQ(shift(-5, 1), -3);  // floor
  EXPECT_EQ(shift(5, -2), 20);
  EXPECT_EQ(shift(-1, 70), -1);
  EXPECT_EQ(shift(1, 70), 0);
  EXPECT_EQ(round_shr(5, 1), 3);  // halves up
  EXPECT_EQ(round_shr(-5, 1), -2);
  EXPECT_EQ(round_shr(-6, 1), -3);
  EXPECT_EQ(saturate_i32(std::int64_t{1} << 40), INT32_MAX);
  EXPECT_EQ(saturate_i32(-(std::int64_t{1} << 40)), INT32_MIN);
  EXPECT_EQ(mul_shift(std::int64_t{3}, 5U, -4), 240);
}

TEST(FixedQmath, AbsolutePositionWrapsLikeTheDrive) {
  EXPECT_EQ(absolute(INT32_MAX, 1), INT32_MIN);
  EXPECT_EQ(absolute(INT32_MAX - 10, 100), INT32_MIN + 89);
  EXPECT_EQ(absolute(INT32_MIN + 5, -10), INT32_MAX - 4);
  EXPECT_EQ(absolute(-100, 50), -50);
}

// The small-factor product a Cortex-M0 runs has int64 multiplication's bits (modulo 2^64).
TEST(FixedQmath, SmallFactorProductFromHalvesIsTheModularProduct) {
  std::mt19937_64 rng{3};
  const auto modular = [](std::int64_t x, std::uint32_t w) {
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(x) * w);
  };
  for (int i = 0; i < 1000000; ++i) {
    const auto x = static_cast<std::int64_t>(rng());
    const auto w = static_cast<std::uint32_t>(rng() & 0xFFFFU);
    ASSERT_EQ(mul_small_halves(x, w), modular(x, w)) << x << " " << w;
    ASSERT_EQ(mul_small(x, w), modular(x, w));
  }
  for (std::int64_t x : {std::int64_t{0}, std::int64_t{1}, std::int64_t{-1}, INT64_MAX, INT64_MIN,
                         std::int64_t{0xFFFF}, std::int64_t{0x1'0000'0000}, std::int64_t{-0x1'0000'0000}}) {
    for (std::uint32_t w : {0U, 1U, 2U, 120U, 240U, 0xFFFFU}) EXPECT_EQ(mul_small_halves(x, w), modular(x, w));
  }
  static_assert(mul_small_halves(-3, 240) == -720);
}

// The 16-bit-halves product a Cortex-M0 runs, and the signed forms built on it, are exact.
TEST(FixedQmath, WideProductsFromHalvesAreExact) {
  std::mt19937_64 rng{2};
  for (int i = 0; i < 1000000; ++i) {
    const auto a = static_cast<std::uint32_t>(rng()), b = static_cast<std::uint32_t>(rng());
    ASSERT_EQ(umul_wide_halves(a, b), static_cast<std::uint64_t>(a) * b);
    const auto sa = static_cast<std::int32_t>(a), sb = static_cast<std::int32_t>(b);
    ASSERT_EQ(mul_wide_halves(sa, b), static_cast<std::int64_t>(sa) * static_cast<std::int64_t>(b));
    ASSERT_EQ(mul_wide_halves(sa, sb), static_cast<std::int64_t>(sa) * sb);
    ASSERT_EQ(mul_wide(sa, b), static_cast<std::int64_t>(sa) * static_cast<std::int64_t>(b));
    ASSERT_EQ(mul_wide(sa, sb), static_cast<std::int64_t>(sa) * sb);
  }
  for (std::uint32_t a : {0U, 1U, 0xFFFFU, 0x10000U, 0x7FFFFFFFU, 0x80000000U, 0xFFFFFFFFU}) {
    for (std::uint32_t b : {0U, 1U, 0xFFFFU, 0x10000U, 0x7FFFFFFFU, 0x80000000U, 0xFFFFFFFFU}) {
      EXPECT_EQ(umul_wide_halves(a, b), static_cast<std::uint64_t>(a) * b);
      const auto sa = static_cast<std::int32_t>(a), sb = static_cast<std::int32_t>(b);
      EXPECT_EQ(mul_wide_halves(sa, sb), static_cast<std::int64_t>(sa) * sb);
      EXPECT_EQ(mul_wide_halves(sa, b), static_cast<std::int64_t>(sa) * static_cast<std::int64_t>(b));
    }
  }
}
