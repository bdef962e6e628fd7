// SPDX-License-Identifier: Apache-2.0
// settle/core/exported_plan.hpp against the planner's own evaluation: over a seeded grid of moves of
// every closed-form family and the pseudo-polynomial, unshaped and shaped, the tables `settle export`
// writes (the move's pieces in double and float, core::fixed's motion) stream every tick within one
// count of round(Move<double>::at(n period) x counts per unit), and end exactly on the target.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "settle/core/exported_plan.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/planner.hpp"

namespace settle::core {
namespace {

// The reference: the planned move's own evaluator, sampled as `settle sample --dt period` samples it.
std::vector<std::int32_t> reference(const Move<double>& m, const AxisScale& scale) {
  const std::int64_t ticks = stream_ticks(m, scale.period_us);
  std::vector<std::int32_t> out;
  for (std::int64_t n = 0; n <= ticks; ++n) {
    const double t = std::min(static_cast<double>(n) * scale.period_s(), m.duration());
    out.push_back(static_cast<std::int32_t>(std::nearbyint(m.at(t).p * scale.counts_per_unit)));
  }
  return out;
}

template <typename Stream, typename Plan>
void expect_streams(const Plan& plan, const std::vector<std::int32_t>& ref, const char* scalar) {
  Stream s{plan, 0};
  bool last = false;
  std::size_t n = 0;
  int worst = 0;
  std::int32_t target = 0;
  for (; !last && n < ref.size() + 1; ++n) {
    target = s.next(last);
    if (n < ref.size()) worst = std::max(worst, std::abs(target - ref[n]));
  }
  EXPECT_EQ(n, ref.size()) << scalar << ": the stream's last tick";
  EXPECT_LE(worst, 1) << scalar << ": largest difference from the move, in counts";
  EXPECT_EQ(target, ref.back()) << scalar << ": the last target";
}

template <typename T>
struct Tables {
  std::vector<ExportedPiece<T>> pieces;
  std::vector<ExportedImpulse<T>> impulses;
  ExportedPlan<T> plan{};
};

template <typename T>
void make_tables(const Move<double>& m, const std::array<Piece, 64>& pc, std::size_t n, const AxisScale& scale,
                 Tables<T>& out) {
  for (std::size_t i = 0; i < n; ++i) {
    ExportedPiece<T> e{static_cast<T>(pc[i].start), static_cast<T>(pc[i].length), {}, static_cast<T>(pc[i].zr),
                       static_cast<T>(pc[i].zi), pc[i].trig};
    for (std::size_t k = 0; k <= kMaxPieceDegree; ++k) e.c[k] = static_cast<T>(pc[i].c[k]);
    out.pieces.push_back(e);
  }
  for (std::size_t i = 0; i < m.shaper().count; ++i) {
    out.impulses.push_back({static_cast<T>(m.shaper().amp[i]), static_cast<T>(m.shaper().time[i])});
  }
  out.plan = {out.pieces.data(), out.pieces.size(), out.impulses.data(), out.impulses.size(),
              static_cast<T>(m.profile().duration()), static_cast<T>(m.profile().distance()),
              static_cast<T>(m.distance()), static_cast<T>(scale.counts_per_unit), static_cast<T>(scale.period_s()),
              static_cast<std::int32_t>(stream_ticks(m, scale.period_us)),
              static_cast<std::int32_t>(std::nearbyint(m.distance() * scale.counts_per_unit))};
}

TEST(ExportedPlan, EveryTickWithinOneCountOfThePlannedMoveOverASeededGrid) {
  std::mt19937_64 rng{20261205};
  auto uni = [&](double lo, double hi) { return std::uniform_real_distribution<double>{lo, hi}(rng); };
  const char* profiles[] = {"scurve", "scurve-damped", "ramp-versine", "pseudopoly", "poly345", "trapezoid",
                            "jerk-limited"};
  const ShaperKind shapers[] = {ShaperKind::none, ShaperKind::zv, ShaperKind::zvd, ShaperKind::ei};
  int checked = 0;
  for (int i = 0; i < 240; ++i) {
    MoveRequest rq{};
    const char* name = profiles[i % 7];
    ASSERT_TRUE(parse_profile_kind(name, rq.profile));
    rq.distance = (i % 2 ? -1.0 : 1.0) * uni(0.005, 0.3);
    const double omega = uni(8.0, 80.0);
    if (rq.profile == ProfileKind::trapezoid || rq.profile == ProfileKind::jerk_limited) {
      rq.limits.vmax = uni(0.1, 1.0);
      rq.limits.amax = uni(1.0, 20.0);
      if (rq.profile == ProfileKind::jerk_limited) rq.limits.jmax = uni(50.0, 2000.0);
    } else {
      rq.time = uni(0.2, 1.5);
    }
    if (rq.profile == ProfileKind::scurve || rq.profile == ProfileKind::scurve_damped ||
        rq.profile == ProfileKind::ramp_versine) {
      rq.set_mode(omega);
    }
    if (rq.profile == ProfileKind::scurve_damped) rq.modes[0].zeta = uni(0.0, 0.2);
    if (rq.profile == ProfileKind::pseudopoly) {
      rq.gamma_count = 4;
      const double g0 = uni(3.0, 4.0);
      for (std::size_t k = 0; k < 4; ++k) rq.gammas[k] = g0 + static_cast<double>(k) * uni(0.6, 1.4);
    }
    rq.shaper = shapers[(i / 7) % 4];
    if (rq.shaper != ShaperKind::none) {
      rq.set_mode(omega, uni(0.0, 0.1));
    }
    Move<double> m{};
    if (plan(rq, m) != Status::ok) continue;
    const AxisScale scale{uni(1e4, 1e6), (i % 3 == 0) ? 500U : 1000U};
    SCOPED_TRACE(::testing::Message() << "move " << i << ": " << name << ", shaper " << to_string(rq.shaper)
                                      << ", distance " << rq.distance << ", counts/unit " << scale.counts_per_unit);
    const std::vector<std::int32_t> ref = reference(m, scale);

    std::array<Piece, 64> pc{};
    std::size_t n = 0;
    ASSERT_EQ(fixed::move_pieces(m.profile(), fixed::Scale{scale}, pc.data(), pc.size(), n), Status::ok);
    Tables<double> d;
    make_tables(m, pc, n, scale, d);
    expect_streams<ExportedStream<double>>(d.plan, ref, "double");
    Tables<float> f;
    make_tables(m, pc, n, scale, f);
    expect_streams<ExportedStream<float>>(f.plan, ref, "float");

    static fixed::PolyMotion motion{};
    ASSERT_EQ(motion.build(m, fixed::Scale{scale}), Status::ok);
    const FixedExportedPlan fx{motion.view()};
    expect_streams<FixedExportedStream>(fx, ref, "fixed");
    ++checked;
  }
  EXPECT_GE(checked, 200) << "moves of the grid that planned";
}

TEST(ExportedPlan, PiecesBeyondTheCapacityAreRefused) {
  MoveRequest rq{};
  ASSERT_TRUE(parse_profile_kind("scurve", rq.profile));
  rq.distance = 0.05;
  rq.time = 0.6;
  rq.set_mode(22.0);
  Move<double> m{};
  ASSERT_EQ(plan(rq, m), Status::ok);
  std::array<Piece, 64> pc{};
  std::size_t n = 0;
  ASSERT_EQ(fixed::move_pieces(m.profile(), fixed::Scale{AxisScale{1e6, 1000}}, pc.data(), pc.size(), n), Status::ok);
  ASSERT_GT(n, 1U);
  std::size_t fewer = 99;
  EXPECT_EQ(fixed::move_pieces(m.profile(), fixed::Scale{AxisScale{1e6, 1000}}, pc.data(), n - 1, fewer),
            Status::table_too_small);
}

}  // namespace
}  // namespace settle::core
