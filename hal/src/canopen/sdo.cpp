// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/sdo.hpp"

#include "settle/hal/canopen/byte_order.hpp"

namespace settle::hal::canopen {

namespace {

// Command specifiers (the top three bits of byte 0).
constexpr std::uint8_t ccs_download_segment = 0;
constexpr std::uint8_t ccs_download_initiate = 1;
constexpr std::uint8_t ccs_upload_initiate = 2;
constexpr std::uint8_t ccs_upload_segment = 3;
constexpr std::uint8_t scs_upload_segment = 0;
constexpr std::uint8_t scs_download_segment = 1;
constexpr std::uint8_t scs_upload_initiate = 2;
constexpr std::uint8_t scs_download_initiate = 3;
constexpr std::uint8_t cs_abort = 4;

constexpr std::uint8_t bit_expedited = 0x02;
constexpr std::uint8_t bit_size_indicated = 0x01;
constexpr std::uint8_t bit_toggle = 0x10;
constexpr std::uint8_t bit_last = 0x01;

[[nodiscard]] CanFrame sdo_frame(std::uint32_t id, std::uint8_t command, std::uint16_t index, std::uint8_t sub,
                                 std::uint32_t payload) noexcept {
  CanFrame f = classic_frame(id, 8);  // SDO frames are always eight bytes; unused bytes stay zero
  f.data[0] = command;
  put_u16(&f.data[1], index);
  f.data[3] = sub;
  put_u32(&f.data[4], payload);
  return f;
}

// Segment frame: cs, t, n = number of unused data bytes, c = last; data in bytes 1..7.
[[nodiscard]] CanFrame segment_frame(std::uint32_t id, std::uint8_t cs, bool toggle,
                                     std::span<const std::uint8_t> data, bool last) noexcept {
  const std::size_t count = data.size() < sdo_segment_bytes ? data.size() : sdo_segment_bytes;
  CanFrame f = classic_frame(id, 8);
  const auto unused = static_cast<std::uint8_t>(sdo_segment_bytes - count);
  f.data[0] = static_cast<std::uint8_t>((static_cast<unsigned>(cs) << 5U) | (toggle ? bit_toggle : 0U) |
                                        (static_cast<unsigned>(unused) << 1U) | (last ? bit_last : 0U));
  for (std::size_t i = 0; i < count; ++i) {
    f.data[1 + i] = data[i];
  }
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

// Little-endian value of up to four bytes.
[[nodiscard]] std::uint32_t le_value(std::span<const std::uint8_t> bytes) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < bytes.size() && i < 4; ++i) {
    v |= static_cast<std::uint32_t>(bytes[i]) << (8U * i);
  }
  return v;
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

// An initiate frame (either direction): expedited value and size, or the segmented size.
[[nodiscard]] SdoMessage initiate(const CanFrame& f, SdoKind kind) noexcept {
  SdoMessage m = plain(f, kind);
  const std::uint8_t cmd = f.data[0];
  m.expedited = (cmd & bit_expedited) != 0;
  m.size_indicated = (cmd & bit_size_indicated) != 0;
  if (m.expedited) {
    m.size = m.size_indicated ? static_cast<std::uint8_t>(4U - ((cmd >> 2U) & 0x03U)) : 0;
    m.value = get_u32(&f.data[4]) & size_mask(m.size);
  } else if (m.size_indicated) {
    m.total = get_u32(&f.data[4]);
  }
  return m;
}

[[nodiscard]] SdoMessage segment(const CanFrame& f, SdoKind kind) noexcept {
  SdoMessage m{};
  m.kind = kind;
  const std::uint8_t cmd = f.data[0];
  m.toggle = (cmd & bit_toggle) != 0;
  m.last = (cmd & bit_last) != 0;
  m.size = static_cast<std::uint8_t>(sdo_segment_bytes - ((cmd >> 1U) & 0x07U));
  for (std::size_t i = 0; i < m.size; ++i) {
    m.data[i] = f.data[1 + i];
  }
  return m;
}

[[nodiscard]] SdoMessage toggle_only(const CanFrame& f, SdoKind kind) noexcept {
  SdoMessage m{};
  m.kind = kind;
  m.toggle = (f.data[0] & bit_toggle) != 0;
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

CanFrame encode_sdo_download_segmented_request(NodeId server, std::uint16_t index, std::uint8_t sub,
                                               std::uint32_t total) noexcept {
  return sdo_frame(cob_id(cob::sdo_rx, server), (ccs_download_initiate << 5U) | bit_size_indicated, index, sub,
                   total);
}

CanFrame encode_sdo_upload_segmented_response(NodeId server, std::uint16_t index, std::uint8_t sub,
                                              std::uint32_t total) noexcept {
  return sdo_frame(cob_id(cob::sdo_tx, server), (scs_upload_initiate << 5U) | bit_size_indicated, index, sub,
                   total);
}

CanFrame encode_sdo_upload_segment_request(NodeId server, bool toggle) noexcept {
  return sdo_frame(cob_id(cob::sdo_rx, server),
                   static_cast<std::uint8_t>((ccs_upload_segment << 5U) | (toggle ? bit_toggle : 0U)), 0, 0, 0);
}

CanFrame encode_sdo_download_segment_response(NodeId server, bool toggle) noexcept {
  return sdo_frame(cob_id(cob::sdo_tx, server),
                   static_cast<std::uint8_t>((scs_download_segment << 5U) | (toggle ? bit_toggle : 0U)), 0, 0, 0);
}

CanFrame encode_sdo_upload_segment(NodeId server, bool toggle, std::span<const std::uint8_t> data,
                                   bool last) noexcept {
  return segment_frame(cob_id(cob::sdo_tx, server), scs_upload_segment, toggle, data, last);
}

CanFrame encode_sdo_download_segment(NodeId server, bool toggle, std::span<const std::uint8_t> data,
                                     bool last) noexcept {
  return segment_frame(cob_id(cob::sdo_rx, server), ccs_download_segment, toggle, data, last);
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
  switch (frame.data[0] >> 5U) {
    case ccs_download_segment: return segment(frame, SdoKind::download_segment);
    case ccs_download_initiate: return initiate(frame, SdoKind::download_request);
    case ccs_upload_initiate: return plain(frame, SdoKind::upload_request);
    case ccs_upload_segment: return toggle_only(frame, SdoKind::upload_segment_request);
    case cs_abort: return plain(frame, SdoKind::abort);
    default: return plain(frame, SdoKind::unsupported);  // 5, 6: block transfer; 7: none
  }
}

std::optional<SdoMessage> decode_sdo_response(const CanFrame& frame, NodeId server) noexcept {
  if (!is_sdo_frame(frame, cob::sdo_tx, server)) {
    return std::nullopt;
  }
  switch (frame.data[0] >> 5U) {
    case scs_upload_segment: return segment(frame, SdoKind::upload_segment);
    case scs_download_segment: return toggle_only(frame, SdoKind::download_segment_response);
    case scs_upload_initiate: return initiate(frame, SdoKind::upload_response);
    case scs_download_initiate: return plain(frame, SdoKind::download_response);
    case cs_abort: return plain(frame, SdoKind::abort);
    default: return plain(frame, SdoKind::unsupported);
  }
}

// ---- Server ----

bool SdoServer::on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept {
  const auto request = decode_sdo_request(frame, node_);
  if (!request) {
    return false;
  }
  poll(now_us, out);
  ++requests_;
  if (request->kind == SdoKind::abort) {
    reset();  // the client gave the transfer up: nothing to answer, nothing was stored
    return true;
  }
  std::uint16_t index = request->index;
  std::uint8_t sub = request->sub;
  SdoAbort abort = SdoAbort::unknown_command;
  switch (phase_) {
    case Phase::idle:
      if (request->kind == SdoKind::upload_request) {
        abort = start_upload(*request, now_us, out);
      } else if (request->kind == SdoKind::download_request) {
        abort = start_download(*request, now_us, out);
      }
      // Anything else (a segment without a transfer, block transfer, command 7): 0x05040001.
      break;
    case Phase::uploading:
      if (request->kind == SdoKind::upload_segment_request) {
        abort = next_upload_segment(*request, now_us, out);
      }
      break;
    case Phase::downloading:
      if (request->kind == SdoKind::download_segment) {
        abort = take_download_segment(*request, now_us, out);
      }
      break;
  }
  if (abort != SdoAbort::none) {
    if (phase_ != Phase::idle) {
      index = index_;  // the abort ends the running transfer and names it
      sub = sub_;
    }
    reset();
    ++aborts_;
    (void)out.put(encode_sdo_abort(node_, false, index, sub, abort));
  }
  return true;
}

void SdoServer::poll(std::uint64_t now_us, FrameSink& out) noexcept {
  if (phase_ != Phase::idle && watchdog_.check(now_us)) {
    ++aborts_;
    ++timeouts_;
    (void)out.put(encode_sdo_abort(node_, false, index_, sub_, SdoAbort::timeout));
    reset();
  }
}

SdoAbort SdoServer::start_upload(const SdoMessage& request, std::uint64_t now_us, FrameSink& out) noexcept {
  const OdEntry* entry = nullptr;
  if (const SdoAbort abort = od_.readable(request.index, request.sub, entry); abort != SdoAbort::none) {
    return abort;
  }
  const OdBytes* bytes = entry->var.bytes();
  if (bytes == nullptr) {
    (void)out.put(encode_sdo_upload_response(node_, request.index, request.sub, entry->var.raw(),
                                             od_type_size(entry->var.type())));
    return SdoAbort::none;
  }
  const std::uint32_t length = bytes->size < bytes->capacity ? bytes->size : bytes->capacity;
  if (length >= 1 && length <= 4) {
    (void)out.put(encode_sdo_upload_response(node_, request.index, request.sub, le_value(bytes->view()),
                                             static_cast<std::uint8_t>(length)));
    return SdoAbort::none;
  }
  // Longer than an expedited frame holds, or empty (which it cannot say): segmented.
  phase_ = Phase::uploading;
  index_ = request.index;
  sub_ = request.sub;
  entry_ = entry;
  total_ = length;
  offset_ = 0;
  toggle_ = false;
  watchdog_.arm(timeout_us_, now_us);
  (void)out.put(encode_sdo_upload_segmented_response(node_, request.index, request.sub, length));
  return SdoAbort::none;
}

SdoAbort SdoServer::next_upload_segment(const SdoMessage& request, std::uint64_t now_us, FrameSink& out) noexcept {
  if (request.toggle != toggle_) {
    return SdoAbort::toggle_bit;
  }
  const std::uint32_t left = total_ - offset_;
  const std::uint32_t count = left < sdo_segment_bytes ? left : sdo_segment_bytes;
  const bool last = count == left;
  // total_ was bounded by the buffer's capacity when the upload started; the capacity is fixed.
  const std::span<const std::uint8_t> data{entry_->var.bytes()->data + offset_, count};
  (void)out.put(encode_sdo_upload_segment(node_, toggle_, data, last));
  offset_ += count;
  toggle_ = !toggle_;
  if (last) {
    reset();
  } else {
    watchdog_.arm(timeout_us_, now_us);
  }
  return SdoAbort::none;
}

std::span<std::uint8_t> SdoServer::download_target() noexcept {
  return entry_->var.bytes() != nullptr ? staging_ : std::span<std::uint8_t>{word_};
}

SdoAbort SdoServer::start_download(const SdoMessage& request, std::uint64_t now_us, FrameSink& out) noexcept {
  if (request.expedited) {
    const SdoAbort abort = od_.write(request.index, request.sub, request.value, request.size);
    if (abort == SdoAbort::none) {
      (void)out.put(encode_sdo_download_response(node_, request.index, request.sub));
    }
    return abort;
  }
  const OdEntry* entry = nullptr;
  if (const SdoAbort abort = od_.writable(request.index, request.sub, entry); abort != SdoAbort::none) {
    return abort;
  }
  const OdBytes* bytes = entry->var.bytes();
  if (request.size_indicated) {
    // An integer takes exactly its size; a byte string at most its capacity.
    const std::uint32_t object = bytes != nullptr ? bytes->capacity : od_type_size(entry->var.type());
    if (request.total > object) {
      return SdoAbort::length_too_high;
    }
    if (bytes == nullptr && request.total < object) {
      return SdoAbort::length_too_low;
    }
    if (bytes != nullptr && request.total > staging_.size()) {
      return SdoAbort::out_of_memory;
    }
  }
  phase_ = Phase::downloading;
  index_ = request.index;
  sub_ = request.sub;
  entry_ = entry;
  size_indicated_ = request.size_indicated;
  total_ = request.total;
  offset_ = 0;
  toggle_ = false;
  word_ = {};
  watchdog_.arm(timeout_us_, now_us);
  (void)out.put(encode_sdo_download_response(node_, request.index, request.sub));
  return SdoAbort::none;
}

SdoAbort SdoServer::take_download_segment(const SdoMessage& request, std::uint64_t now_us,
                                          FrameSink& out) noexcept {
  if (request.toggle != toggle_) {
    return SdoAbort::toggle_bit;
  }
  if (request.size == 0 && !request.last) {
    // A segment that carries nothing and announces more: not a download at all (it would keep
    // the server busy for ever, 100 000 of them answered one by one). Each segment but the last
    // carries a byte at least, so a transfer has at most its size + 1 segments: more are refused
    // by the length checks below (0x06070012).
    return SdoAbort::unknown_command;
  }
  const std::uint32_t end = offset_ + request.size;
  const OdBytes* bytes = entry_->var.bytes();
  const std::uint32_t object = bytes != nullptr ? bytes->capacity : od_type_size(entry_->var.type());
  if ((size_indicated_ && end > total_) || end > object) {
    return SdoAbort::length_too_high;
  }
  const std::span<std::uint8_t> target = download_target();
  if (end > target.size()) {
    return SdoAbort::out_of_memory;
  }
  for (std::size_t i = 0; i < request.size; ++i) {
    target[offset_ + i] = request.data[i];
  }
  offset_ = end;
  if (!request.last) {
    (void)out.put(encode_sdo_download_segment_response(node_, toggle_));
    toggle_ = !toggle_;
    watchdog_.arm(timeout_us_, now_us);
    return SdoAbort::none;
  }
  if ((size_indicated_ && offset_ < total_) || (bytes == nullptr && offset_ < object)) {
    return SdoAbort::length_too_low;
  }
  const SdoAbort abort =
      bytes != nullptr ? od_.write_bytes(*entry_, target.first(offset_))
                       : od_.write(index_, sub_, le_value(target.first(offset_)), static_cast<std::uint8_t>(offset_));
  if (abort != SdoAbort::none) {
    return abort;
  }
  (void)out.put(encode_sdo_download_segment_response(node_, toggle_));
  reset();
  return SdoAbort::none;
}

// ---- Client ----

bool SdoClient::begin(const CanFrame& request, std::uint16_t index, std::uint8_t sub, Phase phase,
                      std::uint64_t now_us, FrameSink& out) noexcept {
  if (busy() || !out.put(request)) {
    return false;
  }
  result_ = SdoResult{};
  result_.status = SdoClientStatus::busy;
  result_.index = index;
  result_.sub = sub;
  phase_ = phase;
  into_word_ = false;
  segmented_ = false;
  toggle_ = false;
  size_indicated_ = false;
  total_ = 0;
  offset_ = 0;
  in_flight_ = 0;
  buffer_ = {};
  data_ = {};
  word_ = {};
  watchdog_.arm(timeout_us_, now_us);
  return true;
}

bool SdoClient::upload(std::uint16_t index, std::uint8_t sub, std::uint64_t now_us, FrameSink& out) noexcept {
  if (!begin(encode_sdo_upload_request(server_, index, sub), index, sub, Phase::upload_initiate, now_us, out)) {
    return false;
  }
  into_word_ = true;
  return true;
}

bool SdoClient::upload_bytes(std::uint16_t index, std::uint8_t sub, std::span<std::uint8_t> buffer,
                             std::uint64_t now_us, FrameSink& out) noexcept {
  if (!begin(encode_sdo_upload_request(server_, index, sub), index, sub, Phase::upload_initiate, now_us, out)) {
    return false;
  }
  buffer_ = buffer;
  return true;
}

bool SdoClient::download(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size,
                         std::uint64_t now_us, FrameSink& out) noexcept {
  if (!begin(encode_sdo_download_request(server_, index, sub, value, size), index, sub, Phase::download_initiate,
             now_us, out)) {
    return false;
  }
  result_.value = value & size_mask(size);
  result_.size = size;
  result_.length = size == 0 || size > 4 ? 4U : size;
  return true;
}

bool SdoClient::download_bytes(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data,
                               std::uint64_t now_us, FrameSink& out) noexcept {
  if constexpr (sizeof(std::size_t) > sizeof(std::uint32_t)) {
    if (data.size() > 0xFFFF'FFFFU) {
      return false;  // more than a size indication can say
    }
  }
  const auto total = static_cast<std::uint32_t>(data.size());
  if (total >= 1 && total <= 4) {
    return download(index, sub, le_value(data), static_cast<std::uint8_t>(total), now_us, out);
  }
  if (!begin(encode_sdo_download_segmented_request(server_, index, sub, total), index, sub,
             Phase::download_initiate, now_us, out)) {
    return false;
  }
  segmented_ = true;
  size_indicated_ = true;
  total_ = total;
  data_ = data;
  return true;
}

void SdoClient::finish(SdoClientStatus status, SdoAbort abort, std::uint32_t abort_raw) noexcept {
  result_.status = status;
  result_.abort = abort;
  result_.abort_raw = abort_raw;
  watchdog_.disarm();
}

void SdoClient::abort_transfer(SdoAbort code, FrameSink& out) noexcept {
  (void)out.put(encode_sdo_abort(server_, true, result_.index, result_.sub, code));
  finish(SdoClientStatus::aborted, code, static_cast<std::uint32_t>(code));
}

std::span<std::uint8_t> SdoClient::upload_target() noexcept {
  return into_word_ ? std::span<std::uint8_t>{word_} : buffer_;
}

void SdoClient::upload_done() noexcept {
  const std::span<const std::uint8_t> received = upload_target().first(offset_);
  result_.length = offset_;
  result_.value = le_value(received);
  finish(SdoClientStatus::done, SdoAbort::none, 0);
}

void SdoClient::take_upload_initiate(const SdoMessage& m, std::uint64_t now_us, FrameSink& out) noexcept {
  const std::span<std::uint8_t> target = upload_target();
  if (m.expedited) {
    const std::uint8_t count = m.size == 0 ? 4 : m.size;
    if (count > target.size()) {
      abort_transfer(SdoAbort::length_too_high, out);
      return;
    }
    if (!into_word_) {  // upload_bytes(): the caller's bytes; upload(): the value is all it gives
      std::uint8_t bytes[4]{};
      put_u32(bytes, m.value);
      for (std::size_t i = 0; i < count; ++i) {
        target[i] = bytes[i];
      }
    }
    // upload_done() without reading the bytes back: they are m.value's low `count` bytes. Kept
    // apart on purpose: ended through upload_done() (copying into word_, reading it back), the
    // micro:bit's fixed-point servo loop's worst tick (an expedited response) rose from 1 312 to
    // 1 408 instructions, over its 1 350 budget (session 28, e10a28b, reverted).
    offset_ = count;
    result_.length = count;
    result_.value = m.value & size_mask(count);
    result_.size = m.size;
    finish(SdoClientStatus::done, SdoAbort::none, 0);
    return;
  }
  if (m.size_indicated && m.total > target.size()) {
    abort_transfer(SdoAbort::length_too_high, out);
    return;
  }
  size_indicated_ = m.size_indicated;
  total_ = m.total;
  phase_ = Phase::upload_segment;
  toggle_ = false;
  offset_ = 0;
  watchdog_.arm(timeout_us_, now_us);
  (void)out.put(encode_sdo_upload_segment_request(server_, toggle_));
}

void SdoClient::take_upload_segment(const SdoMessage& m, std::uint64_t now_us, FrameSink& out) noexcept {
  if (m.toggle != toggle_) {
    abort_transfer(SdoAbort::toggle_bit, out);
    return;
  }
  const std::uint32_t end = offset_ + m.size;
  if (size_indicated_ && end > total_) {
    abort_transfer(SdoAbort::length_mismatch, out);
    return;
  }
  const std::span<std::uint8_t> target = upload_target();
  if (end > target.size()) {
    abort_transfer(SdoAbort::length_too_high, out);
    return;
  }
  for (std::size_t i = 0; i < m.size; ++i) {
    target[offset_ + i] = m.data[i];
  }
  offset_ = end;
  if (m.last) {
    if (size_indicated_ && offset_ != total_) {
      abort_transfer(SdoAbort::length_mismatch, out);
      return;
    }
    upload_done();
    result_.size = offset_ <= 4 ? static_cast<std::uint8_t>(offset_) : 0;
    return;
  }
  toggle_ = !toggle_;
  watchdog_.arm(timeout_us_, now_us);
  (void)out.put(encode_sdo_upload_segment_request(server_, toggle_));
}

void SdoClient::send_download_segment(std::uint64_t now_us, FrameSink& out) noexcept {
  const std::uint32_t left = total_ - offset_;
  in_flight_ = left < sdo_segment_bytes ? left : sdo_segment_bytes;
  watchdog_.arm(timeout_us_, now_us);
  (void)out.put(encode_sdo_download_segment(server_, toggle_, data_.subspan(offset_, in_flight_), in_flight_ == left));
}

void SdoClient::take_download_segment_response(const SdoMessage& m, std::uint64_t now_us, FrameSink& out) noexcept {
  if (m.toggle != toggle_) {
    abort_transfer(SdoAbort::toggle_bit, out);
    return;
  }
  offset_ += in_flight_;
  if (offset_ == total_) {
    result_.length = total_;
    finish(SdoClientStatus::done, SdoAbort::none, 0);
    return;
  }
  toggle_ = !toggle_;
  send_download_segment(now_us, out);
}

bool SdoClient::on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept {
  if (!busy()) {
    return false;
  }
  const auto response = decode_sdo_response(frame, server_);
  if (!response) {
    return false;
  }
  const bool ours = response->index == result_.index && response->sub == result_.sub;
  switch (response->kind) {
    case SdoKind::abort: {
      if (!ours) {
        return false;
      }
      const auto code = is_known_abort(response->abort_code) ? static_cast<SdoAbort>(response->abort_code)
                                                               : SdoAbort::general_error;
      finish(SdoClientStatus::aborted, code, response->abort_code);
      return true;
    }
    case SdoKind::upload_response:
      if (phase_ != Phase::upload_initiate || !ours) {
        return false;
      }
      take_upload_initiate(*response, now_us, out);
      return true;
    case SdoKind::upload_segment:
      if (phase_ != Phase::upload_segment) {
        return false;
      }
      take_upload_segment(*response, now_us, out);
      return true;
    case SdoKind::download_response:
      if (phase_ != Phase::download_initiate || !ours) {
        return false;
      }
      if (!segmented_) {
        finish(SdoClientStatus::done, SdoAbort::none, 0);
        return true;
      }
      phase_ = Phase::download_segment;
      toggle_ = false;
      send_download_segment(now_us, out);
      return true;
    case SdoKind::download_segment_response:
      if (phase_ != Phase::download_segment) {
        return false;
      }
      take_download_segment_response(*response, now_us, out);
      return true;
    case SdoKind::unsupported:
      // A block-transfer answer, or a command no SDO service has: this client does neither.
      if (!ours) {
        return false;
      }
      abort_transfer(SdoAbort::unknown_command, out);
      return true;
    case SdoKind::upload_request:
    case SdoKind::download_request:
    case SdoKind::upload_segment_request:
    case SdoKind::download_segment:
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
