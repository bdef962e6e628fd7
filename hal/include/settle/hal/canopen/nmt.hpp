// SPDX-License-Identifier: Apache-2.0
// CiA 301 network management: the NMT command frame (id 0) a master sends, and the slave-side
// state machine that answers it (initialising -> pre-operational <-> operational <-> stopped).
#pragma once

#include <cstdint>
#include <optional>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen {

enum class NmtCommand : std::uint8_t {
  start = 0x01,
  stop = 0x02,
  enter_pre_operational = 0x80,
  reset_node = 0x81,
  reset_communication = 0x82,
};

// The values are the heartbeat encoding of each state.
enum class NmtState : std::uint8_t {
  initialising = 0x00,  // also the boot-up message
  stopped = 0x04,
  operational = 0x05,
  pre_operational = 0x7F,
};

struct NmtMessage {
  NmtCommand command{NmtCommand::start};
  NodeId node{0};  // 0 addresses every node
};

[[nodiscard]] CanFrame encode_nmt(NmtCommand command, NodeId node) noexcept;
// Rejects anything but a two-byte frame on id 0 with a known command and node 0..127.
[[nodiscard]] std::optional<NmtMessage> decode_nmt(const CanFrame& frame) noexcept;
[[nodiscard]] constexpr std::optional<NmtState> nmt_state_from_byte(std::uint8_t value) noexcept {
  const auto state = static_cast<NmtState>(value);
  switch (state) {
    case NmtState::initialising:
    case NmtState::stopped:
    case NmtState::operational:
    case NmtState::pre_operational:
      return state;
  }
  return std::nullopt;
}

// What the owner of an NmtSlave must do after a command.
enum class NmtEvent : std::uint8_t {
  none,                 // not for us, or no change
  state_changed,
  reset_application,    // reset node: restore application objects, then communication
  reset_communication,  // restore communication objects only
};

class NmtSlave {
 public:
  explicit NmtSlave(NodeId node) noexcept : node_{node} {}

  // Power-on or the end of a reset: enters pre-operational and announces it with a boot-up
  // message (the heartbeat with state 0), as CiA 301 requires before any other traffic.
  void boot(FrameSink& out) noexcept;

  // Applies a decoded NMT frame. A reset also re-boots (sends boot-up) after the owner has
  // been told, through the returned event, which objects to restore.
  [[nodiscard]] NmtEvent on_message(const NmtMessage& message, FrameSink& out) noexcept;

  [[nodiscard]] NmtState state() const noexcept { return state_; }
  [[nodiscard]] NodeId node() const noexcept { return node_; }
  // Stopped nodes answer only NMT (and heartbeat); PDOs run only when operational.
  [[nodiscard]] bool sdo_allowed() const noexcept {
    return state_ == NmtState::pre_operational || state_ == NmtState::operational;
  }
  [[nodiscard]] bool pdo_allowed() const noexcept { return state_ == NmtState::operational; }
  [[nodiscard]] bool emcy_allowed() const noexcept { return sdo_allowed(); }

 private:
  NodeId node_;
  NmtState state_{NmtState::initialising};
};

}  // namespace settle::hal::canopen
