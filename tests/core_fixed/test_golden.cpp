// The golden checksum is what a target image compares with the host: it must be reproducible and
// its host value is pinned here, so that any change to the integers the evaluators produce is a
// deliberate one (update the constants, and the cross test's expectation, in the same commit).
//
// Measured equal on x86-64 (128-bit products), x86-64 built with -DSETTLE_FIXED_NO_INT128
// -DSETTLE_FIXED_MUL_HALVES (the Cortex-M code paths), and QEMU's mps2-an386 (Cortex-M4F) and
// microbit (Cortex-M0). On aarch64 the tick checksum is equal too, but the build checksum is not:
// GCC contracts the planner's double arithmetic into fused multiply-adds there (core is built
// without -ffp-contract=off), so the pseudo-polynomial coefficients differ in their last bits and
// so do a few Q32.32 coefficients, 1e-8 counts below anything streamed.
#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>

#include "settle/core/fixed/golden.hpp"

using namespace settle::core;

namespace {
constexpr std::uint64_t kBuild = UINT64_C(0x83717473ba206014);
constexpr std::uint64_t kTicks = UINT64_C(0xf7c751af5c33e69e);
}  // namespace

TEST(FixedGolden, ReproducibleAndPinned) {
  const fixed::GoldenResult a = fixed::golden_checksum();
  const fixed::GoldenResult b = fixed::golden_checksum();
  std::printf("golden: build 0x%016" PRIx64 " ticks 0x%016" PRIx64 " moves %u samples %u\n", a.build, a.ticks, a.moves,
              a.samples);
  EXPECT_EQ(a.status, Status::ok) << to_string(a.status);
  EXPECT_EQ(a.build, b.build);
  EXPECT_EQ(a.ticks, b.ticks);
  EXPECT_EQ(a.moves, 16U);
  EXPECT_EQ(a.samples, 26076U);
  EXPECT_EQ(a.ticks, kTicks);
#if !defined(__FP_FAST_FMA)
  EXPECT_EQ(a.build, kBuild);
#endif
}
