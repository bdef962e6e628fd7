// SPDX-License-Identifier: Apache-2.0
// Frames per second through vcan0 between two sockets of one process (send, then receive):
// the kernel's cost per frame, without a second process to schedule. Run it through the
// harness when the host kernel has no vcan:  tools/with-vcan <build>/bench/hal/hal_vcan_bench
#include <benchmark/benchmark.h>

#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/socketcan_bus.hpp"

namespace {

using namespace settle::hal;

void BM_VcanSendReceive(benchmark::State& state) {
  SocketCanBus tx;
  SocketCanBus rx;
  if (tx.open("vcan0") != OpenStatus::ok || rx.open("vcan0") != OpenStatus::ok) {
    state.SkipWithError("vcan0 is not present: run through tools/with-vcan");
    return;
  }
  const auto batch = state.range(0);
  CanFrame frame = canopen::encode_rpdo1(1, {0x000F, 0});
  CanFrame got{};
  std::int64_t lost = 0;
  for (auto _ : state) {
    for (std::int64_t i = 0; i < batch; ++i) {
      (void)tx.send(frame);
    }
    for (std::int64_t i = 0; i < batch; ++i) {
      if (rx.receive(got, 100'000) != ReceiveStatus::received) {
        ++lost;
      }
    }
  }
  state.SetItemsProcessed(state.iterations() * batch);
  state.counters["frames_per_second"] =
      benchmark::Counter(static_cast<double>(state.iterations() * batch), benchmark::Counter::kIsRate);
  state.counters["lost"] = static_cast<double>(lost);
}
BENCHMARK(BM_VcanSendReceive)->Arg(1)->Arg(32)->UseRealTime();

}  // namespace
