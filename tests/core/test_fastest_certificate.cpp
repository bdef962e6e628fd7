// SPDX-License-Identifier: Apache-2.0
// core::certify_fastest, the proof by LP duality that a move is the shortest of its problem
// (docs/fastest.md, "A certificate of the shortest move"), on moves whose answer is known without it:
// the rigid time-optimal move (the textbook answer) is proven, mirrored too; a move that is not the
// problem's (a switch moved), a longer move of the problem (two moves in a row) and one whose ramps
// are not at jmax are not. test_fastest_grid.cpp checks proven plans against the LP reference, and
// tools/fastest-certificate (Python, from the printed plan) is the same check written apart.
#include <gtest/gtest.h>

#include <cmath>
#include <type_traits>
#include <utility>
#include <vector>

#include "settle/core/planner.hpp"
#include "settle/core/profiles/fastest.hpp"

namespace {

using namespace settle;

core::FastestTable table(const std::vector<std::pair<double, double>>& segs, double sign = 1.0) {
  core::FastestTable t{};
  double a = 0.0, v = 0.0, p = 0.0;
  for (const auto& [d, j] : segs) {
    t.durations[t.count] = d;
    t.accel0[t.count] = a;
    t.jerk[t.count] = sign * j;
    ++t.count;
    p += v * d + a * d * d / 2.0 + sign * j * d * d * d / 6.0;
    v += a * d + sign * j * d * d / 2.0;
    a += sign * j * d;
  }
  t.distance = p;
  return t;
}

// D = 1 m, vmax 1 m/s, amax 2 m/s^2, jmax 10 m/s^3: ramps of 0.2 s, holds at amax of 0.3 s, a cruise
// of `cruise` s (0.3: at D).
std::vector<std::pair<double, double>> rigid(double cruise = 0.3, double j = 10.0) {
  const double tj = 2.0 / j, hold = (1.0 - 2.0 * tj) / 2.0;  // to vmax at amax
  return {{tj, j}, {hold, 0.0}, {tj, -j}, {cruise, 0.0}, {tj, -j}, {hold, 0.0}, {tj, j}};
}

core::MoveRequest request(double distance, double jmax = 10.0) {
  core::MoveRequest r{};
  r.profile = core::ProfileKind::fastest;
  r.distance = distance;
  r.limits.vmax = 1.0, r.limits.amax = 2.0, r.limits.jmax = jmax;
  return r;
}

TEST(FastestCertificate, TheRigidTimeOptimalMoveIsProvenAndMirroredToo) {
  const core::FastestCertificate c = core::certify_fastest(table(rigid()), request(1.0));
  EXPECT_EQ(c.proof, core::FastestProof::proven) << core::to_string(c.proof) << " at " << c.at;
  EXPECT_LT(std::fabs(c.gap), 1e-9);
  const core::FastestCertificate m = core::certify_fastest(table(rigid(), -1.0), request(-1.0));
  EXPECT_EQ(m.proof, core::FastestProof::proven) << core::to_string(m.proof);
}

TEST(FastestCertificate, AMoveThatIsNotTheProblemsIsRefused) {
  EXPECT_EQ(core::certify_fastest(table(rigid(0.33)), request(1.0)).proof, core::FastestProof::not_the_problems);
  EXPECT_EQ(core::certify_fastest(table(rigid()), request(1.0, 9.0)).proof, core::FastestProof::not_the_problems);
  core::MoveRequest robust = request(1.0);
  robust.robust = 10.0;
  EXPECT_EQ(core::certify_fastest(table(rigid()), robust).proof, core::FastestProof::robust);
}

TEST(FastestCertificate, LongerMovesOfTheProblemAreNotProven) {
  // Two of the moves in a row, with and without a dwell between: 2 m in 3.4 / 3.5 s, where one move
  // takes 2.7 s (a cruise of 1.3 s).
  for (const double dwell : {0.0, 0.1}) {
    std::vector<std::pair<double, double>> two = rigid();
    if (dwell > 0.0) two.emplace_back(dwell, 0.0);
    for (const auto& s : rigid()) two.push_back(s);
    const core::FastestCertificate c = core::certify_fastest(table(two), request(2.0));
    EXPECT_NE(c.proof, core::FastestProof::proven) << "dwell " << dwell;
    EXPECT_NE(c.proof, core::FastestProof::not_the_problems) << "dwell " << dwell;
  }
  EXPECT_EQ(core::certify_fastest(table(rigid(1.3)), request(2.0)).proof, core::FastestProof::proven);
  // Ramps at half the jerk allowed: a move of the problem, not a chain the proof reads.
  EXPECT_EQ(core::certify_fastest(table(rigid(0.3, 5.0)), request(0.0 + table(rigid(0.3, 5.0)).distance)).proof,
            core::FastestProof::not_a_chain);
}

// r's plan, its table certified for `judged` (r itself unless given).
core::FastestCertificate planned(const core::MoveRequest& r, double& duration, const core::MoveRequest* judged = nullptr) {
  core::Move<double> m{};
  EXPECT_EQ(core::plan(r, m), core::Status::ok);
  duration = m.duration();
  core::FastestCertificate c{};
  m.profile().visit([&](const auto& shape) {
    if constexpr (std::is_same_v<std::decay_t<decltype(shape)>, core::Fastest<double>>) {
      if (const auto* t = shape.table()) c = core::certify_fastest(t->params(), judged ? *judged : r);
    }
  });
  return c;
}

TEST(FastestCertificate, PlansAreProvenOrSayWhereAShorterMoveIs) {
  // The one-mode reference request (docs/fastest.md): proven.
  core::MoveRequest r = request(0.1);
  r.limits.vmax = 1.0, r.limits.amax = 20.0, r.limits.jmax = 800.0;
  r.set_mode(22.0, 0.0);
  double t = 0.0;
  EXPECT_EQ(planned(r, t).proof, core::FastestProof::proven);
  // The same move judged for a mode at 23 rad/s, which it leaves ringing: not that problem's.
  core::MoveRequest other = r;
  other.set_mode(23.0, 0.0);
  EXPECT_EQ(planned(r, t, &other).proof, core::FastestProof::not_the_problems);
  // Grid case 10: the plan, 4.571279 s, is not proven: the measure on its cruise is negative near
  // its end (4.4701 s), and the reference at 3000 steps reaches 4.569393 s.
  core::MoveRequest g{};
  g.profile = core::ProfileKind::fastest;
  g.distance = 1.186, g.limits.vmax = 0.2651, g.limits.amax = 91.96, g.limits.jmax = 133.5;
  g.set_mode(111.724, 0.1981);
  (void)g.add_mode({156.1497, 0.0737});
  const core::FastestCertificate c = planned(g, t);
  EXPECT_EQ(c.proof, core::FastestProof::negative_measure);
  EXPECT_NEAR(c.at, 4.4701, 1e-3);
  EXPECT_GT(t, 4.569393);
}

TEST(FastestCertificate, TheSearchStopsAtTheFirstProvenMove) {
  // The commissioning request (BM_PlanFastest/commissioning): its 70 rad/s mode rings 3.9 periods
  // over the bang-bang move, so bang-coast runs after it (bang_bang_family's rule) and found the same
  // 0.35181 s until the search stopped at a proven move; now the proof ends the search there and
  // bang-coast is not tried (its family time 0).
  core::MoveRequest r = request(0.1);
  r.limits.vmax = 0.5, r.limits.amax = 5.0, r.limits.jmax = 200.0;
  r.set_mode(25.0, 0.02);
  (void)r.add_mode({70.0, 0.05});
  core::FastestParams p{};
  core::Peaks<double> pk{};
  ASSERT_EQ(core::plan_fastest(r, p, pk), core::Status::ok);
  EXPECT_EQ(p.family, core::FastestFamily::bang_bang);
  EXPECT_NEAR(p.family_time[static_cast<std::size_t>(core::FastestFamily::bang_bang)], 0.35180684, 1e-8);
  EXPECT_EQ(p.family_time[static_cast<std::size_t>(core::FastestFamily::bang_coast)], 0.0);
  EXPECT_EQ(core::certify_fastest(p.table, r).proof, core::FastestProof::proven);
}

TEST(FastestCertificate, ARefinedChainsTurnsHeldForNoTimeAreMadePeaksWhereThatProvesIt) {
  // Grid case 19 (two modes): zero_holds_to_peaks' chain, the plan before session 32 (1.0821626742
  // s), touches amax for no time again where its minimisation ended, which the proof cannot model
  // (no dual fits it). Those turns made peaks once more and minimised (kept_until_proven), the move
  // is proven, 5.7e-9 s shorter.
  core::MoveRequest g{};
  g.profile = core::ProfileKind::fastest;
  g.distance = 0.317, g.limits.vmax = 2.439, g.limits.amax = 22.08, g.limits.jmax = 414.9;
  g.set_mode(3.7536, 0.117);
  (void)g.add_mode({121.2896, 0.2924});
  double t = 0.0;
  EXPECT_EQ(planned(g, t).proof, core::FastestProof::proven);
  EXPECT_LT(t, 1.082162670);
}

// Grid case 22 as planned by main 0dbc9fb (its segments as `settle plan --json` prints them): a
// 30 s move whose 29.15 s cruise carries a negative measure (down to -0.188, at 27.48 s) and whose
// last hold at vmax a worse one (-0.277, at 29.987 s). Most of the cruise is not walked sample by
// sample (a bound shows no sample there can be the worst: "A certificate of the shortest move",
// docs/fastest.md); the worst is still found, at the sample it was found at when every sample was.
TEST(FastestCertificate, TheWorstConditionIsFoundWhereMostOfALongCruiseIsBoundedNotWalked) {
  const core::FastestTable t = table({{0.014336375181674181, 1627.0},
                                      {0.014336375181674181, -1627.0},
                                      {29.15116504465621, 0.0},
                                      {0.014336375182182337, -1627.0},
                                      {0.014336375182182337, 1627.0},
                                      {0.34468443963143613, 0.0},
                                      {0.014336375181553507, 1627.0},
                                      {0.014336375181553507, -1627.0},
                                      {0.4255846411055977, 0.0},
                                      {0.011100127701389795, -1627.0},
                                      {0.01003944065231721, 1627.0},
                                      {0.008074074870233261, -1627.0},
                                      {0.009134761919309398, 1627.0}});
  core::MoveRequest r{};
  r.profile = core::ProfileKind::fastest;
  r.distance = 9.911, r.limits.vmax = 0.3344, r.limits.amax = 99.8, r.limits.jmax = 1627.0;
  r.set_mode(3.2992, 0.005);
  (void)r.add_mode({174.5023, 0.0911});
  const core::FastestCertificate c = core::certify_fastest(t, r);
  EXPECT_EQ(c.proof, core::FastestProof::negative_measure) << core::to_string(c.proof);
  EXPECT_NEAR(c.at, 29.9872399133181, 1e-9);
  EXPECT_LT(std::fabs(c.gap), 1e-9);
}

}  // namespace
