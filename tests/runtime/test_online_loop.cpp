// SPDX-License-Identifier: Apache-2.0
// Online changes in the servo loop (issue 17): halt() and retarget() post into a lock-free
// mailbox, service() plans outside the tick, and the tick switches to the blend at exactly the
// setpoint it was planned for: the setpoints before it are the move's, those after it the blend's,
// with no jump in position, velocity or acceleration, and the drive ends on the blend's end.
// The same in every evaluation: double, float (the Cortex-M4F's) and fixed point, where the blend is
// converted to the loop's scalar when service() plans it and streamed like a move.
// That the blend itself leaves the modes at rest is proven in tests/core/test_online.cpp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <utility>
#include <thread>
#include <type_traits>
#include <vector>

#include "settle/core/multi_axis.hpp"
#include "settle/runtime/servo_loop.hpp"
#include "settle/runtime/setpoint_sequence.hpp"
#include "settle/hal/testing/ideal_drive.hpp"
#include "../support/path_halt_draw.hpp"
#include "ideal_axes.hpp"

using namespace settle;

namespace {

constexpr std::uint32_t kPeriod = 1000;
constexpr double kCpu = 1e6;  // counts per metre
constexpr double kOmega = 22.04871;

core::MoveRequest scurve(double d, double t) {
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.distance = d;
  r.time = t;
  r.set_mode(kOmega);
  return r;
}

core::Move<double> planned(const core::MoveRequest& req) {
  core::Move<double> m{};
  EXPECT_EQ(core::plan(req, m), core::Status::ok);
  return m;
}

runtime::OnlineConfig online_config(const core::Move<double>& m) {
  runtime::OnlineConfig c{};
  c.modes[0] = {kOmega, 0.0};
  c.mode_count = 1;
  c.limits = {1.2 * m.peaks().v, 1.2 * m.peaks().a, 1.2 * m.peaks().j};
  return c;
}

using DoubleLoop = runtime::ServoLoop<double, 1, 4>;
using FloatLoop = runtime::ServoLoop<float, 1, 4, runtime::FloatEvaluation<float>, hal::CanBus, true>;
using FixedLoop = runtime::ServoLoop<double, 1, 4, runtime::FixedEvaluation, hal::CanBus, true>;

template <typename Loop = DoubleLoop>
struct Rig {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  hal::canopen::DriveNodeConfig drive_config{};
  hal::testing::IdealDrive<> drive{hub, drive_config};
  Loop loop{master, kPeriod};
  std::uint64_t now = 0;
  std::vector<std::int32_t> moving;  // what the loop sent while a move (or its blend) was active

  Rig() {
    runtime::AxisConfig a{};
    a.drive.node = hal::canopen::NodeId{1};
    a.drive.heartbeat_timeout_ms = 500;
    a.scale = {kCpu, kPeriod};
    a.vmax = 2.0;
    EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::ok);
    drive.start(now);
    loop.start(now);
    for (int i = 0; i < 2000 && !loop.ready(0); ++i) tick();
    EXPECT_TRUE(loop.ready(0));
  }
  void tick() {
    now += kPeriod;
    hub.set_time_us(now);
    loop.tick(now);
    if (loop.record(0).sent && loop.record(0).moving) moving.push_back(loop.record(0).target);
    drive.process(now);
    for (runtime::LoopEvent e{}; loop.events().pop(e);) {
    }
  }
};

std::int32_t counts(double p) { return static_cast<std::int32_t>(std::nearbyint(p * kCpu)); }

// The setpoints the loop must send: the move's up to the switch index k, then the blend planned
// by core for the switch at k periods on the move's clock, to its end inclusive. Double: from
// Move::at and Blend::at directly (an independent evaluation of the same plan).
std::vector<std::int32_t> expected_with_blend(const core::Move<double>& m, const runtime::OnlineConfig& c,
                                              std::int32_t k, std::optional<double> target, core::Blend& blend) {
  std::vector<std::int32_t> e;
  for (std::int32_t i = 0; i < k; ++i) e.push_back(counts(m.at(i * 1e-3).p));
  core::OnlineRequest r{};
  EXPECT_EQ(core::online_request(m, k * 1e-3, c.modes.data(), c.mode_count, c.limits, target, r), core::Status::ok);
  EXPECT_EQ(core::plan_online(r, blend), core::Status::ok);
  for (std::int32_t i = 0;; ++i) {
    const double u = i * 1e-3;
    e.push_back(counts(blend.at(u).p));
    if (!(u < blend.duration())) break;
  }
  return e;
}

// The same in an evaluation's scalar: what runtime::stream_setpoints gives for the move with the
// blends switched in at their indices (each on the clock of the command it changes). With no blend,
// the move's own setpoints (to check continuity at the switch). `switched`: how many it switched
// in (without it, every one must be).
template <typename Evaluation>
std::vector<std::int32_t> evaluated_with_blends(const core::Move<double>& m,
                                                const std::vector<std::pair<core::Blend, std::int32_t>>& changes,
                                                std::size_t* switched = nullptr) {
  const core::AxisScale scale{kCpu, kPeriod};
  auto stored = std::make_unique<typename Evaluation::Stored>();
  EXPECT_EQ(Evaluation::prepare(m, scale, *stored), core::Status::ok);
  std::vector<std::unique_ptr<typename Evaluation::BlendStored>> blends;
  std::vector<runtime::SetpointSwitch<Evaluation>> switches;
  for (const auto& [blend, at] : changes) {
    blends.push_back(std::make_unique<typename Evaluation::BlendStored>());
    EXPECT_EQ(Evaluation::prepare(blend, scale, *blends.back()), core::Status::ok);
    switches.push_back({blends.back().get(), at});
  }
  std::vector<std::int32_t> e;
  const runtime::SetpointSequence seq = runtime::stream_setpoints<Evaluation>(
      *stored, 0, switches.data(), switches.size(), 1'000'000, [&](std::int32_t sp) { e.push_back(sp); });
  EXPECT_TRUE(seq.ended);
  if (switched != nullptr) {
    *switched = seq.switches;
  } else {
    EXPECT_EQ(seq.switches, switches.size());
  }
  return e;
}

// No jump at the switch: second differences of the setpoints stay within the acceleration limit
// (plus rounding), the first ones within the velocity limit.
void expect_smooth(const std::vector<std::int32_t>& s, const runtime::OnlineConfig& c) {
  const double dv = c.limits.vmax * 1e-3 * kCpu + 1.0, da = c.limits.amax * 1e-6 * kCpu + 2.0;
  for (std::size_t i = 1; i < s.size(); ++i) ASSERT_LE(std::abs(s[i] - s[i - 1]), dv) << i;
  for (std::size_t i = 2; i < s.size(); ++i) ASSERT_LE(std::abs(s[i] - 2 * s[i - 1] + s[i - 2]), da) << i;
}

template <typename Loop = DoubleLoop>
void run_change(std::optional<double> target) {
  Rig<Loop> r;
  const core::MoveRequest req = scurve(0.1, 0.5);
  const core::Move<double> m = planned(req);
  const runtime::OnlineConfig c = online_config(m);
  ASSERT_EQ(r.loop.configure_online(0, c), runtime::LoopStatus::ok);
  ASSERT_EQ(r.loop.submit(0, req), runtime::LoopStatus::ok);
  ASSERT_EQ(r.loop.submit(0, scurve(0.05, 0.3)), runtime::LoopStatus::ok);  // voided by the change
  for (int i = 0; i < 200; ++i) r.tick();
  ASSERT_EQ(r.moving.size(), 200u);
  // "Another context" asks; the owner's service() plans between two ticks.
  ASSERT_TRUE(target ? r.loop.retarget(0, *target) : r.loop.halt(0));
  ASSERT_EQ(r.loop.service(), runtime::LoopStatus::ok);
  for (int i = 0; i < 3000 && !r.loop.idle(); ++i) r.tick();
  EXPECT_TRUE(r.loop.idle());
  EXPECT_EQ(r.loop.online_switches(0), 1u);
  EXPECT_EQ(r.loop.online_missed(0), 0u);
  core::Blend b{};
  constexpr std::int32_t k = 200 + runtime::kOnlineLeadTicks;
  const std::vector<std::int32_t> e = expected_with_blend(m, c, k, target, b);
  ASSERT_EQ(r.moving.size(), e.size());
  if constexpr (std::is_same_v<Loop, DoubleLoop>) {
    for (std::size_t i = 0; i < e.size(); ++i) ASSERT_EQ(r.moving[i], e[i]) << "setpoint " << i;
  } else {
    // In the loop's scalar: exactly what its evaluation gives for the move and then the blend, one
    // by one; within one count of the double plan's (the scalar's resolution at 1e5 counts).
    const auto es = evaluated_with_blends<typename Loop::EvaluationType>(m, {{b, k}});
    const auto whole = evaluated_with_blends<typename Loop::EvaluationType>(m, {});
    ASSERT_EQ(r.moving.size(), es.size());
    for (std::size_t i = 0; i < es.size(); ++i) ASSERT_EQ(r.moving[i], es[i]) << "setpoint " << i;
    for (std::size_t i = 0; i < es.size(); ++i) ASSERT_LE(std::abs(es[i] - e[i]), 1) << "setpoint " << i;
    // Continuity at the switch: the blend's first setpoint is where the move would have been.
    EXPECT_LE(std::abs(r.moving[k] - whole[k]), 1);
  }
  expect_smooth(r.moving, c);
  EXPECT_EQ(r.drive.position(), counts(b.end_position()));
  if (target) {
    EXPECT_EQ(r.drive.position(), counts(*target));
  }
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);  // the queued second move was voided
}

TEST(ServoLoopOnline, HaltSwitchesAtItsSetpointAndStopsWhereTheBlendEnds) { run_change(std::nullopt); }

// A halt whose best is to finish the move (core::OnlineChoice::finish, issue 36: no blend stops
// short of the target before the move's end) is no switch: the loop streams the move unchanged to
// its end, counts the finish, and voids the move queued behind it, as after a blend.
namespace {
// The first setpoint index at which core chooses to finish a halt of m (the loop plans the same
// request); 0 if none does.
std::int32_t first_finish(const core::Move<double>& m, const runtime::OnlineConfig& c) {
  for (std::int32_t i = 10; i < 500; ++i) {
    core::OnlineRequest q{};
    EXPECT_EQ(core::online_request(m, i * 1e-3, c.modes.data(), c.mode_count, c.limits, std::nullopt, q),
              core::Status::ok);
    core::OnlinePlan p{};
    EXPECT_EQ(core::plan_online(q, p), core::Status::ok);
    if (p.choice == core::OnlineChoice::finish) return i;
  }
  return 0;
}
}  // namespace

TEST(ServoLoopOnline, AHaltThatFinishesTheMoveStreamsItUnchangedAndVoidsTheQueue) {
  const core::MoveRequest req = scurve(0.1, 0.5);
  const core::Move<double> m = planned(req);
  const runtime::OnlineConfig c = online_config(m);
  const std::int32_t k = first_finish(m, c);
  ASSERT_GT(k, 0) << "no halt index of the S-curve chooses to finish";
  Rig<> r;
  ASSERT_EQ(r.loop.configure_online(0, c), runtime::LoopStatus::ok);
  ASSERT_EQ(r.loop.submit(0, req), runtime::LoopStatus::ok);
  ASSERT_EQ(r.loop.submit(0, scurve(0.05, 0.3)), runtime::LoopStatus::ok);  // voided by the halt
  for (std::int32_t i = 0; i < k - runtime::kOnlineLeadTicks; ++i) r.tick();
  ASSERT_TRUE(r.loop.halt(0));
  ASSERT_EQ(r.loop.service(), runtime::LoopStatus::ok);
  for (int i = 0; i < 3000 && !r.loop.idle(); ++i) r.tick();
  EXPECT_TRUE(r.loop.idle());
  EXPECT_EQ(r.loop.online_finishes(0), 1u);
  EXPECT_EQ(r.loop.online_switches(0), 0u);
  EXPECT_EQ(r.loop.online_missed(0), 0u);
  std::vector<std::int32_t> e;
  for (std::int32_t i = 0;; ++i) {
    e.push_back(counts(m.at(i * 1e-3).p));
    if (!(i * 1e-3 < m.duration())) break;
  }
  ASSERT_EQ(r.moving.size(), e.size());
  for (std::size_t i = 0; i < e.size(); ++i) ASSERT_EQ(r.moving[i], e[i]) << "setpoint " << i;
  EXPECT_EQ(r.drive.position(), counts(0.1));
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
}

TEST(ServoLoopOnline, RetargetSwitchesAtItsSetpointAndEndsOnTheNewTarget) { run_change(0.04); }

// A queued move's memory at its end (whether finishing it leaves the modes at rest) is taken at
// submit for the axis's online configuration; a move queued before the axis was configured, or
// configured for other modes, is halted for the modes configured since: the S-curve designed for
// kOmega rings on 3 kOmega (no finish there), and its halt at the first index where core finishes
// it for kOmega finishes it.
TEST(ServoLoopOnline, AMoveQueuedBeforeItsAxisWasConfiguredIsHaltedForTheModesConfiguredSince) {
  const core::MoveRequest req = scurve(0.1, 0.5);
  const core::Move<double> m = planned(req);
  const runtime::OnlineConfig c = online_config(m);
  runtime::OnlineConfig other = c;
  other.modes[0] = {3.0 * kOmega, 0.0};
  const std::int32_t k = first_finish(m, c);
  ASSERT_GT(k, 0) << "no halt index of the S-curve chooses to finish";
  core::EndMemory e{};
  ASSERT_EQ(core::end_memory(m, other.modes.data(), 1, e), core::Status::ok);
  ASSERT_GT(std::hypot(e[0].re, e[0].im), 1e-6 * 0.1) << "the move must ring on the other mode";
  for (const bool configured_before : {false, true}) {
    Rig<> r;
    if (configured_before) {
      ASSERT_EQ(r.loop.configure_online(0, other), runtime::LoopStatus::ok);
    }
    ASSERT_EQ(r.loop.submit(0, req), runtime::LoopStatus::ok);
    ASSERT_EQ(r.loop.configure_online(0, c), runtime::LoopStatus::ok);
    for (std::int32_t i = 0; i < k - runtime::kOnlineLeadTicks; ++i) r.tick();
    ASSERT_TRUE(r.loop.halt(0));
    ASSERT_EQ(r.loop.service(), runtime::LoopStatus::ok);
    for (int i = 0; i < 3000 && !r.loop.idle(); ++i) r.tick();
    EXPECT_EQ(r.loop.online_finishes(0), 1u) << configured_before;
    EXPECT_EQ(r.loop.online_switches(0), 0u) << configured_before;
  }
}


TEST(ServoLoopOnline, FloatHaltStreamsTheBlendInFloat) { run_change<FloatLoop>(std::nullopt); }
TEST(ServoLoopOnline, FloatRetargetStreamsTheBlendInFloat) { run_change<FloatLoop>(0.04); }
TEST(ServoLoopOnline, FixedHaltStreamsTheBlendInFixedPoint) { run_change<FixedLoop>(std::nullopt); }
TEST(ServoLoopOnline, FixedRetargetStreamsTheBlendInFixedPoint) { run_change<FixedLoop>(0.04); }

// A halt while a retarget's blend runs is honoured: planned from that blend's state and its own
// mode memory (core::online_request on the blend), streamed from the other slot, switched in at
// its setpoint. The setpoints are the move's, then the first blend's, then the second's, each as
// the loop's evaluation gives it; the drive ends on the second blend's end.
template <typename Loop>
void halt_after_retarget() {
  Rig<Loop> r;
  const core::MoveRequest req = scurve(0.1, 0.5);
  const core::Move<double> m = planned(req);
  const runtime::OnlineConfig c = online_config(m);
  ASSERT_EQ(r.loop.configure_online(0, c), runtime::LoopStatus::ok);
  ASSERT_EQ(r.loop.submit(0, req), runtime::LoopStatus::ok);
  for (int i = 0; i < 200; ++i) r.tick();
  ASSERT_TRUE(r.loop.retarget(0, 0.04));
  ASSERT_EQ(r.loop.service(), runtime::LoopStatus::ok);
  for (int i = 0; i < 50; ++i) r.tick();
  ASSERT_TRUE(r.loop.halt(0));
  ASSERT_EQ(r.loop.service(), runtime::LoopStatus::ok);
  for (int i = 0; i < 3000 && !r.loop.idle(); ++i) r.tick();
  EXPECT_TRUE(r.loop.idle());
  EXPECT_EQ(r.loop.online_switches(0), 2u);
  EXPECT_EQ(r.loop.online_missed(0), 0u);
  // The plans, in double: the retarget at k1 on the move's clock, the halt at k2 on its blend's.
  constexpr std::int32_t k1 = 200 + runtime::kOnlineLeadTicks;
  constexpr std::int32_t k2 = 250 - k1 + runtime::kOnlineLeadTicks;
  core::OnlineRequest r1{}, r2{};
  ASSERT_EQ(core::online_request(m, k1 * 1e-3, c.modes.data(), c.mode_count, c.limits, 0.04, r1), core::Status::ok);
  core::Blend b1{}, b2{};
  ASSERT_EQ(core::plan_online(r1, b1), core::Status::ok);
  ASSERT_EQ(core::online_request(b1, r1, k2 * 1e-3, std::nullopt, r2), core::Status::ok);
  ASSERT_EQ(core::plan_online(r2, b2), core::Status::ok);
  // The setpoints in the loop's scalar: the move's and the first blend's, then the second blend's.
  const std::vector<std::int32_t> e = evaluated_with_blends<typename Loop::EvaluationType>(m, {{b1, k1}, {b2, k2}});
  ASSERT_EQ(r.moving.size(), e.size());
  for (std::size_t i = 0; i < e.size(); ++i) ASSERT_EQ(r.moving[i], e[i]) << "setpoint " << i;
  expect_smooth(r.moving, c);
  EXPECT_EQ(r.drive.position(), counts(b2.end_position()));
}

TEST(ServoLoopOnline, AHaltAfterARetargetIsPlannedFromItsBlendAndSwitchedIn) { halt_after_retarget<DoubleLoop>(); }
TEST(ServoLoopOnline, AHaltAfterARetargetInFloat) { halt_after_retarget<FloatLoop>(); }
TEST(ServoLoopOnline, AHaltAfterARetargetInFixedPoint) { halt_after_retarget<FixedLoop>(); }

// runtime::stream_setpoints is what the loop streams: over a seeded grid of halts and retargets at
// random setpoints of the move (up to and past its last), and for some a halt on the running blend
// a random number of setpoints later, every setpoint the loop sent equals the exported sequence's
// for the same plans (made here in double as service() makes them), and the switches agree. A
// halt that finishes the move is no switch; a change whose index the command never reaches is
// missed by both.
template <typename Loop>
void loop_streams_the_exported_sequence(std::uint32_t seed) {
  using Evaluation = typename Loop::EvaluationType;
  const core::MoveRequest req = scurve(0.1, 0.5);
  const core::Move<double> m = planned(req);
  const runtime::OnlineConfig c = online_config(m);
  constexpr std::int32_t lead = runtime::kOnlineLeadTicks;
  std::mt19937 rng{seed};
  int compared = 0, switched = 0, chained = 0;
  for (int n = 0; n < 24; ++n) {
    const auto t1 = std::uniform_int_distribution<std::int32_t>{1, 505}(rng);
    const bool retarget = std::bernoulli_distribution{0.5}(rng);
    const double target = std::uniform_real_distribution<double>{-0.02, 0.12}(rng);
    const bool second = std::bernoulli_distribution{0.5}(rng);
    const double second_at = std::uniform_real_distribution<double>{0.0, 1.0}(rng);
    // service()'s plan of the first change, at its switch index on the move's clock.
    const std::int32_t k1 = t1 + lead;
    const std::optional<double> tgt = retarget ? std::optional<double>{target} : std::nullopt;
    core::OnlineRequest r1{};
    core::OnlinePlan p1{};
    if (core::online_request(m, k1 * 1e-3, c.modes.data(), c.mode_count, c.limits, tgt, r1) != core::Status::ok ||
        core::plan_online(r1, p1) != core::Status::ok) {
      continue;  // the loop refuses it too (plan_failed): nothing to switch to
    }
    const bool blends = p1.choice != core::OnlineChoice::finish;
    std::vector<std::pair<core::Blend, std::int32_t>> changes;
    if (blends) changes.emplace_back(p1.blend, k1);
    // A halt on the running blend, asked t2 setpoints after the first ask (its blend running).
    const auto blend_ticks = static_cast<std::int32_t>(std::ceil(p1.blend.duration() / 1e-3));
    const bool ask_second = second && blends && k1 <= 500 && blend_ticks > 2 * lead + 2;
    const std::int32_t t2 = ask_second ? k1 - t1 + 1 + static_cast<std::int32_t>(second_at * (blend_ticks - 2 * lead - 2)) : 0;
    if (ask_second) {
      const std::int32_t k2 = t1 + t2 - k1 + lead;  // on the blend's clock
      core::OnlineRequest r2{};
      core::OnlinePlan p2{};
      ASSERT_EQ(core::online_request(p1.blend, r1, k2 * 1e-3, std::nullopt, r2), core::Status::ok);
      ASSERT_EQ(core::plan_online(r2, p2), core::Status::ok);
      if (p2.choice != core::OnlineChoice::finish) changes.emplace_back(p2.blend, k2);
    }
    Rig<Loop> r;
    ASSERT_EQ(r.loop.configure_online(0, c), runtime::LoopStatus::ok);
    ASSERT_EQ(r.loop.submit(0, req), runtime::LoopStatus::ok);
    for (std::int32_t i = 0; i < t1; ++i) r.tick();
    ASSERT_TRUE(retarget ? r.loop.retarget(0, target) : r.loop.halt(0));
    ASSERT_EQ(r.loop.service(), runtime::LoopStatus::ok) << "t1 " << t1;
    for (std::int32_t i = 0; i < t2; ++i) r.tick();
    if (ask_second) {
      ASSERT_TRUE(r.loop.halt(0));
      ASSERT_EQ(r.loop.service(), runtime::LoopStatus::ok);
    }
    for (int i = 0; i < 3000 && !r.loop.idle(); ++i) r.tick();
    ASSERT_TRUE(r.loop.idle());
    std::size_t switches = 0;
    const std::vector<std::int32_t> e = evaluated_with_blends<Evaluation>(m, changes, &switches);
    EXPECT_EQ(r.loop.online_switches(0), switches) << "t1 " << t1 << " t2 " << t2;
    ASSERT_EQ(r.moving.size(), e.size()) << "t1 " << t1 << " t2 " << t2;
    for (std::size_t i = 0; i < e.size(); ++i) ASSERT_EQ(r.moving[i], e[i]) << "setpoint " << i << " t1 " << t1;
    ++compared;
    switched += switches > 0 ? 1 : 0;
    chained += switches > 1 ? 1 : 0;
  }
  // The grid exercises what it claims: most cases run, most switch, some twice.
  EXPECT_GE(compared, 16);
  EXPECT_GE(switched, 8);
  EXPECT_GE(chained, 2);
}

// The one step both the loop's tick and stream_setpoints drive (setpoint_sequence.hpp). A change
// is ahead before its index and passed after it (neither switches), due exactly at it: the next
// setpoint is the blend's 0, from the move's origin, and the clock restarts on the blend. A null
// blend (a halt that finishes what runs) is due and changes nothing, not even the clock.
TEST(SetpointStepper, SwitchesExactlyAtTheIndexOnTheRunningCommandsClock) {
  using E = runtime::FloatEvaluation<double>;
  const core::Move<double> m = planned(scurve(0.1, 0.5));
  const runtime::OnlineConfig c = online_config(m);
  constexpr std::int32_t k = 100, origin = -7000;
  core::Blend b{};
  const std::vector<std::int32_t> e = expected_with_blend(m, c, k, 0.05, b);
  auto move = std::make_unique<E::Stored>();
  auto blend = std::make_unique<E::BlendStored>();
  ASSERT_EQ(E::prepare(m, {kCpu, kPeriod}, *move), core::Status::ok);
  ASSERT_EQ(E::prepare(b, {kCpu, kPeriod}, *blend), core::Status::ok);
  runtime::SetpointStepper<E> s{};
  s.start(*move, origin);
  bool last = false;
  for (std::int32_t i = 0; i < k; ++i) {
    ASSERT_EQ(s.index(), i);
    ASSERT_EQ(s.offer(k, blend.get()), runtime::SwitchPoint::ahead) << i;
    ASSERT_EQ(s.next(last), origin + e[static_cast<std::size_t>(i)]) << i;
    ASSERT_FALSE(last);
  }
  EXPECT_EQ(s.offer(k - 1, blend.get()), runtime::SwitchPoint::passed);
  EXPECT_FALSE(s.on_blend());
  EXPECT_EQ(s.offer(k, nullptr), runtime::SwitchPoint::due);
  EXPECT_FALSE(s.on_blend());
  EXPECT_EQ(s.index(), k);
  EXPECT_EQ(s.offer(k, blend.get()), runtime::SwitchPoint::due);
  EXPECT_TRUE(s.on_blend());
  EXPECT_EQ(s.index(), 0);
  std::size_t i = static_cast<std::size_t>(k);
  for (last = false; !last; ++i) {
    ASSERT_LT(i, e.size());
    ASSERT_EQ(s.next(last), origin + e[i]) << i;
  }
  EXPECT_EQ(i, e.size());  // the blend's last setpoint is the sequence's
  EXPECT_EQ(s.index(), static_cast<std::int32_t>(e.size()) - k);
  s.end();
  EXPECT_FALSE(s.on_blend());
}

// stream_setpoints takes a finishing halt (null blend) as the loop does: met, nothing changes, and
// a later change is on the same command's clock (the move's, not a blend's).
TEST(SetpointStepper, AFinishingHaltLeavesTheClockToTheNextChange) {
  using E = runtime::FloatEvaluation<double>;
  const core::Move<double> m = planned(scurve(0.1, 0.5));
  constexpr std::int32_t k = 300;
  core::Blend b{};
  const std::vector<std::int32_t> e = expected_with_blend(m, online_config(m), k, std::nullopt, b);
  auto move = std::make_unique<E::Stored>();
  auto blend = std::make_unique<E::BlendStored>();
  ASSERT_EQ(E::prepare(m, {kCpu, kPeriod}, *move), core::Status::ok);
  ASSERT_EQ(E::prepare(b, {kCpu, kPeriod}, *blend), core::Status::ok);
  const runtime::SetpointSwitch<E> changes[] = {{nullptr, 120}, {blend.get(), k}};
  std::vector<std::int32_t> got;
  const runtime::SetpointSequence seq =
      runtime::stream_setpoints<E>(*move, 0, changes, 2, 100000, [&](std::int32_t sp) { got.push_back(sp); });
  EXPECT_TRUE(seq.ended);
  EXPECT_EQ(seq.switches, 2u);
  EXPECT_EQ(seq.setpoints, got.size());
  EXPECT_EQ(got, e);
}

// Without online changes the stepper is the evaluation's stream and nothing more: a Cortex-M0's
// loop (no online changes) pays nothing for the rule, in RAM or per tick.
static_assert(sizeof(runtime::SetpointStepper<runtime::FixedEvaluation, false>) ==
              sizeof(runtime::FixedEvaluation::Stream));
static_assert(sizeof(runtime::SetpointStepper<runtime::FloatEvaluation<float>, false>) ==
              sizeof(runtime::FloatEvaluation<float>::Stream));

TEST(ServoLoopOnline, TheLoopStreamsTheExportedSetpointSequenceInDouble) {
  loop_streams_the_exported_sequence<DoubleLoop>(0x5e771e01);
}
TEST(ServoLoopOnline, TheLoopStreamsTheExportedSetpointSequenceInFloat) {
  loop_streams_the_exported_sequence<FloatLoop>(0x5e771e02);
}
TEST(ServoLoopOnline, TheLoopStreamsTheExportedSetpointSequenceInFixedPoint) {
  loop_streams_the_exported_sequence<FixedLoop>(0x5e771e03);
}

// Every blend is planned within the online limits; limits faster than the axis's vmax (what its
// step guard admits) are refused, so that no blend the loop plans can trip its own guard.
TEST(ServoLoopOnline, OnlineLimitsOverTheAxisVelocityAreRefused) {
  Rig r;  // the axis's vmax: 2 m/s
  runtime::OnlineConfig c = online_config(planned(scurve(0.1, 0.5)));
  c.limits.vmax = 2.5;
  EXPECT_EQ(r.loop.configure_online(0, c), runtime::LoopStatus::exceeds_axis_velocity);
  EXPECT_FALSE(r.loop.halt(0));  // not configured
  c.limits.vmax = 2.0;
  EXPECT_EQ(r.loop.configure_online(0, c), runtime::LoopStatus::ok);
}

TEST(ServoLoopOnline, TheTickNeverPlansAHaltWithoutServiceTheMoveRunsOnUnchanged) {
  Rig<> r;
  const core::MoveRequest req = scurve(0.1, 0.5);
  const core::Move<double> m = planned(req);
  ASSERT_EQ(r.loop.configure_online(0, online_config(m)), runtime::LoopStatus::ok);
  ASSERT_EQ(r.loop.submit(0, req), runtime::LoopStatus::ok);
  for (int i = 0; i < 100; ++i) r.tick();
  ASSERT_TRUE(r.loop.halt(0));
  for (int i = 0; i < 1000 && !r.loop.idle(); ++i) r.tick();
  ASSERT_EQ(r.moving.size(), 501u);
  for (std::size_t i = 0; i < r.moving.size(); ++i) {
    ASSERT_EQ(r.moving[i], counts(m.at(static_cast<double>(i) * 1e-3).p)) << i;
  }
  EXPECT_EQ(r.loop.online_switches(0), 0u);
  // Serviced after the move is over, the halt has nothing to stop.
  EXPECT_EQ(r.loop.service(), runtime::LoopStatus::ok);
  EXPECT_EQ(r.loop.online_missed(0), 1u);
}

TEST(ServoLoopOnline, RefusedWithoutConfigurationOrWhereTheLoopLeavesThemOut) {
  Rig<> r;
  EXPECT_FALSE(r.loop.halt(0));  // not configured
  runtime::OnlineConfig bad{};
  bad.limits = {1.0, 0.0, 1.0};
  EXPECT_EQ(r.loop.configure_online(0, bad), runtime::LoopStatus::bad_axis_config);
  runtime::OnlineConfig no_lead = online_config(planned(scurve(0.1, 0.5)));
  no_lead.lead_ticks = 0;
  EXPECT_EQ(r.loop.configure_online(0, no_lead), runtime::LoopStatus::bad_axis_config);
  EXPECT_FALSE(r.loop.retarget(0, 0.1));
  EXPECT_EQ(r.loop.configure_online(3, online_config(planned(scurve(0.1, 0.5)))), runtime::LoopStatus::no_such_axis);
  hal::LoopbackBus<16> other{r.hub};
  runtime::ServoLoop<float, 1, 2, runtime::FloatEvaluation<float>> small{other, kPeriod};
  EXPECT_EQ(small.configure_online(0, online_config(planned(scurve(0.1, 0.5)))), runtime::LoopStatus::evaluation_refused);
  EXPECT_FALSE(small.halt(0));
  // On by default for the double evaluation only; the others ask for it (FloatLoop, FixedLoop).
  static_assert(runtime::ServoLoop<double, 1, 4>::kOnlineChanges);
  static_assert(!runtime::ServoLoop<double, 1, 4, runtime::FixedEvaluation>::kOnlineChanges);
  static_assert(!runtime::ServoLoop<float, 1, 4, runtime::FloatEvaluation<float>>::kOnlineChanges);
  static_assert(FloatLoop::kOnlineChanges && FixedLoop::kOnlineChanges);
}

// Three path axes on one bus (nodes 1..3), each streaming its own command of one path
// (core::axis_command) with the path's modes and limits times |D_i| (core::axis_online): soak
// draw 263 (tests/support/path_halt_draw.hpp).
struct PathRig {
  static constexpr std::size_t kAxes = 3;
  using Loop = runtime::ServoLoop<double, kAxes, 4>;
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  std::array<std::unique_ptr<hal::testing::IdealDrive<>>, kAxes> drives;
  Loop loop{master, kPeriod};
  std::uint64_t now = 0;
  core::MultiAxisRequest req{};
  core::MultiAxisPlan plan{};
  std::array<core::Move<double>, kAxes> move{};
  std::array<runtime::OnlineConfig, kAxes> config{};
  std::array<std::vector<std::int32_t>, kAxes> moving;

  explicit PathRig(bool path) : req{settle::testing::draw_263()} {
    // Halted at 3 ms, each axis planning its own halt comes to rest up to 9.9 ms after another.
    std::size_t culprit = 0;
    EXPECT_EQ(core::plan_axes(req, plan, culprit), core::Status::ok);
    runtime::AxisConfig a{};
    a.drive.heartbeat_timeout_ms = 500;
    a.scale = {kCpu, kPeriod};
    a.vmax = 2.0;
    settle::testing::add_ideal_axes(loop, hub, drives, a);
    for (std::size_t i = 0; i < kAxes; ++i) {
      core::AxisOnline o{};
      EXPECT_EQ(core::axis_command(req, plan, i, move[i]), core::Status::ok);
      EXPECT_EQ(core::axis_online(req, plan, i, o), core::Status::ok);
      config[i].mode_count = o.mode_count;
      config[i].modes = o.modes;
      config[i].limits = o.limits;
      config[i].path = path;
      EXPECT_EQ(loop.configure_online(i, config[i]), runtime::LoopStatus::ok);
      drives[i]->start(now);
    }
    loop.start(now);
    for (int i = 0; i < 2000 && !loop.all_ready(); ++i) tick();
    EXPECT_TRUE(loop.all_ready());
    for (std::size_t i = 0; i < kAxes; ++i) EXPECT_EQ(loop.submit(i, move[i]), runtime::LoopStatus::ok);
  }
  void tick() {
    now += kPeriod;
    hub.set_time_us(now);
    loop.tick(now);
    for (std::size_t i = 0; i < kAxes; ++i) {
      if (loop.record(i).sent && loop.record(i).moving) moving[i].push_back(loop.record(i).target);
    }
    for (auto& d : drives) d->process(now);
    for (runtime::LoopEvent e{}; loop.events().pop(e);) {
    }
  }
  // Every axis's halt (target none) or retarget asked for in one period, serviced once; to idle.
  void change(const std::array<std::optional<double>, kAxes>& target) {
    for (std::size_t i = 0; i < kAxes; ++i) ASSERT_TRUE(target[i] ? loop.retarget(i, *target[i]) : loop.halt(i));
    ASSERT_EQ(loop.service(), runtime::LoopStatus::ok);
    for (int i = 0; i < 3000 && !loop.idle(); ++i) tick();
    ASSERT_TRUE(loop.idle());
    for (std::size_t i = 0; i < kAxes; ++i) EXPECT_EQ(loop.online_switches(i), 1u) << i;
  }
};

// Path axes (OnlineConfig::path): service() plans their halt once (core::plan_path_online), every
// axis switches at the same setpoint and streams the same blend scaled: each axis's setpoints are
// its move's to the switch and then exactly core's scaled blend, and every axis ends on the same
// tick. The same axes without `path` halt one by one, 9.9 ms apart.
TEST(ServoLoopOnline, PathAxesHaltOncePlannedAndEndOnTheSameTick) {
  for (const bool path : {true, false}) {
    SCOPED_TRACE(path ? "path" : "each axis alone");
    PathRig r{path};
    r.tick();
    const auto k = static_cast<std::int32_t>(r.moving[0].size()) + runtime::kOnlineLeadTicks;
    ASSERT_EQ(k, 3);
    r.change({});
    std::array<core::OnlineRequest, 3> q{};
    std::array<const core::OnlineRequest*, 3> qp{};
    std::array<double, 3> d{};
    for (std::size_t i = 0; i < 3; ++i) {
      const runtime::OnlineConfig& c = r.config[i];
      ASSERT_EQ(core::online_request(r.move[i], k * 1e-3, c.modes.data(), c.mode_count, c.limits, std::nullopt, q[i]),
                core::Status::ok);
      qp[i] = &q[i];
      d[i] = r.move[i].distance();
    }
    std::array<core::OnlinePlan, 3> once{}, alone{};
    std::size_t ref = 3;
    ASSERT_EQ(core::plan_path_online(qp.data(), d.data(), 3, once.data(), ref), core::Status::ok);
    for (std::size_t i = 0; i < 3; ++i) {
      ASSERT_EQ(core::plan_online(q[i], alone[i]), core::Status::ok);
      const core::Blend& b = path ? once[i].blend : alone[i].blend;
      ASSERT_EQ(once[i].choice, core::OnlineChoice::blend);
      std::vector<std::int32_t> e;
      for (std::int32_t n = 0; n < k; ++n) e.push_back(counts(r.move[i].at(n * 1e-3).p));
      for (std::int32_t n = 0;; ++n) {
        e.push_back(counts(b.at(n * 1e-3).p));
        if (!(n * 1e-3 < b.duration())) break;
      }
      ASSERT_EQ(r.moving[i].size(), e.size()) << "axis " << i;
      for (std::size_t n = 0; n < e.size(); ++n) ASSERT_EQ(r.moving[i][n], e[n]) << "axis " << i << " setpoint " << n;
    }
    const bool together = r.moving[1].size() == r.moving[0].size() && r.moving[2].size() == r.moving[0].size();
    EXPECT_EQ(together, path);
  }
}

// A retarget of path axes to the line (lambda D_i) is planned once too; one off the line is each
// axis's own (and they end apart).
TEST(ServoLoopOnline, PathAxesRetargetOnTheLineOnceOffItEachAlone) {
  for (const double off : {1.0, 1.2}) {
    SCOPED_TRACE(off);
    PathRig r{true};
    r.tick();
    std::array<std::optional<double>, 3> target{};
    for (std::size_t i = 0; i < 3; ++i) target[i] = 0.5 * r.move[i].distance();
    *target[2] *= off;
    r.change(target);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(r.drives[i]->position(), counts(*target[i])) << i;
    const bool together = r.moving[1].size() == r.moving[0].size() && r.moving[2].size() == r.moving[0].size();
    EXPECT_EQ(together, off == 1.0);
  }
}

TEST(OnlineMailbox, OneProducerThreadOneConsumerEveryCommandOnceInOrder) {
  runtime::OnlineMailbox<4> box;
  constexpr int n = 5000;
  std::thread producer([&] {
    for (int i = 0; i < n; ++i) {
      while (!box.post({runtime::OnlineKind::retarget, static_cast<double>(i)})) std::this_thread::yield();
    }
  });
  int next = 0;
  while (next < n) {
    runtime::OnlineCommand c{};
    if (!box.take(c)) {
      std::this_thread::yield();
      continue;
    }
    ASSERT_EQ(c.target, static_cast<double>(next));
    ++next;
  }
  producer.join();
  runtime::OnlineCommand c{};
  EXPECT_FALSE(box.take(c));
}

TEST(OnlineMailbox, AFullMailboxRefusesAndKeepsWhatItHolds) {
  runtime::OnlineMailbox<2> box;
  EXPECT_TRUE(box.post({runtime::OnlineKind::halt, 1.0}));
  EXPECT_TRUE(box.post({runtime::OnlineKind::halt, 2.0}));
  EXPECT_FALSE(box.post({runtime::OnlineKind::halt, 3.0}));
  runtime::OnlineCommand c{};
  ASSERT_TRUE(box.take(c));
  EXPECT_EQ(c.target, 1.0);
  ASSERT_TRUE(box.take(c));
  EXPECT_EQ(c.target, 2.0);
}

}  // namespace
