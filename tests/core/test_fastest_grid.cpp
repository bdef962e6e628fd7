// SPDX-License-Identifier: Apache-2.0
// Profile `fastest` against the independent reference (tools/fastest-lp: jerk piecewise constant
// on 1000 steps, its own exact integration of the axis and of every mode, a linear program per
// duration) over a seeded random grid of problems: 1 to 3 modes, omega 1-300 rad/s, zeta 0-0.3,
// D 1e-3-10 m, each limit over two decades. The reference durations were computed once by the
// committed tool (the command and seed are in the data file's header; the soak test
// fastest_lp_grid_current re-solves a sample to show the file is current).
//
// What is checked: every move `fastest` plans is a move (at rest by the Duhamel quadrature of
// residual.hpp to 1e-9 D, within the limits, never backwards); and how its duration compares with
// the reference's: docs/fastest.md ("Against the reference") states the distribution, and the
// test fails if fewer cases are within 0.1 % of the reference than stated there, or if any is
// further over it than the worst stated. The default suite runs 30 cases spread evenly over the
// file; the soak suite (SETTLE_FASTEST_GRID_EVERY=1) all of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "residual.hpp"
#include "settle/core/planner.hpp"
#include "test_helpers.hpp"

#ifndef SETTLE_FASTEST_GRID_EVERY
#define SETTLE_FASTEST_GRID_EVERY 8
#endif

namespace {
// The documented state (docs/fastest.md, "Against the reference"), for the cases this build runs:
// at least this many within 0.1 % of the reference, none more than this ratio over it, at most
// this many refused.
#if SETTLE_FASTEST_GRID_EVERY == 1
// 295 of 295 with a reference (300 cases): 294 before the dwell changes' passes from a stop late in
// a cruise (227; dwell_passes' stops and merge_closed_stops, session 30); 292 before a chain full at 15 nodes had its dwells
// changed too (74; dwell_changes from refined_chains, session 29) and closed pulses and slow-downs
// were taken out of the changed chains (5; drop_closed_pulses); 290 before a refined chain's dwells were changed in
// chains of up to 23 nodes (35, 254; dwell_changes, session 27); 289 before a long cruise's end was
// seeded with three stops (121; cruise_stops_refined, session 26); 287 on the branch of the limit nodes held for no time
// made into peaks (229, 8, 200; zero_holds_to_peaks), 286 on the branch of the pulse a quarter into a
// dwell (263; dwell_pulse_quarter, ramp_to_rest) and the slow-down late in a cruise (44;
// cruise_slowdown_late), merged; 284 before both; 283 before the dips for three modes (137); 281 before
// the pulse inside a dwell (250, 98; dwell_pulse_refined); 280 before the blips of finite size in the chain's
// holds (40; hold_blips_refined); 279 before the blips seeded in the slower mode's chain
// (184; blips_refined); 275 before the chains solved and kept to their rounding
// (31, 34, 265; keep_or_polish, split_to_rounding); 273 before the restart after the move (222, 237); 272
// before the blip moved in its hold (231); 269
// before the split chains with more parts than modes
// (160, 161, 256; 252 of the 277 before cases 135-139 and 287-299 had a reference); 235 of 277
// before the chains with more turns than equations (arc_refine), 222 before session 22.
constexpr int kWithin = 295;
// case 137 (three modes): 1.00095; 1.00271 (case 227, now 0.99983) before the passes from a stop
// late in a cruise, 1.00296 before a full chain's dwells were changed; 1.01158
// (case 74, now 0.99996) before that; 1.01269 (case 5, now 0.99991) before the dwell changes; was
// 1.01568 (case 184, now 0.99933), 1.03214 (case 112), 1.3231 (case 167)
constexpr double kWorst = 1.001;
// None: case 113 (three modes, 2.1 / 13.5 / 278.7 rad/s; D 3.48 m) was refused until the joint
// ZV shaper started from the slower modes' design (docs/fastest.md, "Several modes").
constexpr int kRefused = 0;
// Of the 900 plans at scales 1e-3, 0.37 and 7.3: measured 31 and 3 (worst 0.49 %) since a stall
// below a tenth of the rows' rounding solves a chain (session 34: 46 at scale 1 is now 1.8e-9
// longer than at the other three, 59 at 7.3 now agrees); 29 and 3 with the
// refinement stopping at a proof (session 32: 19 is 5.7e-9 shorter at every scale); 29 and 3 with the passes
// from a stop late in a cruise too (session 30: 227 at 1e-3 4.36949 s against 4.36729 s at 1, was
// 4.37842 against 4.37983 s; every other scaled plan the same); 29 and 3 with both of
// session 29's changes merged (the stall tests, below, left 28 and 5 alone); 32 and 3 (worst 0.49 %: case 35 at 7.3,
// 10.8638 s against 10.8113 s) with a full chain's dwells changed and closed pulses and slow-downs
// taken out (session 29): 74 plans alike at every scale, 254 at 1e-3 and 0.37 is 1.69100 s (was
// 1.70212 and 1.69537 s against 1.69034 s), 5 is 3.60041, 3.60488 and 3.59144 s at 1e-3, 0.37
// and 7.3 against 3.59144 s (its chain at scale 1 reaches the reference's form; 0.24 % and
// 0.37 % over it at 1e-3 and 0.37), but 227 ends 4.37983 s at 1 and 4.37842 s at 1e-3 (before,
// 4.38094 s at each: its dwells were not changed); 31 and 5 (worst 0.90 %: case 5 at 0.37,
// 3.63729 s against 3.60488 s) with a seed's restoration retried and the polish holding the
// inequalities a step would break (step_breaks): 86 at 0.37 and 7.3 keeps its shorter chain
// (7.14936 and 7.14965 s against 7.14542 s, were 7.15315 and 7.16500 s), 254 at 7.3 screens as at
// scale 1 (1.69041 s, was 1.69772 s), 112 at 7.3 and 134 at 1e-3 and 7.3 plan as at scale 1
// (134 there 0.077 % shorter than before), 5 at 1e-3 3.60041 s (was 3.61549 s, now 0.12 % shorter
// than at scale 1); 34 and 9 (worst 0.90 %) with the dwell changes: the chains they reach at scale 1 are not all
// reached at the others (5: 3.6030 to 3.6373 s, 254: 1.69537 to 1.70212 s; 35 at 7.3, 86 at 0.37
// and 7.3 the moves from before them); none longer than the same scale's plan before; 31 and 6
// (worst 0.42 %, case 254) with a long cruise's end seeded with three stops: case 121's chain is found at every scale, but its rows
// round to 2e-8 (a 52 s move at jmax 8413) and the minimisation ends within that, at 0.37 2.6e-9 of
// the duration from scale 1 (52.0285778 s against 52.0285776 s; before, the joint ZV move at every
// scale); 30 and 6 (worst 0.42 %, case 254) with both branches below merged;
// 27 and 3 (worst 0.17 %, case 86 at 1e-3) with
// the limit nodes held for no time made into peaks (case 8 at 1e-3 now 0.057 % longer than at
// scale 1, where it is 0.19 % shorter than before); 29 and 6 (worst 0.42 %: case 254, whose
// chain with a pulse a quarter into a dwell is found at scale 1 only, 1.70070 s against 1.70776 s
// at the other three; 137 differs at every scale by 3e-5 since the slow-down late in a cruise,
// 26 and 6 before it) with the pulse a quarter into a dwell; 26 and 3 (worst 0.17 %) with the dips for
// three modes merged in; 27 and 3 (worst 0.17 %, case 86 at 1e-3) before them;
// 25 and 3, worst 3.2 %, case 112 at 7.3, before the pulse inside a dwell: 254 now differs at
// every scale by 4e-8, 112 at 7.3 by 0.13 %;
// 24 and 4 before the blips of finite size in the chain's holds: case 40 now 1.51802 to 1.51883 s
// at the four scales, where at 0.37 and 7.3 it was 0.08 % and 0.3 % shorter than at 1);
// 27 and 6 before the blips in the slower mode's chain (184 now plans alike at every scale);
// 28 and 6 before the chains kept to their rounding (keep_or_polish; 34, 86 and 110 now differ
// at some scales);
// 29 and 7 before the restart after the move: 22 now plans alike at every scale, 40 at 7.3 is
// 0.3 % shorter than at scale 1, 237 at 0.37 differs by 2e-9; the same after the blip moved in its hold);
// 35 and 9 before the split chains with more parts than modes (67 and 233 now plan alike at every
// scale, 46 at 1e-3).
constexpr int kScaledOff1e9 = 31, kScaledOff1e3 = 3;
#else
// of 30 with a reference (30 cases spread evenly over the 300 of the file; over the 282 before
// cases 135-139 and 287-299 were added, 29 of 29 and 1.00062); 26 and 1.00478 (case 160) before
// the split chains with more parts than modes; 27 before the blips of finite size in the chain's
// holds (case 40); 28 before the pulse inside a dwell (250); 29 before the limit nodes held for no
// time were made into peaks (200)
constexpr int kWithin = 30;
// 1.00036 (case 10); 1.00274 (case 200) before the limit nodes held for no time were made into
// peaks, 1.00288 before the pulse inside a dwell
constexpr double kWorst = 1.0004;
// of 90: measured 4 and 0 (worst 7.9e-5) with Newton's runs given up where they stall and a
// continuation's too long first step cut (session 29: case 40 at scale 1 1.51802 s);
// 6 and 0 (worst 0.031 %: case 40 at 0.37, 1.51883 s against 1.51849 s; 5 and 1,
// worst 0.30 %, before the blips of finite size in the chain's holds: case 40 at 7.3 shorter than
// at scale 1 since the restart after the move; 3 and 1 before the chains kept to their rounding
// (keep_or_polish), where case 110's refined chain was refused at every scale and is now kept at
// each, ending 2e-7 to 1e-6 apart; 2 and 0 before the restart, worst 0.079 %)
constexpr int kScaledOff1e9 = 4, kScaledOff1e3 = 0;
constexpr int kRefused = 0;
#endif
}  // namespace

using namespace settle;

namespace {

struct GridCase {
  int id = 0;
  double d = 0, v = 0, a = 0, j = 0;
  std::vector<core::Mode> modes;
  double lp = 0;  // s; 0: the reference found no move ("infeasible") or failed
};

std::vector<GridCase> read_grid() {
  std::ifstream in(SETTLE_FASTEST_GRID_FILE);
  EXPECT_TRUE(in.good()) << SETTLE_FASTEST_GRID_FILE;
  std::vector<GridCase> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    GridCase c;
    int m = 0;
    s >> c.id >> c.d >> c.v >> c.a >> c.j >> m;
    for (int k = 0; k < 3; ++k) {
      core::Mode md{};
      s >> md.omega >> md.zeta;
      if (k < m) c.modes.push_back(md);
    }
    std::string lp;
    s >> lp;
    EXPECT_FALSE(s.fail()) << line;
    c.lp = (lp == "infeasible" || lp == "failed") ? 0.0 : std::stod(lp);
    out.push_back(c);
  }
  return out;
}

// The cases this build runs: 30 spread evenly over the file, or (soak) all of them.
std::vector<GridCase> cases_run(const std::vector<GridCase>& grid) {
  const std::size_t runs = SETTLE_FASTEST_GRID_EVERY == 1 ? grid.size() : std::min<std::size_t>(30, grid.size());
  std::vector<GridCase> out;
  for (std::size_t n = 0; n < runs; ++n) out.push_back(grid[n * grid.size() / runs]);
  return out;
}

core::MoveRequest grid_request(const GridCase& c) {
  core::MoveRequest r{};
  r.profile = core::ProfileKind::fastest;
  r.distance = c.d, r.limits.vmax = c.v, r.limits.amax = c.a, r.limits.jmax = c.j;
  r.set_mode(c.modes[0].omega, c.modes[0].zeta);
  for (std::size_t k = 1; k < c.modes.size(); ++k) (void)r.add_mode(c.modes[k]);
  return r;
}

// A planned move is a move: every mode at rest (independent quadrature), the limits held (sampled
// densely), the target reached, never backwards.
void expect_is_a_move(const core::MoveRequest& r, const core::Move<double>& m, const std::vector<core::Mode>& modes) {
  const double d = std::fabs(r.distance);
  for (const auto& md : modes) {
    EXPECT_LE(test::residual_amplitude(m, md.omega, md.zeta), 1e-9 * d) << "omega " << md.omega;
  }
  double pv = 0, pa = 0, pj = 0, worst_v = 0, last = 0, back = 0;
  constexpr int n = 20000;
  for (int i = 0; i <= n; ++i) {
    const core::Sample<double> s = m.at(m.duration() * i / n);
    pv = std::max(pv, std::fabs(s.v));
    pa = std::max(pa, std::fabs(s.a));
    pj = std::max(pj, std::fabs(s.j));
    worst_v = std::min(worst_v, s.v);
    back = std::min(back, s.p - last);
    last = s.p;
  }
  EXPECT_LE(pv, *r.limits.vmax * (1 + 1e-9));
  EXPECT_LE(pa, *r.limits.amax * (1 + 1e-9));
  EXPECT_LE(pj, *r.limits.jmax * (1 + 1e-9));
  EXPECT_GE(worst_v, -1e-9 * pv);
  // Position samples: never back by more than 1e-8 D. Grid case 50 (a 5.7 s move of 0.8 mm) steps
  // back 3.4e-12 m = 4.2e-9 D between two samples while the velocity is >= 0 at every sample: the
  // evaluated table is not continuous to better than that (test_fastest.cpp's 1e-12 D holds on its
  // own grids); a finding for the table's evaluation, not a backwards motion.
  EXPECT_GE(back, -1e-8 * d);
  EXPECT_NEAR(m.at(m.duration()).p, r.distance, 1e-12 * d);
}

}  // namespace

TEST(FastestGrid, PlannedMovesAreMovesAndTheirDurationsAgainstTheReferenceAreAsDocumented) {
  const std::vector<GridCase> grid = read_grid();
  ASSERT_GE(grid.size(), 30u);
  int checked = 0, with_ref = 0, within = 0, shorter = 0, refused = 0;
  int by_modes[4][2] = {};  // [modes][0]: with a reference; [1]: within 0.1 % of it
  double worst = 0.0, worst_plan_ms = 0.0;
  std::vector<double> ratios;
  for (const GridCase& c : cases_run(grid)) {
    SCOPED_TRACE(::testing::Message() << "grid case " << c.id);
    const core::MoveRequest r = grid_request(c);
    core::Move<double> m{};
    const auto t0 = std::chrono::steady_clock::now();
    const core::Status st = core::plan(r, m);
    worst_plan_ms = std::max(worst_plan_ms,
                             std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    ++checked;
    if (c.lp > 0.0) ++with_ref;
    if (st != core::Status::ok) {
      ++refused;
      std::printf("case %d: refused (%s), reference %.6f s\n", c.id, core::to_string(st), c.lp);
      continue;
    }
    expect_is_a_move(r, m, c.modes);
    if (c.lp <= 0.0) continue;
    const double ratio = m.duration() / c.lp;
    ratios.push_back(ratio);
    within += ratio <= 1.001;
    by_modes[c.modes.size()][0] += 1;
    by_modes[c.modes.size()][1] += ratio <= 1.001;
    shorter += ratio < 1.0;
    worst = std::max(worst, ratio);
    if (ratio > 1.001) {
      std::printf("case %d (%zu modes): fastest %.6f s, reference %.6f s: %+.2f %%\n", c.id, c.modes.size(),
                  m.duration(), c.lp, 100.0 * (ratio - 1.0));
    }
  }
  std::sort(ratios.begin(), ratios.end());
  for (int k = 1; k <= 3; ++k) std::printf("%d modes: %d of %d within 0.1 %%\n", k, by_modes[k][1], by_modes[k][0]);
  const auto q = [&](double f) { return ratios.empty() ? 0.0 : ratios[static_cast<std::size_t>(f * static_cast<double>(ratios.size() - 1))]; };
  std::printf("%d cases, %d with a reference; %d refused; within 0.1 %%: %d; shorter: %d; worst %.4f\n", checked,
              with_ref, refused, within, shorter, worst);
  std::printf("fastest / reference: min %.5f, 10 %% %.5f, median %.5f, 90 %% %.5f, max %.5f (slowest plan %.1f ms, "
              "for scale only)\n",
              q(0), q(0.1), q(0.5), q(0.9), q(1), worst_plan_ms);
  EXPECT_GE(within, kWithin);
  EXPECT_LE(worst, kWorst);
  EXPECT_LE(refused, kRefused);
}

// The proof that a move is the shortest of its problem (core::certify_fastest, LP duality:
// docs/fastest.md, "A certificate of the shortest move") against the reference, a different method
// whose move is a true move and so at least as long as the optimum: a proven move is never longer
// than its reference (beyond the reference's own 1e-5), and at least the measured count are proven:
// 258 of the 300 (soak; 256 before a stall below a tenth of the rows' rounding solved a chain,
// 255 before grid case 19's chain with its turns held for no time made peaks was proven, 254
// before grid case 227 was planned shorter), 25 of the default suite's 30 (7 Dec 2026). Where a proof fails, a shorter
// move exists: every plan longer than its reference by more than 5e-6 is unproven.
#if SETTLE_FASTEST_GRID_EVERY == 1
constexpr int kProven = 258;
#else
constexpr int kProven = 25;
#endif
TEST(FastestGrid, ProvenMovesAreNeverLongerThanTheReference) {
  const std::vector<GridCase> grid = read_grid();
  ASSERT_FALSE(grid.empty());
  int proven = 0, planned = 0;
  for (const GridCase& c : cases_run(grid)) {
    SCOPED_TRACE(::testing::Message() << "grid case " << c.id);
    const core::MoveRequest r = grid_request(c);
    core::Move<double> m{};
    if (core::plan(r, m) != core::Status::ok) continue;
    ++planned;
    core::FastestCertificate cert{};
    m.profile().visit([&](const auto& shape) {
      if constexpr (std::is_same_v<std::decay_t<decltype(shape)>, core::Fastest<double>>) {
        if (const auto* t = shape.table()) cert = core::certify_fastest(t->params(), r);
      }
    });
    if (cert.proof != core::FastestProof::proven) continue;
    ++proven;
    EXPECT_LT(std::fabs(cert.gap), 1e-6);
    if (c.lp > 0.0) {
      EXPECT_LE(m.duration(), c.lp * (1.0 + 1e-5)) << "proven, yet the reference is shorter";
    }
  }
  std::printf("%d of %d planned moves proven the shortest\n", proven, planned);
  EXPECT_GE(proven, kProven);
}

// Scale: the problem (k D, k vmax, k amax, k jmax) is the problem (D, vmax, amax, jmax) in other
// units of length, so its shortest move lasts as long. `fastest`'s search is not invariant: on
// some cases it lands on another chain at another scale (a path's axes re-planned at their own
// scales once disagreed by 1.5 %, docs/multi_axis.md). This counts the cases whose duration at
// scale k differs from the one at scale 1 by more than 1e-9 and 1e-3 of it, against the measured
// counts: a search that depends more on the units fails.
TEST(FastestGrid, ScaledProblemsPlanAsLongAsTheOriginalsUpToTheMeasuredCount) {
  const std::vector<GridCase> grid = read_grid();
  ASSERT_FALSE(grid.empty());
  int compared = 0, off_1e9 = 0, off_1e3 = 0;
  double worst = 0.0;
  for (const GridCase& c : cases_run(grid)) {
    const core::MoveRequest r = grid_request(c);
    core::Move<double> m{};
    if (core::plan(r, m) != core::Status::ok) continue;
    for (const double k : {1e-3, 0.37, 7.3}) {
      core::MoveRequest q = r;
      q.distance = k * r.distance;
      q.limits = r.limits.scaled(k);
      core::Move<double> mk{};
      const core::Status st = core::plan(q, mk);
      ++compared;
      const double dev = st == core::Status::ok ? std::fabs(mk.duration() / m.duration() - 1.0) : HUGE_VAL;
      worst = std::max(worst, dev);
      off_1e9 += dev > 1e-9;
      off_1e3 += dev > 1e-3;
      if (dev > 1e-9) {
        std::printf("case %d at scale %g: %.9f s against %.9f s (%s)\n", c.id, k, mk.duration(), m.duration(),
                    core::to_string(st));
      }
    }
  }
  std::printf("%d scaled plans: %d differ by more than 1e-9, %d by more than 1e-3; worst %.3g\n", compared, off_1e9,
              off_1e3, worst);
  EXPECT_LE(off_1e9, kScaledOff1e9);
  EXPECT_LE(off_1e3, kScaledOff1e3);
}

// Sign: the move of -D is the move of D mirrored, so `fastest` plans both alike: the same
// duration to the bit and p(t; -D) = -p(t; D) (v, a, j too) at every sample. Before the planner
// planned |D| and mirrored it, the search ran on the signed problem and rounding could steer it:
// test_fastest.cpp's BangCoastStillRefinesALongRingingChain planned 0.4950726 s for D = 1 and
// 0.4950745 s for D = -1. Over the cases this build runs (30, or all 300 in the soak); every one
// of them was mirrored to the bit before too (that request is not in the grid): this guards the
// property over the grid's variety, test_fastest.cpp's checks fail without the change.
TEST(FastestGrid, NegativeDistancesPlanTheMirroredMove) {
  const std::vector<GridCase> grid = read_grid();
  ASSERT_FALSE(grid.empty());
  int compared = 0;
  for (const GridCase& c : cases_run(grid)) {
    SCOPED_TRACE(::testing::Message() << "grid case " << c.id);
    const core::MoveRequest r = grid_request(c);
    core::MoveRequest q = r;
    q.distance = -r.distance;
    core::Move<double> m{}, mq{};
    const core::Status st = core::plan(r, m);
    ASSERT_EQ(core::plan(q, mq), st);
    if (st != core::Status::ok) continue;
    ++compared;
    test::expect_mirrored(m, mq);
  }
  std::printf("%d grid cases planned at D and -D: mirrored\n", compared);
}
