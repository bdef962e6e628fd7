// libFuzzer harness over every CANopen decoder, the SDO server, the drive node and the master
// side, fed one byte stream as a sequence of frames with time steps in between:
//   byte 0: node id; then records of
//   [time step /64 µs] [format bits] [id low] [id high] [len] [len data bytes]
// Besides ASan/UBSan findings it checks invariants: a decoded frame re-encodes to itself, the
// SDO server answers at most once with an eight-byte frame on its own id, no object ever holds
// a value outside its range, candump lines round-trip.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "settle/hal/candump_log.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/emcy.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/hal/frame_sink.hpp"

namespace {

using namespace settle::hal;
using namespace settle::hal::canopen;

// An invariant violation is a crash libFuzzer records, with the line that failed.
void require_at(bool condition, int line) {
  if (!condition) {
    std::fprintf(stderr, "fuzz_canopen.cpp:%d: invariant violated\n", line);
    std::abort();
  }
}
#define REQUIRE(condition) require_at((condition), __LINE__)

void check_round_trips(const CanFrame& f, NodeId node) {
  if (const auto m = decode_nmt(f)) {
    REQUIRE(encode_nmt(m->command, m->node) == f);
  }
  if (const auto s = decode_sync(f)) {
    REQUIRE(encode_sync(s->counter) == f);
  }
  if (const auto h = decode_heartbeat(f)) {
    REQUIRE(encode_heartbeat(h->node, h->state) == f);
  }
  if (const auto e = decode_emcy(f)) {
    REQUIRE(encode_emcy(e->node, e->message) == f);
  }
  if (const auto r = decode_rpdo1(f, node)) {
    REQUIRE(encode_rpdo1(node, *r) == f);
  }
  if (const auto t = decode_tpdo1(f, node)) {
    REQUIRE(encode_tpdo1(node, *t) == f);
  }
  if (const auto t = decode_tpdo2(f, node)) {
    REQUIRE(encode_tpdo2(node, *t) == f);
  }
  if (const auto q = decode_sdo_request(f, node)) {
    REQUIRE(f.len == 8 && f.id == cob_id(cob::sdo_rx, node));
    if (q->kind == SdoKind::upload_request) {
      REQUIRE(q->index == (f.data[1] | (f.data[2] << 8)) && q->sub == f.data[3]);
    }
  }
  if (const auto r = decode_sdo_response(f, node)) {
    REQUIRE(f.len == 8 && f.id == cob_id(cob::sdo_tx, node));
  }
  std::array<char, candump_line_max> line{};
  const std::size_t n = format_candump_line(f, "vcan0", line);
  REQUIRE((n != 0) == is_valid(f));
  if (n != 0) {
    const auto rec = parse_candump_line({line.data(), n});
    REQUIRE(rec && rec->frame == f && rec->frame.timestamp_us == f.timestamp_us);
  }
}

void check_dictionary(DriveNode& drive) {
  for (const OdEntry& e : drive.dictionary().entries()) {
    if (e.access == OdAccess::rw) {
      const std::int64_t v = e.var.value();
      REQUIRE(v >= e.min && v <= e.max);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The whole input is also a candidate log line.
  if (const auto rec = parse_candump_line({reinterpret_cast<const char*>(data), size})) {
    std::array<char, candump_line_max> line{};
    const std::size_t n = format_candump_line(rec->frame, rec->iface.data(), line);
    REQUIRE(n != 0);
    const auto again = parse_candump_line({line.data(), n});
    REQUIRE(again && again->frame == rec->frame);
  }
  if (size < 1) {
    return 0;
  }
  const NodeId node = static_cast<NodeId>(1 + data[0] % 127);
  DriveNodeConfig dc{};
  dc.node = node;
  dc.following_error_window = 1000;
  dc.following_error_timeout_ms = 2;
  DriveNode drive{dc};
  RemoteDriveConfig rc{};
  rc.node = node;
  rc.heartbeat_timeout_ms = 50;
  rc.master_node = 127;
  rc.master_heartbeat_timeout_ms = 20;
  RemoteDrive remote{rc};
  SdoServer server{node, drive.dictionary()};
  SdoClient client{node, 10'000};
  HeartbeatConsumer heartbeat{node, 30};
  EmcyConsumer emcy{node};
  SyncConsumer sync{1000, 2};
  PowerStateMachine power{};
  EnableSequence enable{};
  FrameBuffer<64> out;
  std::uint64_t now = 0;
  drive.start(now, out);
  remote.start(now, out);
  (void)client.upload(0x1000, 0, now, out);

  std::size_t i = 1;
  while (i + 5 <= size) {
    now += std::uint64_t{data[i]} * 64U;
    const std::uint8_t format = data[i + 1];
    CanFrame f{};
    f.flags = static_cast<std::uint8_t>(format & can_flag::all);
    f.id = static_cast<std::uint32_t>(data[i + 2] | (data[i + 3] << 8));
    if ((format & 0x80U) != 0) {
      f.id |= static_cast<std::uint32_t>(data[i + 3]) << 16U;  // reach extended ids too
    }
    f.len = data[i + 4];
    i += 5;
    const std::size_t carried = f.len < can_fd_max_len ? f.len : can_fd_max_len;
    const std::size_t take = carried < size - i ? carried : size - i;
    std::memcpy(f.data.data(), data + i, take);
    i += take;
    f.timestamp_us = now;

    check_round_trips(f, node);

    out.clear();
    const std::size_t before = out.size();
    if (server.on_frame(f, out)) {
      REQUIRE(out.size() == before + 1 || (out.size() == before && decode_sdo_request(f, node)->kind == SdoKind::abort));
      if (out.size() == before + 1) {
        REQUIRE(out[before].len == 8 && out[before].id == cob_id(cob::sdo_tx, node));
      }
    } else {
      REQUIRE(out.size() == before);
    }
    if (drive.on_frame(f, now, out) == DriveEvent::sync) {
      const std::int32_t sp = drive.setpoint();
      if (drive.stopping()) {
        drive.stop_complete();
      }
      drive.publish(DriveFeedback{sp / 2 + static_cast<std::int32_t>(f.data[0]), 0, sp}, now, out);
    }
    drive.poll(now, out);
    remote.on_frame(f, now, out);
    remote.poll(now, out);
    CanFrame rpdo{};
    (void)remote.rpdo(static_cast<std::int32_t>(now), rpdo);
    remote.recover(now);
    (void)client.on_frame(f, out);
    client.poll(now, out);
    (void)heartbeat.on_frame(f, now);
    (void)heartbeat.poll(now);
    (void)emcy.on_frame(f);
    if (const auto s = decode_sync(f)) {
      (void)sync.on_sync(*s, now);
    }
    (void)sync.check_loss(now);
    const std::uint16_t cw = static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
    (void)power.on_controlword(cw);
    REQUIRE(state_from_statusword(power.statusword_bits()) == power.state());
    (void)enable.next(cw);
    check_dictionary(drive);
    REQUIRE(out.overflows() == 0);
  }
  REQUIRE(drive.dictionary().is_well_formed());
  return 0;
}
