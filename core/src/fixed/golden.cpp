// SPDX-License-Identifier: Apache-2.0
// The golden list: every evaluator kind once (both S-curve variants, ramp-versine, 3-4-5, a
// piecewise pseudo-polynomial with whole exponents, a trapezoid, ZV and ZVD shapers whose impulses
// fall between ticks, and cam tables of three orders), each motion also as a position plan. Planning stays libm-free: timed requests,
// whole exponents, zeta = 0 for the shaped moves (exp(0) and sqrt(1) are exact everywhere).
#include "settle/core/fixed/golden.hpp"

#include <array>
#include <cstdint>

#include "settle/core/fixed/cam.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/position.hpp"
#include "settle/core/planner.hpp"

namespace settle::core::fixed {

namespace {

class Fold {
 public:
  void add(std::uint64_t x) noexcept {
    h_ = (h_ ^ x) * 0x9E3779B97F4A7C15ULL;
    h_ ^= h_ >> 29;
  }
  void add_signed(std::int64_t x) noexcept { add(static_cast<std::uint64_t>(x)); }
  void add(const Sample& s) noexcept {
    add_signed(s.p);
    add_signed(s.v);
    add_signed(s.a);
  }
  [[nodiscard]] std::uint64_t value() const noexcept { return h_; }

 private:
  std::uint64_t h_{0xCBF29CE484222325ULL};
};

using GoldenMotion = BasicMotion<16, 4>;
using GoldenPlan = BasicPositionPlan<16>;  // the list needs 15 intervals at most

void fold_motion(const GoldenMotion& m, Fold& f) noexcept {
  const MotionHeader& h = m.header();
  for (std::int64_t x : {h.end, h.final_p, std::int64_t{h.target}, std::int64_t{h.end_tick}, std::int64_t{h.segments},
                         std::int64_t{h.tracks}, std::int64_t{h.v_frac}, std::int64_t{h.a_frac}}) {
    f.add_signed(x);
  }
  for (std::size_t i = 0; i < h.segments; ++i) {
    const Segment& g = m.segment(i);
    f.add_signed(g.start);
    f.add(g.ds);
    for (std::int64_t c : g.c) f.add_signed(c);
    f.add_signed(g.zr);
    f.add_signed(g.zi);
    for (const Factor& x : g.dsp) f.add_signed((std::int64_t{x.exp} << 32) | x.mant);
    for (const Factor& x : {g.kv, g.ka, g.rot_u, g.rot_sum, g.rot_diff}) {
      f.add_signed((std::int64_t{x.exp} << 32) | x.mant);
    }
    for (std::uint8_t s : g.sh) f.add(s);
    f.add(static_cast<std::uint64_t>(g.degree) | (g.trig ? 0x100U : 0U) | (g.steppable ? 0x10000U : 0U));
  }
  for (std::size_t i = 0; i < h.tracks; ++i) {
    const Track& t = m.track(i);
    f.add_signed(t.delay);
    f.add(t.frac);
    f.add_signed(t.weight);
  }
}

void fold_plan(const GoldenPlan& p, Fold& f) noexcept {
  const PositionHeader& h = p.header();
  for (std::int64_t x : {std::int64_t{h.end_tick}, std::int64_t{h.target}, std::int64_t{h.rot_near},
                         std::int64_t{h.rot_hi}, std::int64_t{h.rot_lo}, std::int64_t{h.rot_exp},
                         std::int64_t{h.intervals}}) {
    f.add_signed(x);
  }
  for (std::size_t i = 0; i < h.intervals; ++i) {
    const PositionInterval& iv = p.interval(i);
    for (std::int64_t x : iv.x) f.add_signed(x);
    f.add_signed(iv.first);
    f.add_signed(iv.dsh);
    for (std::uint8_t s : iv.sh) f.add(s);
    f.add(static_cast<std::uint64_t>(iv.degree) | (static_cast<std::uint64_t>(iv.flags) << 8U));
  }
}

constexpr GoldenMove kMoves[] = {
    {"scurve", ProfileKind::scurve, 0.1, 0.5, 22.05, 0.0, {1e6, 1000}, ShaperKind::none},
    {"scurve_damped", ProfileKind::scurve_damped, -0.05, 0.3, 30.0, 0.1, {1e6, 500}, ShaperKind::none},
    {"ramp_versine", ProfileKind::ramp_versine, 1.0, 0.74, 28.28, 0.159, {166886.0, 1000}, ShaperKind::none},
    {"poly345", ProfileKind::poly345, 0.2, 1.0, 0.0, 0.0, {2e6, 2000}, ShaperKind::none},
    {"pseudopoly", ProfileKind::pseudopoly, 3.0, 0.8, 0.0, 0.0, {3e5, 1000}, ShaperKind::none},
    {"trapezoid", ProfileKind::trapezoid, -0.3, 0.6, 0.0, 0.0, {1e7, 1000}, ShaperKind::none},
    {"scurve_zv", ProfileKind::scurve, 0.02, 0.25, 40.0, 0.0, {1e6, 250}, ShaperKind::zv},
    {"scurve_damped_zvd", ProfileKind::scurve_damped, 0.4, 0.9, 12.0, 0.2, {4e6, 1000}, ShaperKind::zvd},
};

}  // namespace

std::span<const GoldenMove> golden_moves() noexcept { return kMoves; }

Status plan_golden(const GoldenMove& g, Move<double>& out) noexcept {
  MoveRequest r{};
  r.profile = g.kind;
  r.distance = g.distance;
  r.time = g.time;
  if (g.omega > 0.0) r.set_mode(g.omega, g.zeta);
  if (g.kind == ProfileKind::pseudopoly) {
    r.gamma_count = 4;
    r.gammas[0] = 3.0;
    r.gammas[1] = 5.0;
    r.gammas[2] = 7.0;
    r.gammas[3] = 9.0;
  }
  r.shaper = g.shaper;
  if (g.shaper != ShaperKind::none) r.modes[0].zeta = 0.0;  // the designed shaper's exp(-zeta pi/...) is then exp(0)
  return plan(r, out);
}

GoldenResult golden_checksum() noexcept {
  GoldenResult r{};
  Fold build{}, ticks{}, plan{}, positions{};
  auto fail = [&](Status st) {
    if (r.status == Status::ok) r.status = st;
  };
  // Static, not on the stack: an M0 image's stack is a few KiB and plan() needs most of it. (They
  // are constant-initialised, so no guard variable; golden_checksum is not reentrant.)
  static GoldenMotion motion{};
  static MotionStepper<GoldenMotion::kMaxTracks> stepper{};
  static GoldenPlan position_plan{};
  static std::array<CamKnot, 96> knots{};
  static constexpr CamOrder kCams[] = {CamOrder::quintic, CamOrder::cubic, CamOrder::linear};
  int cam = 0;
  for (const GoldenMove& g : kMoves) {
    static Move<double> move{};
    Status st = plan_golden(g, move);
    const Scale scale = golden_scale(g);
    if (st == Status::ok) st = motion.build(move, scale);
    if (st != Status::ok) {
      fail(st);
      continue;
    }
    ++r.moves;
    fold_motion(motion, build);
    stepper = MotionStepper<GoldenMotion::kMaxTracks>{motion, -2};
    for (std::int32_t n = -2; n <= motion.end_tick() + 2; ++n) {
      ticks.add(motion.at_tick(n));
      ticks.add(stepper.next());
      r.samples += 2;
    }
    st = position_plan.build(motion);
    if (st != Status::ok) {
      fail(st);
      continue;
    }
    fold_plan(position_plan, plan);
    PositionStepper ps{position_plan, -2};
    for (std::int32_t n = -2; n <= position_plan.end_tick() + 2; ++n) {
      positions.add_signed(ps.next());
      ++r.position_samples;
    }
    // Every move also as a cam table, cycling through the orders.
    {
      CamTable table{};
      st = build_cam_table(move, scale, kCams[cam++ % 3], knots, table, 1e9);
      if (st != Status::ok) {
        fail(st);
        continue;
      }
      ++r.moves;
      for (std::size_t k = 0; k < table.knots(); ++k) {
        build.add_signed(knots[k].p);
        build.add_signed(knots[k].v);
        build.add_signed(knots[k].a);
      }
      CamStepper cs{table, -2};
      for (std::int32_t n = -2; n <= table.end_tick() + 2; ++n) {
        ticks.add(table.at_tick(n));
        ticks.add(cs.next());
        r.samples += 2;
      }
    }
  }
  r.build = build.value();
  r.ticks = ticks.value();
  r.plan = plan.value();
  r.positions = positions.value();
  return r;
}

}  // namespace settle::core::fixed
