// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/nmt.hpp"

#include "settle/hal/canopen/heartbeat.hpp"

namespace settle::hal::canopen {

CanFrame encode_nmt(NmtCommand command, NodeId node) noexcept {
  CanFrame f = classic_frame(cob::nmt, 2);
  f.data[0] = static_cast<std::uint8_t>(command);
  f.data[1] = node;
  return f;
}

std::optional<NmtMessage> decode_nmt(const CanFrame& frame) noexcept {
  if (!is_canopen_data_frame(frame) || frame.id != cob::nmt || frame.len != 2 || frame.data[1] > node_id_max) {
    return std::nullopt;
  }
  const auto cs = static_cast<NmtCommand>(frame.data[0]);
  switch (cs) {
    case NmtCommand::start:
    case NmtCommand::stop:
    case NmtCommand::enter_pre_operational:
    case NmtCommand::reset_node:
    case NmtCommand::reset_communication:
      return NmtMessage{cs, frame.data[1]};
  }
  return std::nullopt;
}

void NmtSlave::boot(FrameSink& out) noexcept {
  state_ = NmtState::pre_operational;
  // A full queue here only delays the master's discovery to the next heartbeat.
  (void)out.put(encode_heartbeat(node_, NmtState::initialising));
}

NmtEvent NmtSlave::on_message(const NmtMessage& message, FrameSink& out) noexcept {
  if (message.node != 0 && message.node != node_) {
    return NmtEvent::none;
  }
  NmtState next = state_;
  switch (message.command) {
    case NmtCommand::start: next = NmtState::operational; break;
    case NmtCommand::stop: next = NmtState::stopped; break;
    case NmtCommand::enter_pre_operational: next = NmtState::pre_operational; break;
    case NmtCommand::reset_node:
      state_ = NmtState::initialising;
      boot(out);
      return NmtEvent::reset_application;
    case NmtCommand::reset_communication:
      state_ = NmtState::initialising;
      boot(out);
      return NmtEvent::reset_communication;
  }
  if (next == state_) {
    return NmtEvent::none;
  }
  state_ = next;
  return NmtEvent::state_changed;
}

}  // namespace settle::hal::canopen
