// SPDX-License-Identifier: Apache-2.0
// Per-frame cost of what the servo loop and the drive do every SYNC: encode and decode the
// RPDO/TPDO pair, and carry frames through the loopback bus. The budget is 50 ns per
// frame in Release for "encode + decode of an RPDO/TPDO pair and a send through loopback".
#include <benchmark/benchmark.h>

#include <cstdint>
#include <map>

#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/process_data.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/hal/loopback_bus.hpp"

namespace {

using namespace settle::hal;
using namespace settle::hal::canopen;

constexpr NodeId node = 1;

void per_frame(benchmark::State& state, std::int64_t frames_per_iteration) {
  const auto frames = static_cast<double>(state.iterations() * frames_per_iteration);
  state.SetItemsProcessed(state.iterations() * frames_per_iteration);
  state.counters["per_frame"] = benchmark::Counter(frames, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Encode and decode of an RPDO1/TPDO1 pair: two frames per iteration.
void BM_PdoPairEncodeDecode(benchmark::State& state) {
  std::int32_t target = 0;
  for (auto _ : state) {
    const CanFrame rpdo = encode_rpdo1(node, Rpdo1{0x000F, target});
    benchmark::DoNotOptimize(rpdo);
    const auto r = decode_rpdo1(rpdo, node);
    benchmark::DoNotOptimize(r);
    const CanFrame tpdo = encode_tpdo1(node, Tpdo1{0x1237, r->target_position});
    benchmark::DoNotOptimize(tpdo);
    const auto t = decode_tpdo1(tpdo, node);
    benchmark::DoNotOptimize(t);
    target += 3;
  }
  per_frame(state, 2);
}
BENCHMARK(BM_PdoPairEncodeDecode);

// One frame sent on one loopback port and received on the other.
void BM_LoopbackSendReceive(benchmark::State& state) {
  LoopbackHub hub;
  LoopbackBus<64> a{hub};
  LoopbackBus<64> b{hub};
  const CanFrame frame = encode_rpdo1(node, Rpdo1{0x000F, 42});
  CanFrame got{};
  for (auto _ : state) {
    benchmark::DoNotOptimize(a.send(frame));
    benchmark::DoNotOptimize(b.receive(got));
    benchmark::DoNotOptimize(got);
  }
  per_frame(state, 1);
}
BENCHMARK(BM_LoopbackSendReceive);

// The figure: encode RPDO, send it through loopback, receive and decode it on the
// drive side; encode TPDO, send it back, receive and decode it on the master side.
void BM_PdoPairThroughLoopback(benchmark::State& state) {
  LoopbackHub hub;
  LoopbackBus<64> master{hub};
  LoopbackBus<64> drive{hub};
  CanFrame got{};
  std::int32_t target = 0;
  std::int64_t sum = 0;
  for (auto _ : state) {
    (void)master.send(encode_rpdo1(node, Rpdo1{0x000F, target}));
    (void)drive.receive(got);
    const auto r = decode_rpdo1(got, node);
    (void)drive.send(encode_tpdo1(node, Tpdo1{0x1237, r ? r->target_position : 0}));
    (void)master.receive(got);
    const auto t = decode_tpdo1(got, node);
    sum += t ? t->position_actual : 0;
    target += 3;
  }
  benchmark::DoNotOptimize(sum);
  per_frame(state, 2);
}
BENCHMARK(BM_PdoPairThroughLoopback);

// The drive's side of one SYNC period through its object dictionary and generic mapping:
// latch RPDO1, SYNC (apply it, run the state machine), publish (TPDO1 + TPDO2 into a buffer).
void BM_DriveNodeSyncPeriod(benchmark::State& state) {
  DriveNode drive{DriveNodeConfig{node}};
  FrameBuffer<8> out;
  drive.start(0, out);
  (void)drive.on_frame(encode_nmt(NmtCommand::start, node), 0, out);
  for (const std::uint16_t cw : {std::uint16_t{0x06}, std::uint16_t{0x07}, std::uint16_t{0x0F}}) {
    (void)drive.on_frame(encode_rpdo1(node, Rpdo1{cw, 0}), 0, out);
    (void)drive.on_frame(encode_sync(), 0, out);
  }
  std::uint64_t now = 0;
  std::int32_t target = 0;
  const CanFrame sync = encode_sync();
  for (auto _ : state) {
    out.clear();
    now += 1000;
    target += 3;
    (void)drive.on_frame(encode_rpdo1(node, Rpdo1{0x000F, target}), now, out);
    (void)drive.on_frame(sync, now, out);
    drive.publish(DriveFeedback{drive.setpoint(), 0, drive.setpoint()}, now, out);
    benchmark::DoNotOptimize(out);
  }
  if (!drive.following()) {
    state.SkipWithError("drive did not enable");
  }
  per_frame(state, 4);  // RPDO, SYNC in; TPDO1, TPDO2 out
}
BENCHMARK(BM_DriveNodeSyncPeriod);

// The master's side of one period for one axis: RPDO from RemoteDrive, feedback in. Under the
// default layout (inline codecs) and under another one (the generic ones of process_data.hpp):
// controlword after the target in RPDO1, velocity and position in TPDO1 with the statusword last.
void remote_drive_period(benchmark::State& state, bool other_layout) {
  RemoteDriveConfig config{};
  config.node = node;
  if (other_layout) {
    config.layout.controlword = PdoSlot{1, 4, 2};
    config.layout.target_position = PdoSlot{1, 0, 4};
    config.layout.statusword = PdoSlot{1, 4, 2};
    config.layout.position_actual = PdoSlot{1, 0, 4};
  }
  RemoteDrive remote{config};
  FrameBuffer<16> out;
  // Bring it to "ready" by feeding the answers a drive would give: a write reads back as written.
  std::map<std::uint32_t, std::uint32_t> objects{{obj::device_type << 8U, cia402_device_type},
                                                 {obj::modes_of_operation_display << 8U, 8}};
  // TPDO1 with the statusword "operation enabled" and a position, in the layout's places.
  const auto tpdo1 = [&](std::int32_t position) {
    CanFrame f = encode_tpdo1(node, Tpdo1{0x1237, position});
    if (other_layout) {
      const auto p = static_cast<std::uint32_t>(position);
      f.data = {};
      f.data[0] = static_cast<std::uint8_t>(p);
      f.data[1] = static_cast<std::uint8_t>(p >> 8U);
      f.data[2] = static_cast<std::uint8_t>(p >> 16U);
      f.data[3] = static_cast<std::uint8_t>(p >> 24U);
      f.data[4] = 0x37;
      f.data[5] = 0x12;
    }
    return f;
  };
  remote.start(0, out);
  for (int i = 0; i < 64 && !remote.ready(); ++i) {
    for (std::size_t k = 0; k < out.size(); ++k) {
      const auto q = decode_sdo_request(out[k], node);
      if (!q) {
        continue;
      }
      const std::uint32_t key = (std::uint32_t{q->index} << 8U) | q->sub;
      if (q->kind == SdoKind::download_request) objects[key] = q->value;
      const CanFrame answer = q->kind == SdoKind::upload_request
                                  ? encode_sdo_upload_response(node, q->index, q->sub, objects[key], 4)
                                  : encode_sdo_download_response(node, q->index, q->sub);
      out.clear();
      remote.on_frame(answer, 0, out);
      break;
    }
    remote.on_frame(tpdo1(0), 0, out);
  }
  if (!remote.ready()) {
    state.SkipWithError("remote drive did not become ready");
    return;
  }
  std::int32_t target = 0;
  CanFrame rpdo{};
  for (auto _ : state) {
    target += 3;
    benchmark::DoNotOptimize(remote.rpdo(target, rpdo));
    benchmark::DoNotOptimize(rpdo);
    remote.on_frame(tpdo1(target), 0, out);
    remote.on_frame(encode_tpdo2(node, Tpdo2{target, 0}), 0, out);
  }
  benchmark::DoNotOptimize(remote.feedback());
  per_frame(state, 3);
}
void BM_RemoteDrivePeriod(benchmark::State& state) { remote_drive_period(state, false); }
BENCHMARK(BM_RemoteDrivePeriod);
void BM_RemoteDrivePeriodOtherLayout(benchmark::State& state) { remote_drive_period(state, true); }
BENCHMARK(BM_RemoteDrivePeriodOtherLayout);

}  // namespace
