// SPDX-License-Identifier: Apache-2.0
// libFuzzer harness over every CANopen decoder, the SDO server, the drive node and the master
// side, fed one byte stream as a sequence of frames with time steps in between:
//   byte 0: node id (bit 7: the drive's PDO mapping is writable); then records of
//   [time step /64 µs] [format bits] [id low] [id high] [len] [len data bytes]
// Format bits: can_flag bits as they are; 0x80 reaches extended ids; 0x40 also hands the record's
// first eight data bytes to the segmented-SDO rig as a request (0x600 + node), 0x20 to its
// client as a response (0x580 + node), so that the fuzzer reaches deep transfer states.
// Besides ASan/UBSan findings it checks invariants: a decoded frame re-encodes to itself, the
// SDO server answers at most once with an eight-byte frame on its own id, no object ever holds
// a value outside its range, candump lines round-trip. The segmented-SDO rig (SdoRig) adds: its
// server answers every request with exactly one frame (an abort from the client: none), nothing
// is written outside the byte-string objects, the download buffer or the client's buffer, and
// after the input both ends recover: the server drops any transfer at its timeout, then a full
// download and upload between a fresh client and it carry the bytes exactly.
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

// A server over byte-string objects (one larger than its download buffer) and an integer, and a
// client that keeps starting byte transfers; canaries around every buffer either writes into.
class SdoRig {
 public:
  static constexpr std::uint32_t timeout_us = 5'000;
  static constexpr std::size_t canary = 16;
  static constexpr std::uint8_t canary_byte = 0xA5;

  explicit SdoRig(NodeId node) noexcept : node_{node} {
    name_.assign("Settle fuzz rig name");
    domain_data_ = domain_.view().data();
    name_data_ = name_.view().data();
    guard_.fill(canary_byte);
    staging_.fill(canary_byte);
    client_buffer_.fill(canary_byte);
    REQUIRE(od_.is_well_formed());
  }

  // One record: poll first (its frames are the timeout's), then exactly one answer per request.
  void to_server(const CanFrame& f, std::uint64_t now, FrameBuffer<64>& out) noexcept {
    server_.poll(now, out);
    const std::size_t before = out.size();
    if (!server_.on_frame(f, now, out)) {
      REQUIRE(out.size() == before);
      return;
    }
    const auto q = decode_sdo_request(f, node_);
    REQUIRE(q.has_value());
    REQUIRE(out.size() == before + (q->kind == SdoKind::abort ? 0U : 1U));
    for (std::size_t k = before; k < out.size(); ++k) {
      REQUIRE(out[k].len == 8 && out[k].id == cob_id(cob::sdo_tx, node_));
    }
    check();
  }

  void to_client(const CanFrame& f, std::uint64_t now, FrameBuffer<64>& out) noexcept {
    const std::size_t before = out.size();
    (void)client_.on_frame(f, now, out);
    client_.poll(now, out);
    REQUIRE(out.size() <= before + 1);
    for (std::size_t k = before; k < out.size(); ++k) {
      REQUIRE(out[k].len == 8 && out[k].id == cob_id(cob::sdo_rx, node_));
    }
    if (uploading_ && client_.status() == SdoClientStatus::done) {
      REQUIRE(client_.result().length <= client_window);
    }
    if (!client_.busy()) {
      start_client(f.data[0], now, out);
    }
    check();
  }

  void start_client(std::uint8_t choice, std::uint64_t now, FrameBuffer<64>& out) noexcept {
    const std::uint16_t index = (choice & 1U) != 0 ? 0x2100 : 0x2101;
    uploading_ = (choice & 2U) == 0;
    if (uploading_) {
      (void)client_.upload_bytes(index, 0, client_window_span(), now, out);
    } else {
      (void)client_.download_bytes(index, 0, std::span<const std::uint8_t>{pattern_}.first(choice % 40U), now, out);
    }
  }

  // After the input: whatever state it left, the server times out, then real transfers work.
  void recover(std::uint64_t now) noexcept {
    FrameBuffer<64> out;
    server_.poll(now + timeout_us, out);
    REQUIRE(!server_.busy());
    out.clear();
    SdoClient fresh{node_, timeout_us};
    std::array<std::uint8_t, 40> data{};
    for (std::size_t k = 0; k < data.size(); ++k) {
      data[k] = static_cast<std::uint8_t>(k * 7U + 1U);
    }
    now += 2U * timeout_us;
    REQUIRE(fresh.download_bytes(0x2100, 0, data, now, out));
    exchange(fresh, now, out);
    REQUIRE(fresh.status() == SdoClientStatus::done);
    std::array<std::uint8_t, 64> back{};
    REQUIRE(fresh.upload_bytes(0x2100, 0, back, now, out));
    exchange(fresh, now, out);
    REQUIRE(fresh.status() == SdoClientStatus::done && fresh.result().length == data.size());
    REQUIRE(std::memcmp(back.data(), data.data(), data.size()) == 0);
    check();
  }

 private:
  static constexpr std::size_t client_window = 24;

  std::span<std::uint8_t> client_window_span() noexcept { return {client_buffer_.data() + canary, client_window}; }

  void exchange(SdoClient& client, std::uint64_t now, FrameBuffer<64>& out) noexcept {
    for (int guard = 0; guard < 64 && !out.empty(); ++guard) {
      const std::array<CanFrame, 1> request{out[out.size() - 1]};
      out.clear();
      FrameBuffer<64> answer;
      REQUIRE(server_.on_frame(request[0], now, answer));
      REQUIRE(answer.size() == 1);
      REQUIRE(client.on_frame(answer[0], now, out));
    }
    REQUIRE(out.empty());
  }

  void check() const noexcept {
    for (std::size_t k = 0; k < canary; ++k) {
      REQUIRE(staging_[k] == canary_byte && staging_[staging_.size() - 1 - k] == canary_byte);
      REQUIRE(client_buffer_[k] == canary_byte && client_buffer_[client_buffer_.size() - 1 - k] == canary_byte);
    }
    for (const std::uint8_t b : guard_) {
      REQUIRE(b == canary_byte);
    }
    for (const OdEntry& e : entries_) {
      if (const OdBytes* b = e.var.bytes()) {
        REQUIRE(b->size <= b->capacity && b->capacity == e.max);
      }
    }
    REQUIRE(domain_.view().data() == domain_data_ && name_.view().data() == name_data_);
    REQUIRE(name_.view().size() == 20 && std::memcmp(name_.view().data(), "Settle fuzz rig name", 20) == 0);
  }

  NodeId node_;
  bool uploading_{false};
  const std::uint8_t* domain_data_{nullptr};
  const std::uint8_t* name_data_{nullptr};
  OdByteString<64> domain_;
  std::array<std::uint8_t, canary> guard_{};  // between the two objects: an overrun of domain_ lands here
  OdByteString<24> name_;
  std::uint16_t word_{0};
  std::array<OdEntry, 3> entries_{{
      od_bytes_entry(0x2100, 0, domain_.bytes(), OdType::domain, OdAccess::rw),
      od_bytes_entry(0x2101, 0, name_.bytes(), OdType::visible_string, OdAccess::ro),
      od_entry(0x2102, 0, word_, OdAccess::rw),
  }};
  ObjectDictionary od_{entries_};
  std::array<std::uint8_t, canary + 48 + canary> staging_{};  // 48 < 64: downloads can run out of it
  SdoServer server_{node_, od_, timeout_us, std::span<std::uint8_t>{staging_.data() + canary, 48}};
  SdoClient client_{node_, timeout_us};
  std::array<std::uint8_t, canary + client_window + canary> client_buffer_{};
  std::array<std::uint8_t, 40> pattern_{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20,
                                        21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40};
};

void check_dictionary(DriveNode& drive) {
  for (const OdEntry& e : drive.dictionary().entries()) {
    if (e.access == OdAccess::rw) {
      const std::int64_t v = e.var.value();
      REQUIRE(v >= e.min && v <= e.max);
    }
  }
  // The mapping procedure never leaves a valid PDO without a bound, non-empty mapping.
  const DriveCommObjects& c = drive.objects().comm;
  for (std::size_t p = 0; p < drive_rpdo_capacity; ++p) {
    if (drive.dictionary().has_index(static_cast<std::uint16_t>(0x1400 + p)) && (c.rpdo_comm[p].cob_id >> 31U) == 0) {
      REQUIRE(c.rpdo_map[p].count > 0 && drive.rpdo_active(p));
    }
  }
  for (std::size_t p = 0; p < drive_tpdo_capacity; ++p) {
    if (drive.dictionary().has_index(static_cast<std::uint16_t>(0x1800 + p)) && (c.tpdo_comm[p].cob_id >> 31U) == 0) {
      REQUIRE(c.tpdo_map[p].count > 0 && drive.tpdo_active(p));
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
  if ((data[0] & 0x80U) != 0) {  // a drive with dynamic mapping and every PDO it can have
    dc.pdo_mapping_writable = true;
    dc.rpdo_count = static_cast<std::uint8_t>(drive_rpdo_capacity);
    dc.tpdo_count = static_cast<std::uint8_t>(drive_tpdo_capacity);
  }
  DriveNode drive{dc};
  RemoteDriveConfig rc{};
  rc.node = node;
  rc.heartbeat_timeout_ms = 50;
  rc.master_node = 127;
  rc.master_heartbeat_timeout_ms = 20;
  RemoteDrive remote{rc};
  SdoServer server{node, drive.dictionary()};
  SdoRig rig{node};
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
  rig.start_client(0, now, out);

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
    server.poll(now, out);  // a transfer's timeout has its own frame
    const std::size_t before = out.size();
    if (server.on_frame(f, now, out)) {
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
    (void)client.on_frame(f, now, out);
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
    if ((format & 0x60U) != 0) {
      CanFrame g{};
      g.len = 8;
      std::memcpy(g.data.data(), f.data.data(), 8);
      g.timestamp_us = now;
      if ((format & 0x40U) != 0) {
        g.id = cob_id(cob::sdo_rx, node);
        rig.to_server(g, now, out);
      }
      if ((format & 0x20U) != 0) {
        g.id = cob_id(cob::sdo_tx, node);
        rig.to_client(g, now, out);
      }
    }
    check_dictionary(drive);
    REQUIRE(out.overflows() == 0);
  }
  rig.recover(now);
  REQUIRE(drive.dictionary().is_well_formed());
  return 0;
}
