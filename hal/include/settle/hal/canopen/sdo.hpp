// SPDX-License-Identifier: Apache-2.0
// CiA 301 SDO, expedited and segmented transfers: the frame codec, the server that answers
// from an object dictionary, and the client a master uses, with timeouts and the standard
// aborts. Freestanding: no heap; a transfer's bytes live in buffers the caller owns.
//
// Frames (eight bytes, byte 0 the command; multiplexer = index (bytes 1-2, LE) and sub (byte 3)):
//   initiate download  client 001 0 nn e s  mux  data (e=1: 4-nn bytes if s) | size (e=0, s=1)
//                      server 011 00000     mux
//   download segment   client 000 t nnn c   7-nnn data bytes; c = last
//                      server 001 t 0000
//   initiate upload    client 010 00000     mux
//                      server 010 0 nn e s  mux  as the initiate download request
//   upload segment     client 011 t 0000
//                      server 000 t nnn c   7-nnn data bytes; c = last
//   abort              either 100 00000     mux  abort code (u32 LE)
// The toggle bit t is 0 in the first segment and alternates; the other side echoes it. Up to
// four bytes go expedited; more (and zero, which an expedited frame cannot say) are segmented,
// with the size indicated. Block transfer (client command 5 or 6) is not supported: it is
// answered with abort 0x05040001, as is any other command the state does not expect.
//
// Length aborts: 0x06070012 / 0x06070013 when a download is longer / shorter than the object
// or than the size the client indicated (the server), or when an object is longer than the
// buffer an upload reads into (the client: 0x06070012); 0x06070010 when an upload's segments
// do not add up to the size the server indicated (the client).
//
// Both sides time out: the client when the server does not answer within its timeout, the
// server when a segmented transfer's next request does not come within its own; each then
// sends abort 0x05040000 and is ready for the next transfer. A request that arrives while a
// segmented transfer runs and is not its next segment (a new initiate, say) aborts the running
// transfer with 0x05040001 and is not served; the client repeats it.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/canopen/object_dictionary.hpp"
#include "settle/hal/canopen/sdo_abort.hpp"
#include "settle/hal/canopen/watchdog.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen {

// Data bytes in one segment.
inline constexpr std::uint8_t sdo_segment_bytes = 7;
// What a server waits for the next segment request before it drops the transfer (CiA 301
// leaves the value to the device; 1 s is common).
inline constexpr std::uint32_t sdo_server_default_timeout_us = 1'000'000;

enum class SdoKind : std::uint8_t {
  upload_request,             // client: initiate upload of index/sub
  download_request,           // client: initiate download: expedited value, or segmented (total)
  upload_response,            // server: initiate upload answer: expedited value, or segmented (total)
  download_response,          // server: initiate download accepted
  upload_segment_request,     // client: next upload segment (toggle)
  upload_segment,             // server: segment data (toggle, size bytes, last)
  download_segment,           // client: segment data (toggle, size bytes, last)
  download_segment_response,  // server: segment taken (toggle)
  abort,                      // either side: transfer aborted with abort_code
  unsupported,                // block transfer, or a command specifier no SDO service has
};

struct SdoMessage {
  SdoKind kind{SdoKind::abort};
  std::uint16_t index{0};  // initiate and abort frames only
  std::uint8_t sub{0};
  std::uint32_t value{0};  // expedited data
  std::uint8_t size{0};    // expedited: 1..4 (0 = not indicated); segment: data bytes 0..7
  std::uint32_t abort_code{0};
  bool expedited{false};       // initiate: e
  bool size_indicated{false};  // initiate: s
  std::uint32_t total{0};      // segmented initiate with s: the transfer's length in bytes
  bool toggle{false};          // segments
  bool last{false};            // segments: c, no more segments follow
  std::array<std::uint8_t, sdo_segment_bytes> data{};  // segment data, `size` bytes
};

[[nodiscard]] CanFrame encode_sdo_upload_request(NodeId server, std::uint16_t index, std::uint8_t sub) noexcept;
// size 1..4 sets the size bits; 0 sends four bytes without a size indication.
[[nodiscard]] CanFrame encode_sdo_download_request(NodeId server, std::uint16_t index, std::uint8_t sub,
                                                   std::uint32_t value, std::uint8_t size) noexcept;
[[nodiscard]] CanFrame encode_sdo_upload_response(NodeId server, std::uint16_t index, std::uint8_t sub,
                                                  std::uint32_t value, std::uint8_t size) noexcept;
[[nodiscard]] CanFrame encode_sdo_download_response(NodeId server, std::uint16_t index, std::uint8_t sub) noexcept;
// Segmented initiates with the size indicated (e = 0, s = 1).
[[nodiscard]] CanFrame encode_sdo_download_segmented_request(NodeId server, std::uint16_t index, std::uint8_t sub,
                                                             std::uint32_t total) noexcept;
[[nodiscard]] CanFrame encode_sdo_upload_segmented_response(NodeId server, std::uint16_t index, std::uint8_t sub,
                                                            std::uint32_t total) noexcept;
[[nodiscard]] CanFrame encode_sdo_upload_segment_request(NodeId server, bool toggle) noexcept;
[[nodiscard]] CanFrame encode_sdo_download_segment_response(NodeId server, bool toggle) noexcept;
// Segments carry the first seven bytes of data at most; the rest of the frame stays zero.
[[nodiscard]] CanFrame encode_sdo_upload_segment(NodeId server, bool toggle, std::span<const std::uint8_t> data,
                                                 bool last) noexcept;
[[nodiscard]] CanFrame encode_sdo_download_segment(NodeId server, bool toggle, std::span<const std::uint8_t> data,
                                                   bool last) noexcept;
// to_server: the client aborts (id 0x600+node); otherwise the server does (0x580+node).
[[nodiscard]] CanFrame encode_sdo_abort(NodeId server, bool to_server, std::uint16_t index, std::uint8_t sub,
                                        SdoAbort code) noexcept;

// Decoders for the two directions: not eight bytes or not this node's SDO id gives nullopt.
// A request the server must refuse still decodes (kind unsupported), so the server can
// answer it with the abort CiA 301 asks for (0x05040001) instead of silence.
[[nodiscard]] std::optional<SdoMessage> decode_sdo_request(const CanFrame& frame, NodeId server) noexcept;
[[nodiscard]] std::optional<SdoMessage> decode_sdo_response(const CanFrame& frame, NodeId server) noexcept;

// One transfer at a time, as CiA 301 allows per SDO channel. Every request it takes is
// answered with exactly one frame (a response or an abort); an abort from the client is not.
class SdoServer {
 public:
  // download_buffer holds a segmented download into a byte string until its last segment, so
  // that an aborted download leaves the object as it was; a byte-string download longer than
  // it aborts 0x05040005. Without one, byte strings take expedited downloads (<= 4 bytes) only.
  SdoServer(NodeId node, ObjectDictionary& od, std::uint32_t timeout_us = sdo_server_default_timeout_us,
            std::span<std::uint8_t> download_buffer = {}) noexcept
      : node_{node}, od_{od}, timeout_us_{timeout_us}, staging_{download_buffer} {}

  // Answers a request addressed to this node. Returns false, and changes nothing, for any
  // frame that is not one (other nodes, other services, malformed lengths). A transfer whose
  // timeout has passed is dropped first (as poll would have), so the request finds the server idle.
  [[nodiscard]] bool on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept;
  // Drops a segmented transfer whose client went silent: abort 0x05040000 on the bus.
  void poll(std::uint64_t now_us, FrameSink& out) noexcept;
  // Forgets a running transfer without a word (NMT reset of the communication).
  void reset() noexcept { phase_ = Phase::idle; watchdog_.disarm(); }

  [[nodiscard]] bool busy() const noexcept { return phase_ != Phase::idle; }
  [[nodiscard]] std::uint64_t requests() const noexcept { return requests_; }
  [[nodiscard]] std::uint64_t aborts() const noexcept { return aborts_; }
  [[nodiscard]] std::uint64_t timeouts() const noexcept { return timeouts_; }

 private:
  enum class Phase : std::uint8_t { idle, uploading, downloading };

  [[nodiscard]] SdoAbort start_upload(const SdoMessage& request, std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] SdoAbort start_download(const SdoMessage& request, std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] SdoAbort next_upload_segment(const SdoMessage& request, std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] SdoAbort take_download_segment(const SdoMessage& request, std::uint64_t now_us,
                                               FrameSink& out) noexcept;
  [[nodiscard]] std::span<std::uint8_t> download_target() noexcept;

  NodeId node_;
  ObjectDictionary& od_;
  std::uint32_t timeout_us_;
  std::span<std::uint8_t> staging_;
  Watchdog watchdog_{};
  Phase phase_{Phase::idle};
  std::uint16_t index_{0};
  std::uint8_t sub_{0};
  const OdEntry* entry_{nullptr};
  bool toggle_{false};          // the toggle bit the next segment must carry
  bool size_indicated_{false};  // download: the client indicated total_
  std::uint32_t total_{0};      // upload: bytes to send; download: indicated size
  std::uint32_t offset_{0};     // bytes sent (upload) or received (download) so far
  std::array<std::uint8_t, 4> word_{};  // a segmented download into an integer object
  std::uint64_t requests_{0};
  std::uint64_t aborts_{0};
  std::uint64_t timeouts_{0};
};

enum class SdoClientStatus : std::uint8_t { idle, busy, done, aborted, timed_out };

struct SdoResult {
  SdoClientStatus status{SdoClientStatus::idle};
  std::uint16_t index{0};
  std::uint8_t sub{0};
  std::uint32_t value{0};   // the uploaded value (upload) or the value written (download)
  std::uint8_t size{0};     // expedited size indication (0 = not indicated); segmented: length if <= 4
  std::uint32_t length{0};  // bytes transferred (upload_bytes: the object's length in the buffer)
  SdoAbort abort{SdoAbort::none};  // why it ended, when it did not end in done
  std::uint32_t abort_raw{0};      // the code on the wire, even one outside the standard set
};

// One transfer at a time, as CiA 301 allows per SDO channel.
class SdoClient {
 public:
  SdoClient(NodeId server, std::uint32_t timeout_us) noexcept : server_{server}, timeout_us_{timeout_us} {}

  // Start a transfer; false when one is still running or the request could not be queued.
  // upload/download: an integer object of up to four bytes (result().value, .size); the
  // server may answer either way, expedited or segmented.
  [[nodiscard]] bool upload(std::uint16_t index, std::uint8_t sub, std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] bool download(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size,
                              std::uint64_t now_us, FrameSink& out) noexcept;
  // Any object into / from the caller's bytes, which must stay valid until the transfer ends:
  // up to four bytes expedited, otherwise segmented. An object longer than `buffer` aborts
  // 0x06070012 on the bus. result().length says how many bytes arrived.
  [[nodiscard]] bool upload_bytes(std::uint16_t index, std::uint8_t sub, std::span<std::uint8_t> buffer,
                                  std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] bool download_bytes(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data,
                                    std::uint64_t now_us, FrameSink& out) noexcept;

  // Consumes the server's response (and sends the next segment request or segment, which
  // restarts the timeout from now_us). Returns true when the frame belonged to the running
  // transfer; stale or foreign frames are ignored.
  [[nodiscard]] bool on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept;
  // Times a silent server out: aborts the transfer on the bus (0x05040000) and reports it.
  void poll(std::uint64_t now_us, FrameSink& out) noexcept;
  // Forget the running transfer without telling the server (after the node rebooted).
  void cancel() noexcept;

  [[nodiscard]] SdoClientStatus status() const noexcept { return result_.status; }
  [[nodiscard]] bool busy() const noexcept { return result_.status == SdoClientStatus::busy; }
  [[nodiscard]] const SdoResult& result() const noexcept { return result_; }
  [[nodiscard]] NodeId server() const noexcept { return server_; }

 private:
  enum class Phase : std::uint8_t { upload_initiate, upload_segment, download_initiate, download_segment };

  [[nodiscard]] bool begin(const CanFrame& request, std::uint16_t index, std::uint8_t sub, Phase phase,
                           std::uint64_t now_us, FrameSink& out) noexcept;
  void finish(SdoClientStatus status, SdoAbort abort, std::uint32_t abort_raw) noexcept;
  // Ends the transfer with an abort of our own, sent to the server.
  void abort_transfer(SdoAbort code, FrameSink& out) noexcept;
  void upload_done() noexcept;
  [[nodiscard]] std::span<std::uint8_t> upload_target() noexcept;
  void take_upload_initiate(const SdoMessage& m, std::uint64_t now_us, FrameSink& out) noexcept;
  void take_upload_segment(const SdoMessage& m, std::uint64_t now_us, FrameSink& out) noexcept;
  void take_download_segment_response(const SdoMessage& m, std::uint64_t now_us, FrameSink& out) noexcept;
  void send_download_segment(std::uint64_t now_us, FrameSink& out) noexcept;

  NodeId server_;
  std::uint32_t timeout_us_;
  Watchdog watchdog_{};
  SdoResult result_{};
  Phase phase_{Phase::upload_initiate};
  bool into_word_{false};   // upload(): the bytes land in word_, then in result_.value
  bool segmented_{false};   // download: segments follow the initiate
  bool toggle_{false};      // the toggle bit of the segment (request) in flight
  bool size_indicated_{false};
  std::uint32_t total_{0};  // upload: the size the server indicated; download: data's size
  std::uint32_t offset_{0};
  std::uint32_t in_flight_{0};  // download: bytes in the segment awaiting its response
  std::span<std::uint8_t> buffer_{};
  std::span<const std::uint8_t> data_{};
  std::array<std::uint8_t, 4> word_{};
};

}  // namespace settle::hal::canopen
