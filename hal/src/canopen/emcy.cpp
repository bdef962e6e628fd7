// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/emcy.hpp"

#include "settle/hal/canopen/byte_order.hpp"

namespace settle::hal::canopen {

CanFrame encode_emcy(NodeId node, const EmcyMessage& message) noexcept {
  CanFrame f{};
  f.id = cob_id(cob::emcy, node);
  f.len = 8;
  put_u16(&f.data[0], message.error_code);
  f.data[2] = message.error_register;
  for (std::size_t i = 0; i < message.data.size(); ++i) {
    f.data[3 + i] = message.data[i];
  }
  return f;
}

std::optional<EmcyFrame> decode_emcy(const CanFrame& frame) noexcept {
  const auto node = node_of(frame, cob::emcy);
  if (!node || frame.len != 8) {
    return std::nullopt;
  }
  EmcyFrame e{};
  e.node = *node;
  e.message.error_code = get_u16(&frame.data[0]);
  e.message.error_register = frame.data[2];
  for (std::size_t i = 0; i < e.message.data.size(); ++i) {
    e.message.data[i] = frame.data[3 + i];
  }
  return e;
}

bool EmcyProducer::emit(const EmcyMessage& message, std::uint64_t now_us, FrameSink& out) noexcept {
  if (last_sent_us_ && now_us - *last_sent_us_ < inhibit_us_) {
    pending_ = message;
    return false;
  }
  pending_.reset();
  last_sent_us_ = now_us;
  return out.put(encode_emcy(node_, message));
}

bool EmcyProducer::poll(std::uint64_t now_us, FrameSink& out) noexcept {
  if (!pending_) {
    return false;
  }
  const EmcyMessage message = *pending_;
  return emit(message, now_us, out);
}

std::optional<EmcyMessage> EmcyConsumer::on_frame(const CanFrame& frame) noexcept {
  const auto e = decode_emcy(frame);
  if (!e || e->node != node_) {
    return std::nullopt;
  }
  last_ = e->message;
  ++count_;
  return e->message;
}

}  // namespace settle::hal::canopen
