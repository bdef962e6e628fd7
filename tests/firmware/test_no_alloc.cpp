// The servo loop never touches the heap once started: global operator new and malloc are
// replaced in this test binary and counted while the loop and a drive run 1 000 000 ticks on the
// loopback bus, streaming moves back and forth.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "ideal_drive.hpp"
#include "settle/firmware/servo_loop.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

extern "C" void* __libc_malloc(std::size_t);  // glibc's own allocator, beneath our hook
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
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace settle;

TEST(NoAllocation, OneMillionTicksOfStreamingMakeNoHeapCalls) {
  // The hook itself must work, or this test proves nothing.
  g_counting = true;
  void* probe = std::malloc(16);
  g_counting = false;
  std::free(probe);
  ASSERT_EQ(g_allocations.load(), 1);
  g_allocations = 0;

  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  test::IdealDrive drive{hub, hal::canopen::DriveNodeConfig{}};
  firmware::ServoLoop<double, 1, 4> loop{master, 1000};
  firmware::AxisConfig a{};
  a.drive.heartbeat_timeout_ms = 500;
  ASSERT_EQ(loop.add_axis(a), firmware::LoopStatus::ok);
  drive.applied.reserve(1'100'000);  // the test's own log, allocated before counting starts
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.time = 0.4;
  r.omega = 22.0;
  core::Move<double> out{}, back{};
  r.distance = 0.1;
  ASSERT_EQ(core::plan(r, out), core::Status::ok);
  r.distance = -0.1;
  ASSERT_EQ(core::plan(r, back), core::Status::ok);

  std::uint64_t now = 0;
  drive.start(now);
  loop.start(now);
  g_counting = true;
  for (int i = 0; i < 1'000'000; ++i) {
    now += 1000;
    hub.set_time_us(now);
    if (loop.idle() && loop.ready(0)) (void)loop.submit(0, (i / 1000) % 2 == 0 ? out : back);
    loop.tick(now);
    drive.process(now);
  }
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_GT(loop.axis_stats(0).moves_completed, 1000u);
  EXPECT_EQ(loop.axis_stats(0).step_guard_trips, 0u);
}
