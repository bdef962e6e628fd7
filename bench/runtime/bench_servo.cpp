// SPDX-License-Identifier: Apache-2.0
// Cost of one full servo tick per axis (drain feedback, supervise, evaluate the move, encode and
// send the RPDO, send SYNC), for 1..64 axes. The drives' side is kept out of the timing: between
// timed ticks a feeder injects each axis's TPDO1/TPDO2 and discards what the loop sent. Two buses:
// the loopback (what a Linux master's tests run on: frames copied whole into the peer's queue) and
// hal::MailboxBus (a CAN controller's buffers, what drive firmware has: the *Mailbox benchmarks).
// Three evaluations: the float/double stepper (FloatEvaluation) and the integer-only position plan
// (FixedEvaluation, what a Cortex-M0 without FPU runs: the *Fixed benchmarks).
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <type_traits>
#include <vector>

#include "settle/runtime/servo_loop.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/mailbox_bus.hpp"
#include "settle/hal/testing/ideal_drive.hpp"

using namespace settle;

namespace {

constexpr std::size_t kMaxAxes = 64;

using Controller = hal::MailboxBus<kMaxAxes + 1, 4 * kMaxAxes + 16>;

// OnMailbox: the loop holds the controller by its own type (direct driver calls, as firmware
// does); otherwise it holds the loopback bus as a hal::CanBus (virtual calls).
template <typename Scalar, bool OnMailbox, typename Evaluation = runtime::FloatEvaluation<Scalar>>
void BM_FullTick(benchmark::State& state, core::ShaperKind shaper) {
  const auto n = static_cast<std::size_t>(state.range(0));
  hal::LoopbackHub hub;
  auto master = std::make_unique<hal::LoopbackBus<1024>>(hub);
  // On a controller, `master` is its wire: pump() moves frames between the two, untimed.
  auto controller = std::make_unique<Controller>();
  using LoopBus = std::conditional_t<OnMailbox, Controller, hal::CanBus>;
  LoopBus* bus_ptr = nullptr;
  if constexpr (OnMailbox) {
    bus_ptr = controller.get();
  } else {
    bus_ptr = master.get();
  }
  LoopBus& bus = *bus_ptr;
  const auto pump = [&] {
    if (!OnMailbox) return;
    hal::CanFrame f{};
    while (controller->take_sent(f)) (void)master->send(f);
    while (master->receive(f, 0) == hal::ReceiveStatus::received) (void)controller->put_received(f);
  };
  auto loop = std::make_unique<runtime::ServoLoop<Scalar, kMaxAxes, 2, Evaluation, LoopBus>>(bus, 1000);
  std::vector<std::unique_ptr<hal::testing::IdealDrive<>>> drives;
  for (std::size_t i = 0; i < n; ++i) {
    runtime::AxisConfig a{};
    a.drive.node = hal::canopen::NodeId{static_cast<std::uint8_t>(i + 1)};
    a.vmax = 5.0;
    (void)loop->add_axis(a);
    hal::canopen::DriveNodeConfig dc{};
    dc.node = a.drive.node;
    drives.push_back(std::make_unique<hal::testing::IdealDrive<>>(hub, dc));
  }
  std::uint64_t now = 0;
  for (auto& d : drives) d->start(now);
  loop->start(now);
  for (int t = 0; t < 5000 && !loop->all_ready(); ++t) {
    now += 1000;
    hub.set_time_us(now);
    pump();
    loop->tick(now);
    pump();
    for (auto& d : drives) d->process(now);
  }
  if (!loop->all_ready()) {
    state.SkipWithError("drives did not become ready");
    return;
  }
  drives.clear();  // from here the feeder plays the drives
  pump();
  hal::LoopbackBus<256> feeder{hub};
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.distance = 0.2;
  r.time = 0.5;
  r.set_mode(22.0);
  r.shaper = shaper;
  core::Move<double> m{};
  if (core::plan(r, m) != core::Status::ok) std::abort();
  std::int32_t pos = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      if (loop->idle() && loop->submit(i, m) != runtime::LoopStatus::ok) {
        state.SkipWithError("the loop refused the move");
        return;
      }
      const hal::canopen::NodeId id{static_cast<std::uint8_t>(i + 1)};
      (void)feeder.send(hal::canopen::encode_tpdo1(id, {0x0237, pos}));
      (void)feeder.send(hal::canopen::encode_tpdo2(id, {pos, 0}));
    }
    pump();
    hal::CanFrame f{};
    while (feeder.pending() > 0) (void)feeder.receive(f, 0);  // what the loop sent, discarded
    now += 1000;
    const auto t0 = std::chrono::steady_clock::now();
    loop->tick(now);
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    pump();
    ++pos;
  }
  if (bus.counters().rx_overflow_drops != 0 || master->counters().rx_overflow_drops != 0) {
    state.SkipWithError("a receive queue overflowed: the benchmark fed more than it holds");
  }
  state.counters["ns_per_axis"] = benchmark::Counter(static_cast<double>(state.iterations()) * static_cast<double>(n),
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_FullTickDouble(benchmark::State& s) { BM_FullTick<double, false>(s, core::ShaperKind::none); }
void BM_FullTickFloat(benchmark::State& s) { BM_FullTick<float, false>(s, core::ShaperKind::none); }
void BM_FullTickDoubleZv(benchmark::State& s) { BM_FullTick<double, false>(s, core::ShaperKind::zv); }
void BM_FullTickDoubleMailbox(benchmark::State& s) { BM_FullTick<double, true>(s, core::ShaperKind::none); }
void BM_FullTickFloatMailbox(benchmark::State& s) { BM_FullTick<float, true>(s, core::ShaperKind::none); }
using Fixed = runtime::FixedEvaluation;
void BM_FullTickFixed(benchmark::State& s) { BM_FullTick<float, false, Fixed>(s, core::ShaperKind::none); }
void BM_FullTickFixedZv(benchmark::State& s) { BM_FullTick<float, false, Fixed>(s, core::ShaperKind::zv); }
void BM_FullTickFixedMailbox(benchmark::State& s) { BM_FullTick<float, true, Fixed>(s, core::ShaperKind::none); }

}  // namespace

BENCHMARK(BM_FullTickDouble)->UseManualTime()->Arg(1)->Arg(2)->Arg(3)->Arg(4)->Arg(8)->Arg(16)->Arg(32)->Arg(64);
BENCHMARK(BM_FullTickFloat)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
BENCHMARK(BM_FullTickDoubleZv)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
BENCHMARK(BM_FullTickDoubleMailbox)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
BENCHMARK(BM_FullTickFloatMailbox)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
BENCHMARK(BM_FullTickFixed)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
BENCHMARK(BM_FullTickFixedZv)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
BENCHMARK(BM_FullTickFixedMailbox)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
