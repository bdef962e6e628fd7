// SPDX-License-Identifier: Apache-2.0
// The servo loop never touches the heap once started: global operator new and malloc are
// replaced in this test binary and counted while the loop and a drive run 1 000 000 ticks on the
// loopback bus, streaming moves back and forth, and while every fault reaction runs.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>

#include "settle/core/multi_axis.hpp"
#include "settle/runtime/servo_loop.hpp"
#include "settle/hal/testing/fault_injecting_bus.hpp"
#include "settle/hal/testing/ideal_drive.hpp"
#include "ideal_axes.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

extern "C" void* __libc_malloc(std::size_t);  // glibc's own allocator, beneath our hook
extern "C" void __libc_free(void*);
extern "C" void* malloc(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  void* p = __libc_malloc(n == 0 ? 1 : n);
  if (p == nullptr) throw std::bad_alloc{};
  return p;
}
// glibc's own free, the pair of __libc_malloc (std::free here is what GCC flags as a mismatch).
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }

using namespace settle;

// A million ticks of one loop type streaming moves back and forth; returns the moves completed.
template <typename Loop>
std::uint64_t million_ticks_without_heap() {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  hal::testing::IdealDrive<> drive{hub, hal::canopen::DriveNodeConfig{}};
  Loop loop{master, 1000};
  runtime::AxisConfig a{};
  a.drive.heartbeat_timeout_ms = 500;
  EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::ok);
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.time = 0.4;
  r.set_mode(22.0);
  core::Move<double> out{}, back{};
  r.distance = 0.1;
  EXPECT_EQ(core::plan(r, out), core::Status::ok);
  r.distance = -0.1;
  EXPECT_EQ(core::plan(r, back), core::Status::ok);

  std::uint64_t now = 0;
  drive.start(now);
  loop.start(now);
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < 1'000'000; ++i) {
    now += 1000;
    hub.set_time_us(now);
    // submit converts the planned move (to float, or to fixed point) inside the loop object
    if (loop.idle() && loop.ready(0)) (void)loop.submit(0, (i / 1000) % 2 == 0 ? out : back);
    loop.tick(now);
    drive.process(now);
  }
  g_counting = false;
  EXPECT_EQ(loop.axis_stats(0).step_guard_trips, 0u);
  return loop.axis_stats(0).moves_completed;
}

TEST(NoAllocation, HookCountsAllocations) {
  // The hook itself must work, or the tests below prove nothing.
  g_allocations = 0;
  g_counting = true;
  void* probe = std::malloc(16);
  int* one = new int{1};
  g_counting = false;
  std::free(probe);
  delete one;
  EXPECT_EQ(g_allocations.load(), 2);
}

using FloatLoop = runtime::ServoLoop<double, 1, 4>;
using FixedLoop = runtime::ServoLoop<double, 1, 2, runtime::FixedEvaluation>;

TEST(NoAllocation, OneMillionTicksOfStreamingMakeNoHeapCalls) {
  EXPECT_GT(million_ticks_without_heap<FloatLoop>(), 1000u);
  EXPECT_EQ(g_allocations.load(), 0);
}

TEST(NoAllocation, TheFixedPointLoopToo) {
  EXPECT_GT(million_ticks_without_heap<FixedLoop>(), 1000u);
  EXPECT_EQ(g_allocations.load(), 0);
}

// The fault paths too: sends refused at random, bus-off and its recovery, a foreign SYNC, a drive
// that stops answering, restarts, while the loop keeps streaming moves. Each fault's reaction (the
// event log, halts, voided moves, start-up again) runs inside tick() without the heap.
TEST(NoAllocation, TheFaultPathsMakeNoHeapCalls) {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> port{hub};
  hal::testing::FaultInjectingBus bus{port};
  hal::LoopbackBus<16> other{hub};
  hal::testing::IdealDrive<> drive{hub, hal::canopen::DriveNodeConfig{}};
  FloatLoop loop{bus, 1000};
  runtime::AxisConfig a{};
  a.drive.heartbeat_timeout_ms = 500;
  ASSERT_EQ(loop.add_axis(a), runtime::LoopStatus::ok);
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.time = 0.2;
  r.set_mode(22.0);
  r.distance = 0.01;
  core::Move<double> move{};
  ASSERT_EQ(core::plan(r, move), core::Status::ok);
  hal::testing::FaultRates rates{};
  rates.tx_busy_ppm = 20'000;
  rates.tx_error_ppm = 5'000;
  bus.set_random(7, rates);
  bus.set_restart_answer(hal::BusStatus::ok, false);
  hal::CanFrame sync{};
  sync.id = 0x080;
  std::uint64_t now = 0;
  drive.start(now);
  loop.start(now);
  std::uint64_t events = 0;
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < 200'000; ++i) {
    now += 1000;
    hub.set_time_us(now);
    bus.set_time_us(now);
    const int phase = i % 20'000;
    if (phase == 5'000) bus.inject_bus_state(hal::BusState::error_passive);
    if (phase == 6'000) bus.inject_bus_state(hal::BusState::bus_off);
    if (phase == 6'050) bus.inject_bus_state(hal::BusState::error_active);
    if (phase == 10'000) (void)other.send(sync);
    if (phase == 10'100 || phase == 15'100) loop.restart(0, now);
    if (loop.idle() && loop.ready(0)) (void)loop.submit(0, move);
    loop.tick(now);
    if (phase < 15'000 || phase > 15'050) drive.process(now);  // the drive hangs for 50 periods
    for (runtime::LoopEvent e{}; loop.events().pop(e);) ++events;
  }
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
  // and the faults did happen
  EXPECT_EQ(loop.stats().bus_offs, 10u);
  EXPECT_EQ(loop.stats().foreign_syncs, 10u);
  EXPECT_GE(loop.axis_stats(0).feedback_timeouts, 10u);
  EXPECT_GT(loop.stats().units_held, 1000u);
  EXPECT_GT(loop.axis_stats(0).moves_completed, 100u);
  EXPECT_GT(events, 100u);
}

// Ticks `ticks` periods counting heap calls: whenever every axis is idle and ready, submits each
// its move; 150 ticks later halts every axis and services. No heap call; on every axis more than
// 100 blends switched in, none missed, no step guard trip.
template <typename Loop, std::size_t N>
struct HaltRig {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  std::array<std::unique_ptr<hal::testing::IdealDrive<>>, N> drives;
  std::unique_ptr<Loop> owned = std::make_unique<Loop>(master, 1000);  // before counting starts
  Loop& loop = *owned;

  explicit HaltRig(double vmax) {
    runtime::AxisConfig a{};
    a.drive.heartbeat_timeout_ms = 500;
    a.vmax = vmax;
    settle::testing::add_ideal_axes(loop, hub, drives, a);
  }
  void halt_every_move(const std::array<core::Move<double>, N>& moves, int ticks);
};

template <typename Loop, std::size_t N>
void HaltRig<Loop, N>::halt_every_move(const std::array<core::Move<double>, N>& moves, int ticks) {
  std::uint64_t now = 0;
  for (auto& d : drives) d->start(now);
  loop.start(now);
  int since_start = -1;
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < ticks; ++i) {
    now += 1000;
    hub.set_time_us(now);
    if (loop.idle() && loop.all_ready()) {
      for (std::size_t k = 0; k < N; ++k) (void)loop.submit(k, moves[k]);
      since_start = 0;
    }
    if (since_start >= 0 && ++since_start == 150) {
      for (std::size_t k = 0; k < N; ++k) (void)loop.halt(k);
      (void)loop.service();
    }
    loop.tick(now);
    for (auto& d : drives) d->process(now);
    for (runtime::LoopEvent e{}; loop.events().pop(e);) {
    }
  }
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
  for (std::size_t k = 0; k < N; ++k) {
    EXPECT_GT(loop.online_switches(k), 100u) << k;
    EXPECT_EQ(loop.online_missed(k), 0u) << k;
    EXPECT_EQ(loop.axis_stats(k).step_guard_trips, 0u) << k;
  }
}

// Online halts (issue 17): halt() posts, service() plans the blend and converts it to the loop's
// scalar, and the tick switches to it, every move, 200 000 ticks: neither the planning, the
// conversion nor the switch touches the heap. In double, float and fixed point.
template <typename Loop>
void halts_without_heap() {
  HaltRig<Loop, 1> rig{1.0};
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.time = 0.4;
  r.set_mode(22.0);
  r.distance = 0.1;
  std::array<core::Move<double>, 1> move{};
  ASSERT_EQ(core::plan(r, move[0]), core::Status::ok);
  runtime::OnlineConfig oc{};
  oc.modes[0] = {22.0, 0.0};
  oc.mode_count = 1;
  oc.limits = {1.2 * move[0].peaks().v, 1.2 * move[0].peaks().a, 1.2 * move[0].peaks().j};
  ASSERT_EQ(rig.loop.configure_online(0, oc), runtime::LoopStatus::ok);
  rig.halt_every_move(move, 200'000);
}

TEST(NoAllocation, HaltsPlannedAndSwitchedInMakeNoHeapCalls) { halts_without_heap<FloatLoop>(); }
TEST(NoAllocation, HaltsInTheSinglePrecisionLoopMakeNoHeapCalls) {
  halts_without_heap<runtime::ServoLoop<float, 1, 2, runtime::FloatEvaluation<float>, hal::CanBus, true>>();
}
TEST(NoAllocation, HaltsInTheFixedPointLoopMakeNoHeapCalls) {
  halts_without_heap<runtime::ServoLoop<double, 1, 2, runtime::FixedEvaluation, hal::CanBus, true>>();
}

// A path's halt (OnlineConfig::path): service() plans it once for three axes and hands each its
// scaled blend (core::plan_path_online, the plans on its stack), every move, 100 000 ticks: no heap.
TEST(NoAllocation, PathHaltsPlannedOnceForEveryAxisMakeNoHeapCalls) {
  HaltRig<runtime::ServoLoop<double, 3, 2>, 3> rig{2.0};
  core::MultiAxisRequest req{};
  req.count = 3;
  req.base.profile = core::ProfileKind::scurve;
  req.base.time = 0.4;
  const double d[3] = {0.1, 0.05, -0.2};
  for (std::size_t i = 0; i < 3; ++i) req.axes[i] = {d[i], {}, 22.0, 0.0};
  core::MultiAxisPlan plan{};
  std::size_t culprit = 0;
  ASSERT_EQ(core::plan_axes(req, plan, culprit), core::Status::ok);
  std::array<core::Move<double>, 3> move{};
  for (std::size_t i = 0; i < 3; ++i) {
    core::AxisOnline o{};
    ASSERT_EQ(core::axis_command(req, plan, i, move[i]), core::Status::ok);
    ASSERT_EQ(core::axis_online(req, plan, i, o), core::Status::ok);
    runtime::OnlineConfig oc{};
    oc.modes = o.modes;
    oc.mode_count = o.mode_count;
    oc.limits = o.limits;
    oc.path = true;
    ASSERT_EQ(rig.loop.configure_online(i, oc), runtime::LoopStatus::ok);
  }
  rig.halt_every_move(move, 100'000);
}
