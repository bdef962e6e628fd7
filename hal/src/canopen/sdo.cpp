#include "settle/hal/canopen/sdo.hpp"

#include "settle/hal/canopen/byte_order.hpp"

namespace settle::hal::canopen {

namespace {

// Command specifiers (the top three bits of byte 0).
constexpr std::uint8_t ccs_download_initiate = 1;
constexpr std::uint8_t ccs_upload_initiate = 2;
constexpr std::uint8_t scs_upload_initiate = 2;
constexpr std::uint8_t scs_download_initiate = 3;
constexpr std::uint8_t cs_abort = 4;

constexpr std::uint8_t bit_expedited = 0x02;
constexpr std::uint8_t bit_size_indicated = 0x01;

[[nodiscard]] CanFrame sdo_frame(std::uint32_t id, std::uint8_t command, std::uint16_t index, std::uint8_t sub,
                                 std::uint32_t payload) noexcept {
  CanFrame f{};
  f.id = id;
  f.len = 8;  // SDO frames are always eight bytes; unused bytes stay zero
  f.data[0] = command;
  put_u16(&f.data[1], index);
  f.data[3] = sub;
  put_u32(&f.data[4], payload);
  return f;
}

// Expedited command byte: cs, n = number of unused bytes, e = 1, s = size indicated.
[[nodiscard]] std::uint8_t expedited_command(std::uint8_t cs, std::uint8_t size) noexcept {
  if (size == 0 || size > 4) {
    return static_cast<std::uint8_t>((cs << 5U) | bit_expedited);
  }
  const auto unused = static_cast<std::uint8_t>(4U - size);
  return static_cast<std::uint8_t>((cs << 5U) | (unused << 2U) | bit_expedited | bit_size_indicated);
}

[[nodiscard]] std::uint32_t size_mask(std::uint8_t size) noexcept {
  return size == 0 || size >= 4 ? 0xFFFF'FFFFU : (1U << (8U * size)) - 1U;
}

// Splits an expedited initiate frame (either direction) into value and size.
[[nodiscard]] SdoMessage expedited_payload(const CanFrame& f, SdoKind kind) noexcept {
  SdoMessage m{};
  m.kind = kind;
  m.index = get_u16(&f.data[1]);
  m.sub = f.data[3];
  const std::uint8_t cmd = f.data[0];
  m.size = (cmd & bit_size_indicated) != 0 ? static_cast<std::uint8_t>(4U - ((cmd >> 2U) & 0x03U)) : 0;
  m.value = get_u32(&f.data[4]) & size_mask(m.size);
  return m;
}

[[nodiscard]] SdoMessage plain(const CanFrame& f, SdoKind kind) noexcept {
  SdoMessage m{};
  m.kind = kind;
  m.index = get_u16(&f.data[1]);
  m.sub = f.data[3];
  if (kind == SdoKind::abort) {
    m.abort_code = get_u32(&f.data[4]);
  }
  return m;
}

[[nodiscard]] bool is_sdo_frame(const CanFrame& f, std::uint16_t function_code, NodeId node) noexcept {
  return is_canopen_data_frame(f) && is_valid_node(node) && f.id == cob_id(function_code, node) && f.len == 8;
}

}  // namespace

CanFrame encode_sdo_upload_request(NodeId server, std::uint16_t index, std::uint8_t sub) noexcept {
  return sdo_frame(cob_id(cob::sdo_rx, server), ccs_upload_initiate << 5U, index, sub, 0);
}

CanFrame encode_sdo_download_request(NodeId server, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                                     std::uint8_t size) noexcept {
  return sdo_frame(cob_id(cob::sdo_rx, server), expedited_command(ccs_download_initiate, size), index, sub,
                   value & size_mask(size));
}

CanFrame encode_sdo_upload_response(NodeId server, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                                    std::uint8_t size) noexcept {
  return sdo_frame(cob_id(cob::sdo_tx, server), expedited_command(scs_upload_initiate, size), index, sub,
                   value & size_mask(size));
}

CanFrame encode_sdo_download_response(NodeId server, std::uint16_t index, std::uint8_t sub) noexcept {
  return sdo_frame(cob_id(cob::sdo_tx, server), scs_download_initiate << 5U, index, sub, 0);
}

CanFrame encode_sdo_abort(NodeId server, bool to_server, std::uint16_t index, std::uint8_t sub,
                          SdoAbort code) noexcept {
  return sdo_frame(cob_id(to_server ? cob::sdo_rx : cob::sdo_tx, server), cs_abort << 5U, index, sub,
                   static_cast<std::uint32_t>(code));
}

std::optional<SdoMessage> decode_sdo_request(const CanFrame& frame, NodeId server) noexcept {
  if (!is_sdo_frame(frame, cob::sdo_rx, server)) {
    return std::nullopt;
  }
  const std::uint8_t cmd = frame.data[0];
  switch (cmd >> 5U) {
    case ccs_download_initiate:
      // Without the expedited bit the client is starting a segmented download.
      return (cmd & bit_expedited) != 0 ? expedited_payload(frame, SdoKind::download_request)
                                        : plain(frame, SdoKind::unsupported);
    case ccs_upload_initiate: return plain(frame, SdoKind::upload_request);
    case cs_abort: return plain(frame, SdoKind::abort);
    default: return plain(frame, SdoKind::unsupported);
  }
}

std::optional<SdoMessage> decode_sdo_response(const CanFrame& frame, NodeId server) noexcept {
  if (!is_sdo_frame(frame, cob::sdo_tx, server)) {
    return std::nullopt;
  }
  const std::uint8_t cmd = frame.data[0];
  switch (cmd >> 5U) {
    case scs_upload_initiate:
      return (cmd & bit_expedited) != 0 ? expedited_payload(frame, SdoKind::upload_response)
                                        : plain(frame, SdoKind::unsupported);
    case scs_download_initiate: return plain(frame, SdoKind::download_response);
    case cs_abort: return plain(frame, SdoKind::abort);
    default: return plain(frame, SdoKind::unsupported);
  }
}

bool SdoServer::on_frame(const CanFrame& frame, FrameSink& out) noexcept {
  const auto request = decode_sdo_request(frame, node_);
  if (!request) {
    return false;
  }
  ++requests_;
  SdoAbort abort = SdoAbort::none;
  switch (request->kind) {
    case SdoKind::upload_request: {
      std::uint32_t value = 0;
      std::uint8_t size = 0;
      abort = od_.read(request->index, request->sub, value, size);
      if (abort == SdoAbort::none) {
        (void)out.put(encode_sdo_upload_response(node_, request->index, request->sub, value, size));
      }
      break;
    }
    case SdoKind::download_request:
      abort = od_.write(request->index, request->sub, request->value, request->size);
      if (abort == SdoAbort::none) {
        (void)out.put(encode_sdo_download_response(node_, request->index, request->sub));
      }
      break;
    case SdoKind::abort:
      // Expedited transfers keep no state between frames, so there is nothing to undo.
      return true;
    case SdoKind::upload_response:
    case SdoKind::download_response:
    case SdoKind::unsupported:
      abort = SdoAbort::unknown_command;
      break;
  }
  if (abort != SdoAbort::none) {
    ++aborts_;
    (void)out.put(encode_sdo_abort(node_, false, request->index, request->sub, abort));
  }
  return true;
}

bool SdoClient::begin(const CanFrame& request, std::uint16_t index, std::uint8_t sub, bool is_upload,
                      std::uint64_t now_us, FrameSink& out) noexcept {
  if (busy() || !out.put(request)) {
    return false;
  }
  result_ = SdoResult{};
  result_.status = SdoClientStatus::busy;
  result_.index = index;
  result_.sub = sub;
  is_upload_ = is_upload;
  watchdog_.arm(timeout_us_, now_us);
  return true;
}

bool SdoClient::upload(std::uint16_t index, std::uint8_t sub, std::uint64_t now_us, FrameSink& out) noexcept {
  return begin(encode_sdo_upload_request(server_, index, sub), index, sub, true, now_us, out);
}

bool SdoClient::download(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size,
                         std::uint64_t now_us, FrameSink& out) noexcept {
  if (!begin(encode_sdo_download_request(server_, index, sub, value, size), index, sub, false, now_us, out)) {
    return false;
  }
  result_.value = value & size_mask(size);
  result_.size = size;
  return true;
}

void SdoClient::finish(SdoClientStatus status, SdoAbort abort, std::uint32_t abort_raw) noexcept {
  result_.status = status;
  result_.abort = abort;
  result_.abort_raw = abort_raw;
  watchdog_.disarm();
}

bool SdoClient::on_frame(const CanFrame& frame, FrameSink& out) noexcept {
  if (!busy()) {
    return false;
  }
  const auto response = decode_sdo_response(frame, server_);
  if (!response || response->index != result_.index || response->sub != result_.sub) {
    return false;
  }
  switch (response->kind) {
    case SdoKind::upload_response:
      if (!is_upload_) {
        return false;
      }
      result_.value = response->value;
      result_.size = response->size;
      finish(SdoClientStatus::done, SdoAbort::none, 0);
      return true;
    case SdoKind::download_response:
      if (is_upload_) {
        return false;
      }
      finish(SdoClientStatus::done, SdoAbort::none, 0);
      return true;
    case SdoKind::abort: {
      const auto code = is_known_abort(response->abort_code) ? static_cast<SdoAbort>(response->abort_code)
                                                               : SdoAbort::general_error;
      finish(SdoClientStatus::aborted, code, response->abort_code);
      return true;
    }
    case SdoKind::unsupported:
      // A segmented upload answer: the object is larger than this client can take.
      (void)out.put(encode_sdo_abort(server_, true, result_.index, result_.sub, SdoAbort::unknown_command));
      finish(SdoClientStatus::aborted, SdoAbort::unknown_command, static_cast<std::uint32_t>(SdoAbort::unknown_command));
      return true;
    case SdoKind::upload_request:
    case SdoKind::download_request:
      return false;
  }
  return false;
}

void SdoClient::poll(std::uint64_t now_us, FrameSink& out) noexcept {
  if (busy() && watchdog_.check(now_us)) {
    (void)out.put(encode_sdo_abort(server_, true, result_.index, result_.sub, SdoAbort::timeout));
    finish(SdoClientStatus::timed_out, SdoAbort::timeout, static_cast<std::uint32_t>(SdoAbort::timeout));
  }
}

void SdoClient::cancel() noexcept {
  if (busy()) {
    finish(SdoClientStatus::idle, SdoAbort::none, 0);
  }
}

}  // namespace settle::hal::canopen
