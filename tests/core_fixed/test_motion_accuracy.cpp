// SPDX-License-Identifier: Apache-2.0
// The fixed-point evaluator against the double one over seeded random moves (fixed_cases.hpp):
// position within one count everywhere, velocity and acceleration within half an output LSB plus
// a tiny fraction of their peak, and the stepping form equal to random access within one count
// (v and a within a few LSB). The numbers measured are printed for docs/fixed-point.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "fixed_cases.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/position.hpp"

#ifndef SETTLE_FIXED_CLOSED_MOVES
#define SETTLE_FIXED_CLOSED_MOVES 100000
#endif
#ifndef SETTLE_FIXED_POLY_MOVES
#define SETTLE_FIXED_POLY_MOVES 3000
#endif
#ifndef SETTLE_FIXED_STEPPED_MOVES
#define SETTLE_FIXED_STEPPED_MOVES 2000
#endif
#ifndef SETTLE_FIXED_TICKS_PER_MOVE  // random ticks checked per move besides its boundaries; 0: all
#define SETTLE_FIXED_TICKS_PER_MOVE 40
#endif

using namespace settle;
using core::Status;
using core::fixed::PolyMotion;

namespace {

// Worst errors of one group of moves. v and a also as the excess over `lsb_allowance` output LSB
// relative to the move's peak, which is how they scale (for peaks of 1024 LSB and more: below,
// the excess is a matter of ties in rounding a value that is itself a few LSB).
struct Worst {
  long moves{0}, ticks{0};
  double p{0.0}, v{0.0}, a{0.0}, v_rel{0.0}, a_rel{0.0};
  void add(const test::Errors& e, double vpk, double apk, double lsb_allowance) {
    ++ticks;
    p = std::max(p, e.p);
    v = std::max(v, e.v);
    a = std::max(a, e.a);
    if (vpk >= 1024.0) v_rel = std::max(v_rel, (e.v - lsb_allowance) / vpk);
    if (apk >= 1024.0) a_rel = std::max(a_rel, (e.a - lsb_allowance) / apk);
  }
};

std::string group(const core::MoveRequest& r) {
  return std::string{core::to_string(r.profile)} + (r.shaper != core::ShaperKind::none ? "+shaper" : "");
}

// The ticks worth checking: around every segment boundary of every track, the first and last
// ticks, and `random` more (or every tick of a short move).
std::vector<std::int32_t> ticks_of(const PolyMotion& m, std::mt19937_64& rng, int random) {
  std::vector<std::int32_t> out;
  const std::int32_t end = m.end_tick();
  if (random == 0 || end <= 4 * random) {
    for (std::int32_t n = 0; n <= end; ++n) out.push_back(n);
    return out;
  }
  for (std::int32_t n : {0, 1, 2, end - 2, end - 1, end}) out.push_back(n);
  for (unsigned t = 0; t < m.header().tracks; ++t) {
    const auto& tr = m.track(t);
    for (unsigned k = 0; k <= m.header().segments; ++k) {
      const std::int64_t edge = k < m.header().segments ? m.segment(k).start : m.header().end;
      const auto first = static_cast<std::int32_t>(tr.delay + ((edge + tr.frac + 0xFFFFFFFFLL) >> 32));
      for (std::int32_t n : {first - 1, first}) out.push_back(std::clamp(n, 0, end));
    }
  }
  for (int i = 0; i < random; ++i) out.push_back(static_cast<std::int32_t>(rng() % static_cast<std::uint64_t>(end)));
  return out;
}

double peak_a(const test::FixedCase& c, double observed) {
  const double a = c.move.peaks().a;
  if (!std::isfinite(a)) return observed;
  return std::ldexp(a * c.scale.axis.counts_per_unit * c.scale.axis.period_s() * c.scale.axis.period_s(), c.scale.accel_frac_bits);
}

double peak_v(const test::FixedCase& c) {
  return std::ldexp(c.move.peaks().v * c.scale.axis.counts_per_unit * c.scale.axis.period_s(), c.scale.velocity_frac_bits);
}

struct Suite {
  std::map<std::string, Worst> worst;
  std::map<std::string, long> refused;
  long built{0};

  void run(test::Kinds kinds, int moves, std::uint64_t seed, double lsb_allowance) {
    test::FixedCaseGen gen{std::mt19937_64{seed}, kinds};
    std::mt19937_64 pick{seed + 1};
    auto motion = std::make_unique<PolyMotion>();
    for (int i = 0; i < moves; ++i) {
      test::FixedCase c{};
      if (!gen.next(c)) {
        --i;  // a request the planner refuses is not a move
        continue;
      }
      const Status st = motion->build(c.move, c.scale);
      if (st != Status::ok) {
        ++refused[group(c.req) + ": " + core::to_string(st)];
        continue;
      }
      ++built;
      Worst& w = worst[group(c.req)];
      ++w.moves;
      const double vpk = peak_v(c);
      std::vector<std::pair<std::int32_t, test::Errors>> errs;
      double amax = 0.0;
      for (std::int32_t n : ticks_of(*motion, pick, SETTLE_FIXED_TICKS_PER_MOVE)) {
        const test::Errors e = test::errors_at(c.move, c.scale, n, motion->at_tick(n));
        amax = std::max(amax, std::fabs(e.ref.a));
        errs.emplace_back(n, e);
      }
      const double apk = peak_a(c, amax);
      for (const auto& [n, e] : errs) {
        w.add(e, vpk, apk, lsb_allowance);
        if (e.p > 1.0) {
          ADD_FAILURE() << group(c.req) << " tick " << n << " of " << motion->end_tick() << ": position off by "
                        << e.p << " counts (distance " << c.req.distance * c.scale.axis.counts_per_unit << ")";
        }
      }
    }
  }

  void print(const char* title) const {
    std::printf("%s: %ld moves built\n", title, built);
    std::printf("  %-22s %8s %10s %8s %9s %10s %9s %10s\n", "group", "moves", "ticks", "p cnt", "v LSB", "v rel", "a LSB",
                "a rel");
    for (const auto& [g, w] : worst) {
      std::printf("  %-22s %8ld %10ld %8.3f %9.2f %10.2e %9.2f %10.2e\n", g.c_str(), w.moves, w.ticks, w.p, w.v,
                  w.v_rel, w.a, w.a_rel);
    }
    for (const auto& [k, n] : refused) std::printf("  refused %s: %ld\n", k.c_str(), n);
  }
};

}  // namespace

// Every closed form (ramp-cycloid both variants, ramp-versine, 3-4-5, trapezoid, jerk-limited),
// 20 % shaped (ZV, ZVD, EI at non-integer impulse times).
TEST(FixedAccuracy, ClosedFormsWithinOneCount) {
  Suite s{};
  s.run(test::Kinds::closed_forms, SETTLE_FIXED_CLOSED_MOVES, 20261122, 0.5);
  s.print("closed forms");
  long refusals = 0;
  for (const auto& [k, n] : s.refused) refusals += n;
  EXPECT_LE(refusals, SETTLE_FIXED_CLOSED_MOVES / 1000) << "a closed-form move of <= 2^24 counts should fit";
  for (const auto& [g, w] : s.worst) {
    EXPECT_LE(w.p, 1.0) << g;
    EXPECT_LE(w.v_rel, 0x1p-24) << g;  // |dv| <= 0.5 LSB + 6e-8 peak
    EXPECT_LE(w.a_rel, 0x1p-24) << g;  // |da| <= 0.5 LSB + 6e-8 peak
  }
}

// Pseudo-polynomials, any 3..8 exponents (piecewise quintic fit): position within one count;
// v and a are as good as the fit's tolerances, within one LSB plus a fraction of their peak.
TEST(FixedAccuracy, PseudoPolyWithinOneCount) {
  Suite s{};
  s.run(test::Kinds::pseudopoly, SETTLE_FIXED_POLY_MOVES, 4004, 1.0);
  s.print("pseudo-polynomials");
  long refusals = 0;
  for (const auto& [k, n] : s.refused) {
    refusals += n;
    EXPECT_TRUE(k.find("precision_insufficient") != std::string::npos || k.find("table_too_small") != std::string::npos)
        << k;
  }
  EXPECT_LE(refusals, SETTLE_FIXED_POLY_MOVES / 20) << "only very short moves over large distances are refused";
  for (const auto& [g, w] : s.worst) {
    EXPECT_LE(w.p, 1.0) << g;
    EXPECT_LE(w.v_rel, 0.02) << g;
    EXPECT_LE(w.a_rel, 0.05) << g;
  }
}

// next() against at_tick() over whole moves, from the start and from a random tick.
TEST(FixedAccuracy, SteppingMatchesRandomAccess) {
  test::FixedCaseGen gen{std::mt19937_64{77}, test::Kinds::all};
  std::mt19937_64 pick{78};
  auto motion = std::make_unique<PolyMotion>();
  long ticks = 0, identical = 0, moves = 0, stepped_segments = 0, segments = 0;
  std::int64_t dp = 0, dv = 0, da = 0;
  double worst_vs_double = 0.0;
  for (int i = 0; i < SETTLE_FIXED_STEPPED_MOVES; ++i) {
    test::FixedCase c{};
    if (!gen.next(c) || motion->build(c.move, c.scale) != Status::ok) continue;
    ++moves;
    for (unsigned k = 0; k < motion->header().segments; ++k) {
      ++segments;
      stepped_segments += motion->segment(k).steppable ? 1 : 0;
    }
    const std::int32_t end = motion->end_tick();
    const std::int32_t from = (i % 2 == 0) ? -3 : static_cast<std::int32_t>(pick() % static_cast<std::uint64_t>(end + 1));
    core::fixed::MotionStepper<PolyMotion::kMaxTracks> st{*motion, from};
    for (std::int32_t n = from; n <= end + 2; ++n) {
      const core::fixed::Sample a = motion->at_tick(n), b = st.next();
      ++ticks;
      identical += (a.p == b.p && a.v == b.v && a.a == b.a) ? 1 : 0;
      dp = std::max<std::int64_t>(dp, std::llabs(std::int64_t{a.p} - b.p));
      dv = std::max<std::int64_t>(dv, std::llabs(std::int64_t{a.v} - b.v));
      da = std::max<std::int64_t>(da, std::llabs(std::int64_t{a.a} - b.a));
      if (n >= 0 && a.p != b.p) {
        worst_vs_double = std::max(worst_vs_double, test::errors_at(c.move, c.scale, n, b).p);
      }
    }
  }
  std::printf("stepping: %ld moves, %ld ticks, %.5f %% bit-identical to random access; max |diff| p %" PRId64
              " v %" PRId64 " a %" PRId64 " LSB; %ld of %ld segments stepped; worst stepped p vs double %.3f\n",
              moves, ticks, 100.0 * static_cast<double>(identical) / static_cast<double>(ticks), dp, dv, da,
              stepped_segments, segments, worst_vs_double);
  EXPECT_LE(dp, 1);
  EXPECT_LE(dv, 4);  // 3 seen over 1e9 soak ticks: each form within 0.5 LSB + 2^-28 of the peak
  EXPECT_LE(da, 4);
  EXPECT_LE(worst_vs_double, 1.0);
  EXPECT_GE(identical, ticks * 99 / 100);
}

// The position-only stepper (the servo loop's per-tick path) against at_tick() and the double
// evaluator over whole moves, started at -3 or at a random tick: within one count of both, equal
// to at_tick() bit for bit at the first tick of every interval (where its state is the sum
// at_tick() forms), and restarting anywhere gives what an uninterrupted run gives.
TEST(FixedAccuracy, PositionSteppingMatchesRandomAccess) {
  test::FixedCaseGen gen{std::mt19937_64{79}, test::Kinds::all};
  std::mt19937_64 pick{80};
  auto motion = std::make_unique<PolyMotion>();
  auto plan = std::make_unique<core::fixed::PolyPositionPlan>();
  long ticks = 0, identical = 0, moves = 0, intervals = 0, natural = 0, precise = 0, shaped = 0, anchors = 0;
  std::map<std::string, long> refused;
  std::int64_t dp = 0;
  double worst_vs_double = 0.0;
  std::size_t most = 0;
  for (int i = 0; i < SETTLE_FIXED_STEPPED_MOVES; ++i) {
    test::FixedCase c{};
    if (!gen.next(c) || motion->build(c.move, c.scale) != Status::ok) continue;
    const Status st = plan->build(*motion);
    if (st != Status::ok) {
      ++refused[group(c.req) + ": " + core::to_string(st)];
      continue;
    }
    ++moves;
    shaped += motion->header().tracks > 1 ? 1 : 0;
    const auto& h = plan->header();
    intervals += h.intervals;
    most = std::max<std::size_t>(most, h.intervals);
    for (unsigned k = 0; k < h.intervals; ++k) {
      precise += (plan->interval(k).flags & core::fixed::PositionInterval::kPrecise) != 0 ? 1 : 0;
    }
    // Intervals the drift budget added to the tracks' own boundaries.
    std::vector<std::int32_t> edges;
    for (unsigned t = 0; t < motion->header().tracks; ++t) {
      const auto& tr = motion->track(t);
      for (unsigned k = 0; k <= motion->header().segments; ++k) {
        const std::int64_t edge = k < motion->header().segments ? motion->segment(k).start : motion->header().end;
        edges.push_back(static_cast<std::int32_t>(tr.delay + ((edge + tr.frac + 0xFFFFFFFFLL) >> 32)));
      }
    }
    for (unsigned k = 0; k < h.intervals; ++k) {
      natural += std::find(edges.begin(), edges.end(), plan->interval(k).first) != edges.end() ? 1 : 0;
    }
    const std::int32_t end = plan->end_tick();
    ASSERT_EQ(end, motion->end_tick());
    const std::int32_t from = (i % 2 == 0) ? -3 : static_cast<std::int32_t>(pick() % static_cast<std::uint64_t>(end + 1));
    core::fixed::PositionStepper st_from{*plan, from};
    core::fixed::PositionStepper st_zero{*plan, std::min(from, 0)};
    for (std::int32_t n = std::min(from, 0); n < from; ++n) (void)st_zero.next();
    unsigned next_iv = 0;
    while (next_iv < h.intervals && plan->interval(next_iv).first < from) ++next_iv;
    for (std::int32_t n = from; n <= end + 2; ++n) {
      const std::int32_t a = motion->at_tick(n).p, b = st_from.next(), z = st_zero.next();
      ++ticks;
      identical += a == b ? 1 : 0;
      dp = std::max<std::int64_t>(dp, std::llabs(std::int64_t{a} - b));
      if (b != z) ADD_FAILURE() << "restart at " << from << " differs from a run from the start at tick " << n;
      if (next_iv < h.intervals && plan->interval(next_iv).first == n) {
        ++anchors;
        EXPECT_EQ(a, b) << group(c.req) << ": interval " << next_iv << " starts at tick " << n;
        ++next_iv;
      }
      if (n >= 0) worst_vs_double = std::max(worst_vs_double, test::errors_at(c.move, c.scale, n, {b, 0, 0}).p);
    }
  }
  std::printf("position stepping: %ld moves (%ld shaped), %ld ticks, %.5f %% bit-identical to random access; max "
              "|diff| p %" PRId64 "; %ld intervals (at most %zu in a move, %ld at no segment boundary, %ld with the "
              "64-bit rotation), %ld anchors checked; worst p vs double %.3f\n",
              moves, shaped, ticks, 100.0 * static_cast<double>(identical) / static_cast<double>(ticks), dp, intervals,
              most, intervals - natural, precise, anchors, worst_vs_double);
  for (const auto& [k, n] : refused) std::printf("  refused %s: %ld\n", k.c_str(), n);
  EXPECT_TRUE(refused.empty());
  EXPECT_LE(dp, 1);
  EXPECT_LE(worst_vs_double, 1.0);
  EXPECT_GE(identical, ticks * 99 / 100);
}
