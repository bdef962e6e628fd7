// Cost of one full servo tick per axis (drain feedback, supervise, evaluate the move, encode and
// send the RPDO on the loopback bus, send SYNC), for 1..64 axes. The drives' side is kept out of
// the timing: a feeder port injects each axis's TPDO1/TPDO2 between timed ticks.
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <vector>

#include "ideal_drive.hpp"
#include "settle/firmware/servo_loop.hpp"
#include "settle/hal/canopen/default_mapping.hpp"

using namespace settle;

namespace {

constexpr std::size_t kMaxAxes = 64;

template <typename Scalar>
void BM_FullTick(benchmark::State& state, core::ShaperKind shaper) {
  const auto n = static_cast<std::size_t>(state.range(0));
  hal::LoopbackHub hub;
  auto master = std::make_unique<hal::LoopbackBus<1024>>(hub);
  auto loop = std::make_unique<firmware::ServoLoop<Scalar, kMaxAxes, 2>>(*master, 1000);
  std::vector<std::unique_ptr<test::IdealDrive>> drives;
  for (std::size_t i = 0; i < n; ++i) {
    firmware::AxisConfig a{};
    a.drive.node = hal::canopen::NodeId{static_cast<std::uint8_t>(i + 1)};
    a.vmax = 5.0;
    (void)loop->add_axis(a);
    hal::canopen::DriveNodeConfig dc{};
    dc.node = a.drive.node;
    drives.push_back(std::make_unique<test::IdealDrive>(hub, dc));
  }
  std::uint64_t now = 0;
  for (auto& d : drives) d->start(now);
  loop->start(now);
  for (int t = 0; t < 5000 && !loop->all_ready(); ++t) {
    now += 1000;
    hub.set_time_us(now);
    loop->tick(now);
    for (auto& d : drives) d->process(now);
  }
  if (!loop->all_ready()) {
    state.SkipWithError("drives did not become ready");
    return;
  }
  drives.clear();  // from here the feeder plays the drives
  hal::LoopbackBus<64> feeder{hub};
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.distance = 0.2;
  r.time = 0.5;
  r.omega = 22.0;
  r.shaper = shaper;
  core::Move<double> m{};
  if (core::plan(r, m) != core::Status::ok) std::abort();
  std::int32_t pos = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) {
      if (loop->idle()) (void)loop->submit(i, m);
      const hal::canopen::NodeId id{static_cast<std::uint8_t>(i + 1)};
      (void)feeder.send(hal::canopen::encode_tpdo1(id, {0x0237, pos}));
      (void)feeder.send(hal::canopen::encode_tpdo2(id, {pos, 0}));
    }
    while (feeder.pending() > 0) {
      hal::CanFrame f{};
      (void)feeder.receive(f, 0);  // the feeder discards what the loop sends
    }
    now += 1000;
    const auto t0 = std::chrono::steady_clock::now();
    loop->tick(now);
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    ++pos;
  }
  state.counters["ns_per_axis"] = benchmark::Counter(static_cast<double>(state.iterations()) * static_cast<double>(n),
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_FullTickDouble(benchmark::State& s) { BM_FullTick<double>(s, core::ShaperKind::none); }
void BM_FullTickFloat(benchmark::State& s) { BM_FullTick<float>(s, core::ShaperKind::none); }
void BM_FullTickDoubleZv(benchmark::State& s) { BM_FullTick<double>(s, core::ShaperKind::zv); }

}  // namespace

BENCHMARK(BM_FullTickDouble)->UseManualTime()->Arg(1)->Arg(2)->Arg(4)->Arg(8)->Arg(16)->Arg(32)->Arg(64);
BENCHMARK(BM_FullTickFloat)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
BENCHMARK(BM_FullTickDoubleZv)->UseManualTime()->Arg(1)->Arg(8)->Arg(64);
