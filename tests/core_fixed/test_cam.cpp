// SPDX-License-Identifier: Apache-2.0
// Cam tables: a quintic table reproduces a quintic move exactly, every accepted table of random
// moves meets its tolerance at every tick, the stepper equals random access, and orders rank as
// their interpolation error says.
#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "fixed_cases.hpp"
#include "settle/core/fixed/cam.hpp"

#ifndef SETTLE_FIXED_CAM_MOVES
#define SETTLE_FIXED_CAM_MOVES 400
#endif

using namespace settle;
using core::Status;
using core::fixed::CamOrder;
using core::fixed::CamTable;

using test::planned;

namespace {

double worst_p(const CamTable& t, const core::Move<double>& m, const core::fixed::Scale& s) {
  double w = 0.0;
  for (std::int32_t n = 0; n <= t.end_tick() + 1; ++n) w = std::max(w, test::errors_at(m, s, n, t.at_tick(n)).p);
  return w;
}

}  // namespace

// The 3-4-5 polynomial is a quintic: nine knots 64 ticks apart hold its 512 ticks exactly (the
// end, where the jerk jumps, falls on a knot).
TEST(FixedCam, QuinticTableOfAQuinticIsExact) {
  const auto m = planned(core::ProfileKind::poly345, 0.25, 0.512);
  const core::fixed::Scale s{{1e6, 1000}, 16, 16};
  std::vector<core::fixed::CamKnot> knots(9);
  CamTable t{};
  ASSERT_EQ(core::fixed::build_cam_table(m, s, CamOrder::quintic, knots, t), Status::ok);
  EXPECT_EQ(t.formats().log2_spacing, 6);
  EXPECT_LE(worst_p(t, m, s), 0.5 + 1e-3);
  EXPECT_LE(t.check().v, 1.0);
  EXPECT_LE(t.check().a, 1.0);
}

TEST(FixedCam, HigherOrderIsCloserForTheSameTable) {
  const auto m = planned(core::ProfileKind::scurve_damped, 0.1, 0.6, 15.0);
  const core::fixed::Scale s{{1e6, 1000}, 16, 16};
  std::vector<core::fixed::CamKnot> knots(80);
  double err[3];
  int i = 0;
  for (CamOrder o : {CamOrder::linear, CamOrder::cubic, CamOrder::quintic}) {
    CamTable t{};
    ASSERT_EQ(core::fixed::build_cam_table(m, s, o, knots, t, 1e9), Status::ok);
    err[i++] = worst_p(t, m, s);
  }
  std::printf("80-knot table of a 600-tick S-curve: linear %.2f, cubic %.3f, quintic %.3f counts\n", err[0], err[1],
              err[2]);
  EXPECT_GT(err[0], err[1]);
  EXPECT_GT(err[1], err[2]);
  EXPECT_LE(err[2], 1.0);
}

// Random moves of every kind into 4096-knot tables: what is accepted is within one count at
// every tick (the builder checks every tick of these), and stepping equals random access.
TEST(FixedCam, AcceptedTablesAreWithinToleranceAndStepLikeRandomAccess) {
  test::FixedCaseGen gen{std::mt19937_64{11}, test::Kinds::all};
  std::vector<core::fixed::CamKnot> knots(4096);
  std::map<std::string, long> outcome;
  double worst = 0.0;
  long ticks = 0, identical = 0;
  std::int64_t diff = 0;
  for (int i = 0; i < SETTLE_FIXED_CAM_MOVES; ++i) {
    test::FixedCase c{};
    if (!gen.next(c)) continue;
    const CamOrder o = (i % 3 == 0) ? CamOrder::linear : (i % 3 == 1) ? CamOrder::cubic : CamOrder::quintic;
    CamTable t{};
    const Status st = core::fixed::build_cam_table(c.move, c.scale, o, knots, t);
    ++outcome[core::to_string(st)];
    if (st != Status::ok) {
      EXPECT_EQ(st, Status::table_too_small);
      continue;
    }
    core::fixed::CamStepper cs{t};
    for (std::int32_t n = 0; n <= t.end_tick(); ++n) {
      const auto a = t.at_tick(n), b = cs.next();
      ++ticks;
      identical += (a.p == b.p && a.v == b.v && a.a == b.a) ? 1 : 0;
      diff = std::max<std::int64_t>({diff, std::llabs(std::int64_t{a.p} - b.p), std::llabs(std::int64_t{a.v} - b.v),
                                     std::llabs(std::int64_t{a.a} - b.a)});
      if (t.end_tick() <= 4000 || n % 97 == 0) worst = std::max(worst, test::errors_at(c.move, c.scale, n, a).p);
    }
  }
  std::printf("cam tables: ok %ld, table_too_small %ld; worst accepted %.3f counts; stepping %.5f %% identical, "
              "max diff %" PRId64 "\n",
              outcome["ok"], outcome["table_too_small"], worst,
              100.0 * static_cast<double>(identical) / static_cast<double>(ticks), diff);
  EXPECT_LE(worst, 1.0);
  EXPECT_LE(diff, 1);
  EXPECT_GT(outcome["ok"], SETTLE_FIXED_CAM_MOVES / 2);
}
