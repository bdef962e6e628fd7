// CiA 301 SDO, expedited transfers only (objects of up to four bytes, which is every object a
// CiA 402 drive is configured through): the frame codec, the server that answers from an
// object dictionary, and the client a master uses, with timeouts and the standard aborts.
#pragma once

#include <cstdint>
#include <optional>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/canopen/object_dictionary.hpp"
#include "settle/hal/canopen/sdo_abort.hpp"
#include "settle/hal/canopen/watchdog.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen {

enum class SdoKind : std::uint8_t {
  upload_request,     // client: read index/sub
  download_request,   // client: expedited write of value (size bytes, 0 = not indicated)
  upload_response,    // server: expedited answer with value
  download_response,  // server: write done
  abort,              // either side: transfer aborted with abort_code
  unsupported,        // segmented, block, or a command specifier no SDO service has
};

struct SdoMessage {
  SdoKind kind{SdoKind::abort};
  std::uint16_t index{0};
  std::uint8_t sub{0};
  std::uint32_t value{0};
  std::uint8_t size{0};
  std::uint32_t abort_code{0};
};

[[nodiscard]] CanFrame encode_sdo_upload_request(NodeId server, std::uint16_t index, std::uint8_t sub) noexcept;
// size 1..4 sets the size bits; 0 sends four bytes without a size indication.
[[nodiscard]] CanFrame encode_sdo_download_request(NodeId server, std::uint16_t index, std::uint8_t sub,
                                                   std::uint32_t value, std::uint8_t size) noexcept;
[[nodiscard]] CanFrame encode_sdo_upload_response(NodeId server, std::uint16_t index, std::uint8_t sub,
                                                  std::uint32_t value, std::uint8_t size) noexcept;
[[nodiscard]] CanFrame encode_sdo_download_response(NodeId server, std::uint16_t index, std::uint8_t sub) noexcept;
// to_server: the client aborts (id 0x600+node); otherwise the server does (0x580+node).
[[nodiscard]] CanFrame encode_sdo_abort(NodeId server, bool to_server, std::uint16_t index, std::uint8_t sub,
                                        SdoAbort code) noexcept;

// Decoders for the two directions: not eight bytes or not this node's SDO id gives nullopt.
// A request the server must refuse still decodes (kind unsupported), so the server can
// answer it with the abort CiA 301 asks for (0x05040001) instead of silence.
[[nodiscard]] std::optional<SdoMessage> decode_sdo_request(const CanFrame& frame, NodeId server) noexcept;
[[nodiscard]] std::optional<SdoMessage> decode_sdo_response(const CanFrame& frame, NodeId server) noexcept;

class SdoServer {
 public:
  SdoServer(NodeId node, ObjectDictionary& od) noexcept : node_{node}, od_{od} {}

  // Answers a request addressed to this node. Returns false, and changes nothing, for any
  // frame that is not one (other nodes, other services, malformed lengths).
  [[nodiscard]] bool on_frame(const CanFrame& frame, FrameSink& out) noexcept;

  [[nodiscard]] std::uint64_t requests() const noexcept { return requests_; }
  [[nodiscard]] std::uint64_t aborts() const noexcept { return aborts_; }

 private:
  NodeId node_;
  ObjectDictionary& od_;
  std::uint64_t requests_{0};
  std::uint64_t aborts_{0};
};

enum class SdoClientStatus : std::uint8_t { idle, busy, done, aborted, timed_out };

struct SdoResult {
  SdoClientStatus status{SdoClientStatus::idle};
  std::uint16_t index{0};
  std::uint8_t sub{0};
  std::uint32_t value{0};  // the uploaded value (upload) or the value written (download)
  std::uint8_t size{0};
  SdoAbort abort{SdoAbort::none};  // why it ended, when it did not end in done
  std::uint32_t abort_raw{0};      // the code on the wire, even one outside the standard set
};

// One transfer at a time, as CiA 301 allows per SDO channel.
class SdoClient {
 public:
  SdoClient(NodeId server, std::uint32_t timeout_us) noexcept : server_{server}, timeout_us_{timeout_us} {}

  // Start a transfer; false when one is still running or the request could not be queued.
  [[nodiscard]] bool upload(std::uint16_t index, std::uint8_t sub, std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] bool download(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size,
                              std::uint64_t now_us, FrameSink& out) noexcept;

  // Consumes the server's response. Returns true when the frame was the answer to the
  // running transfer; stale or foreign frames are ignored.
  [[nodiscard]] bool on_frame(const CanFrame& frame, FrameSink& out) noexcept;
  // Times a silent server out: aborts the transfer on the bus (0x05040000) and reports it.
  void poll(std::uint64_t now_us, FrameSink& out) noexcept;
  // Forget the running transfer without telling the server (after the node rebooted).
  void cancel() noexcept;

  [[nodiscard]] SdoClientStatus status() const noexcept { return result_.status; }
  [[nodiscard]] bool busy() const noexcept { return result_.status == SdoClientStatus::busy; }
  [[nodiscard]] const SdoResult& result() const noexcept { return result_; }
  [[nodiscard]] NodeId server() const noexcept { return server_; }

 private:
  [[nodiscard]] bool begin(const CanFrame& request, std::uint16_t index, std::uint8_t sub, bool is_upload,
                           std::uint64_t now_us, FrameSink& out) noexcept;
  void finish(SdoClientStatus status, SdoAbort abort, std::uint32_t abort_raw) noexcept;

  NodeId server_;
  std::uint32_t timeout_us_;
  Watchdog watchdog_{};
  SdoResult result_{};
  bool is_upload_{false};
};

}  // namespace settle::hal::canopen
