// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/heartbeat.hpp"

namespace settle::hal::canopen {

CanFrame encode_heartbeat(NodeId node, NmtState state) noexcept {
  CanFrame f{};
  f.id = cob_id(cob::heartbeat, node);
  f.len = 1;
  f.data[0] = static_cast<std::uint8_t>(state);
  return f;
}

std::optional<HeartbeatMessage> decode_heartbeat(const CanFrame& frame) noexcept {
  const auto node = node_of(frame, cob::heartbeat);
  if (!node || frame.len != 1) {
    return std::nullopt;
  }
  const auto state = nmt_state_from_byte(frame.data[0]);
  if (!state) {
    return std::nullopt;
  }
  return HeartbeatMessage{*node, *state};
}

bool HeartbeatProducer::poll(std::uint64_t now_us, NmtState state, FrameSink& out) noexcept {
  if (period_ms_ == 0 || now_us < next_due_us_) {
    return false;
  }
  const std::uint64_t period_us = std::uint64_t{period_ms_} * 1000U;
  // Late calls do not catch up: a heartbeat is a statement about now, not a count.
  next_due_us_ = now_us - (now_us - next_due_us_) % period_us + period_us;
  return out.put(encode_heartbeat(node_, state));
}

HeartbeatConsumer::HeartbeatConsumer(NodeId watched, std::uint16_t timeout_ms) noexcept
    : node_{watched}, timeout_us_{std::uint32_t{timeout_ms} * 1000U} {}

void HeartbeatConsumer::configure(NodeId watched, std::uint16_t timeout_ms) noexcept {
  node_ = watched;
  timeout_us_ = std::uint32_t{timeout_ms} * 1000U;
  watchdog_.disarm();
  seen_ = false;
}

HeartbeatEvent HeartbeatConsumer::on_frame(const CanFrame& frame, std::uint64_t now_us) noexcept {
  const auto hb = decode_heartbeat(frame);
  if (!hb || hb->node != node_ || !is_valid_node(node_)) {
    return HeartbeatEvent::none;
  }
  return on_state(hb->state, now_us);
}

HeartbeatEvent HeartbeatConsumer::poll(std::uint64_t now_us) noexcept {
  return watchdog_.check(now_us) ? HeartbeatEvent::lost : HeartbeatEvent::none;
}

}  // namespace settle::hal::canopen
