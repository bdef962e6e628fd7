// SPDX-License-Identifier: Apache-2.0
// Per-tick cost of the fixed-point evaluators: random access (at_tick, ticks in order), stepping
// (next) and position-only stepping (the position plan), for every kind of move, shaped and not,
// and the cam tables; the double evaluator on the same moves for reference; the two fixed-point
// sines; and, apart, what a build costs at planning time. One benchmark iteration is one tick.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "settle/core/fixed/cam.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/position.hpp"
#include "settle/core/fixed/trig.hpp"
#include "settle/core/planner.hpp"

using namespace settle::core;

namespace {

struct Case {
  const char* name;
  ProfileKind kind;
  ShaperKind shaper;
};

// Half a second at 1 kHz (500 ticks), 100 mm at 1 um, a 22 rad/s mode (seed 000's beam).
constexpr Case kCases[] = {
    {"scurve", ProfileKind::scurve, ShaperKind::none},
    {"scurve_damped", ProfileKind::scurve_damped, ShaperKind::none},
    {"ramp_versine", ProfileKind::ramp_versine, ShaperKind::none},
    {"poly345", ProfileKind::poly345, ShaperKind::none},
    {"pseudopoly", ProfileKind::pseudopoly, ShaperKind::none},
    {"trapezoid", ProfileKind::trapezoid, ShaperKind::none},
    {"scurve_damped+zvd", ProfileKind::scurve_damped, ShaperKind::zvd},
};
constexpr fixed::Scale kScale{{1e6, 1000}, 16, 16};

Move<double> plan_case(const Case& c) {
  MoveRequest r{};
  r.profile = c.kind;
  r.distance = 0.1;
  r.time = 0.5;
  r.set_mode(22.05, c.kind == ProfileKind::scurve ? 0.0 : 0.1);
  r.shaper = c.shaper;
  if (c.kind == ProfileKind::pseudopoly) {
    r.gamma_count = 3;
    r.gammas = {3.024, 4.565, 5.874};  // seed 004's optimum
  }
  Move<double> m{};
  if (plan(r, m) != Status::ok) std::abort();
  return m;
}

const fixed::PolyMotion& motion_of(int id) {
  static std::array<std::unique_ptr<fixed::PolyMotion>, std::size(kCases)> cache{};
  auto& slot = cache[static_cast<std::size_t>(id)];
  if (!slot) {
    slot = std::make_unique<fixed::PolyMotion>();
    if (slot->build(plan_case(kCases[id]), kScale) != Status::ok) std::abort();
  }
  return *slot;
}

void BM_double_at(benchmark::State& st) {
  const auto id = static_cast<int>(st.range(0));
  const Move<double> m = plan_case(kCases[id]);
  const auto end = motion_of(id).end_tick();
  std::int32_t n = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(m.at(n * 1e-3));
    if (++n > end) n = 0;
  }
  st.SetLabel(kCases[id].name);
}

void BM_fixed_at_tick(benchmark::State& st) {
  const auto id = static_cast<int>(st.range(0));
  const fixed::PolyMotion& m = motion_of(id);
  std::int32_t n = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(m.at_tick(n));
    if (++n > m.end_tick()) n = 0;
  }
  st.SetLabel(kCases[id].name);
}

void BM_fixed_next(benchmark::State& st) {
  const auto id = static_cast<int>(st.range(0));
  const fixed::PolyMotion& m = motion_of(id);
  fixed::MotionStepper<fixed::PolyMotion::kMaxTracks> s{m};
  for (auto _ : st) {
    benchmark::DoNotOptimize(s.next());
    if (s.tick() > m.end_tick()) s.restart(0);
  }
  st.SetLabel(kCases[id].name);
}

// Position only (the servo loop's fixed-point path), from the motion's position plan.
void BM_fixed_position(benchmark::State& st) {
  const auto id = static_cast<int>(st.range(0));
  const fixed::PolyMotion& m = motion_of(id);
  auto plan = std::make_unique<fixed::PolyPositionPlan>();
  if (plan->build(m) != Status::ok) std::abort();
  fixed::PositionStepper s{*plan};
  for (auto _ : st) {
    benchmark::DoNotOptimize(s.next());
    if (s.tick() > m.end_tick()) s.restart(0);
  }
  st.SetLabel(kCases[id].name);
}

// The damped S-curve as 512-, 128- and 32-knot tables (knots every 1, 4 and 16 ticks).
struct Cam {
  std::vector<fixed::CamKnot> knots;
  fixed::CamTable table{};
};
const Cam& cam_of(fixed::CamOrder order, std::size_t knots) {
  static std::vector<std::unique_ptr<Cam>> cache;
  for (const auto& c : cache) {
    if (c->table.order() == order && c->knots.size() == knots) return *c;
  }
  auto c = std::make_unique<Cam>();
  c->knots.resize(knots);
  if (fixed::build_cam_table(plan_case(kCases[1]), kScale, order, c->knots, c->table, 1e9) != Status::ok) std::abort();
  cache.push_back(std::move(c));
  return *cache.back();
}

constexpr fixed::CamOrder kOrders[] = {fixed::CamOrder::linear, fixed::CamOrder::cubic, fixed::CamOrder::quintic};

void BM_cam_at_tick(benchmark::State& st) {
  const Cam& c = cam_of(kOrders[st.range(0)], static_cast<std::size_t>(st.range(1)));
  std::int32_t n = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(c.table.at_tick(n));
    if (++n > c.table.end_tick()) n = 0;
  }
}

void BM_cam_next(benchmark::State& st) {
  const Cam& c = cam_of(kOrders[st.range(0)], static_cast<std::size_t>(st.range(1)));
  fixed::CamStepper s{c.table};
  for (auto _ : st) {
    benchmark::DoNotOptimize(s.next());
    if (s.tick() > c.table.end_tick()) s.restart(0);
  }
}

void BM_sincos_table(benchmark::State& st) {
  std::uint32_t a = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(fixed::sincos(a));
    a += 0x9E3779B9U;
  }
}

void BM_sincos_poly(benchmark::State& st) {
  std::uint32_t a = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(fixed::sincos_poly(a));
    a += 0x9E3779B9U;
  }
}

// Planning time, not per tick: converting a planned move.
void BM_build(benchmark::State& st) {
  const auto id = static_cast<int>(st.range(0));
  const Move<double> m = plan_case(kCases[id]);
  auto out = std::make_unique<fixed::PolyMotion>();
  for (auto _ : st) benchmark::DoNotOptimize(out->build(m, kScale));
  st.SetLabel(kCases[id].name);
}

// Planning time: a built motion's position plan.
void BM_build_position(benchmark::State& st) {
  const auto id = static_cast<int>(st.range(0));
  const fixed::PolyMotion& m = motion_of(id);
  auto out = std::make_unique<fixed::PolyPositionPlan>();
  for (auto _ : st) benchmark::DoNotOptimize(out->build(m));
  st.SetLabel(kCases[id].name);
}

}  // namespace

BENCHMARK(BM_double_at)->DenseRange(0, std::size(kCases) - 1);
BENCHMARK(BM_fixed_at_tick)->DenseRange(0, std::size(kCases) - 1);
BENCHMARK(BM_fixed_next)->DenseRange(0, std::size(kCases) - 1);
BENCHMARK(BM_fixed_position)->DenseRange(0, std::size(kCases) - 1);
BENCHMARK(BM_cam_at_tick)->ArgsProduct({{0, 1, 2}, {512, 32}});
BENCHMARK(BM_cam_next)->ArgsProduct({{0, 1, 2}, {512, 32}});
BENCHMARK(BM_sincos_table);
BENCHMARK(BM_sincos_poly);
BENCHMARK(BM_build)->DenseRange(0, std::size(kCases) - 1);
BENCHMARK(BM_build_position)->DenseRange(0, std::size(kCases) - 1);
