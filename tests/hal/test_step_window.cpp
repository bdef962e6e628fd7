// SPDX-License-Identifier: Apache-2.0
// StepWindow: within one window of receive time the setpoints applied stay within the limit of
// each other and of the one held a window before, whatever the arrival pattern; the brute-force
// check below recomputes that bound from the whole history, independently of the ring.
#include "settle/hal/canopen/step_window.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace settle::hal::canopen {
namespace {

constexpr std::uint64_t period = 1000;
constexpr std::uint32_t window = 750;
constexpr std::int64_t limit = 100;

// Applies target at t through the window, as the drive does, and returns the setpoint.
std::int32_t apply(StepWindow& w, std::uint64_t t, std::int32_t target) {
  const std::int32_t s = w.bound(t, target, limit, window);
  w.push(t, s, window);
  return s;
}

TEST(StepWindow, OneSyncPerPeriodIsNeverHeldBack) {
  StepWindow w;
  w.reset(0, 0);
  for (std::int32_t k = 1; k <= 100; ++k) {
    ASSERT_EQ(apply(w, static_cast<std::uint64_t>(k) * period, 100 * k), 100 * k);
  }
}

TEST(StepWindow, TwoStepsInOnePeriodMoveOneAndTheSecondCatchesUpNextPeriod) {
  StepWindow w;
  w.reset(0, 0);
  ASSERT_EQ(apply(w, period, 100), 100);
  // A period missing, then two pairs received together: one step now, the rest next SYNC.
  EXPECT_EQ(apply(w, 3 * period, 200), 200);
  EXPECT_EQ(apply(w, 3 * period, 300), 200);
  EXPECT_EQ(apply(w, 4 * period, 400), 300);
  EXPECT_EQ(apply(w, 5 * period, 500), 400);
  EXPECT_EQ(apply(w, 6 * period, 500), 500);
}

TEST(StepWindow, SyncsUpToAQuarterPeriodEarlyAreNotHeldBack) {
  StepWindow w;
  w.reset(0, 0);
  ASSERT_EQ(apply(w, 1000, 100), 100);
  EXPECT_EQ(apply(w, 1760, 200), 200);  // 0.76 period after the previous one
  EXPECT_EQ(apply(w, 3000, 300), 300);
  EXPECT_EQ(apply(w, 3740, 400), 300);  // 0.74: held back to one step in the window
}

TEST(StepWindow, ALongBurstAtOneInstantMovesOneStepInAll) {
  StepWindow w;
  w.reset(5000, 0);
  std::int32_t s = 0;
  for (std::int32_t k = 1; k <= 300; ++k) {
    s = apply(w, 5000, 10 * k);  // 3000 counts asked for at one instant
    ASSERT_LE(s, limit) << k;
    ASSERT_GE(s, 0) << k;
  }
  EXPECT_EQ(s, limit);
  // Downwards too, after the burst: still one step per window from the held position.
  EXPECT_EQ(apply(w, 6000, -1000), 0);
}

TEST(StepWindow, PositionsAcrossTheCountersWrapAreOneStepApart) {
  StepWindow w;
  constexpr std::int32_t top = std::numeric_limits<std::int32_t>::max();
  w.reset(0, top - 50);
  EXPECT_EQ(apply(w, 0, std::numeric_limits<std::int32_t>::min() + 500), std::numeric_limits<std::int32_t>::min() + 49);
}

// Random arrival times (bursts, gaps, early and late SYNCs) and random targets: every setpoint
// applied is within the limit of every other applied less than a window before it and of the
// latest applied at least a window before it, by a scan of the whole history.
TEST(StepWindow, RandomArrivalsNeverMoveMoreThanTheLimitWithinAWindow) {
  std::mt19937 rng{2026};
  std::uniform_int_distribution<int> gap_kind{0, 9};
  std::uniform_int_distribution<std::uint64_t> jitter{0, 2 * period};
  std::uniform_int_distribution<std::int32_t> step{-150, 150};
  for (int run = 0; run < 200; ++run) {
    StepWindow w;
    std::uint64_t t = 1'000'000;
    std::int32_t target = 0;
    std::vector<std::pair<std::uint64_t, std::int32_t>> applied{{t, 0}};
    w.reset(t, 0);
    std::int64_t held_back = 0;
    for (int k = 0; k < 400; ++k) {
      const int kind = gap_kind(rng);
      t += kind < 3 ? 0 : (kind < 5 ? jitter(rng) : period);  // bursts, jitter, on time
      target += step(rng);
      const std::int32_t s = apply(w, t, target);
      held_back += s != target ? 1 : 0;
      for (auto it = applied.rbegin(); it != applied.rend(); ++it) {
        const std::int64_t d = std::int64_t{s} - it->second;
        ASSERT_LE(d < 0 ? -d : d, limit) << "run " << run << " sync " << k;
        if (t - it->first >= window) break;  // the one held a window before: older ones do not count
      }
      applied.emplace_back(t, s);
    }
    ASSERT_GT(held_back, 0);  // the pattern did exercise the bound
  }
}

}  // namespace
}  // namespace settle::hal::canopen
