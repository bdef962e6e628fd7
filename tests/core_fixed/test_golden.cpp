// SPDX-License-Identifier: Apache-2.0
// The golden checksum is what a target image compares with the host: it must be reproducible and
// its host values are pinned here, so that any change to the integers the evaluators produce is a
// deliberate one (update the constants, and the cross test's expectation, in the same commit).
// `plan` and `positions` (the position plan and its stepper) were added after the others, which
// kept their values.
//
// Measured equal, all four, on x86-64 (128-bit products), x86-64 built with -DSETTLE_FIXED_NO_INT128
// -DSETTLE_FIXED_MUL_HALVES (the Cortex-M code paths), aarch64 (qemu-aarch64) and QEMU's
// mps2-an386 (Cortex-M4F) and microbit (Cortex-M0). Core is built without FMA contraction, so the
// planner's doubles, and with them the quantised coefficients, are the same everywhere too.
#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>

#include "settle/core/fixed/golden.hpp"

using namespace settle::core;

namespace {
constexpr std::uint64_t kBuild = UINT64_C(0x83717473ba206014);
constexpr std::uint64_t kTicks = UINT64_C(0xf7c751af5c33e69e);
constexpr std::uint64_t kPlan = UINT64_C(0x43e9700017c1c908);
constexpr std::uint64_t kPositions = UINT64_C(0xa1355d40506d8a12);
}  // namespace

TEST(FixedGolden, ReproducibleAndPinned) {
  const fixed::GoldenResult a = fixed::golden_checksum();
  const fixed::GoldenResult b = fixed::golden_checksum();
  std::printf("golden: build 0x%016" PRIx64 " ticks 0x%016" PRIx64 " moves %u samples %u\n", a.build, a.ticks, a.moves,
              a.samples);
  std::printf("golden: plan 0x%016" PRIx64 " positions 0x%016" PRIx64 " position samples %u\n", a.plan, a.positions,
              a.position_samples);
  EXPECT_EQ(a.status, Status::ok) << to_string(a.status);
  EXPECT_EQ(a.build, b.build);
  EXPECT_EQ(a.ticks, b.ticks);
  EXPECT_EQ(a.plan, b.plan);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.moves, 16U);
  EXPECT_EQ(a.samples, 26076U);
  EXPECT_EQ(a.ticks, kTicks);
  // One position per tick of each motion: the ticks at which `samples` holds two samples of the
  // motion (at_tick and next) and two of its cam table.
  EXPECT_EQ(a.position_samples * 4, a.samples);
  EXPECT_EQ(a.positions, kPositions);
  EXPECT_EQ(a.build, kBuild);
  EXPECT_EQ(a.plan, kPlan);
}
