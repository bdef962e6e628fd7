// SPDX-License-Identifier: Apache-2.0
// CiA 301 heartbeat: each node announces its NMT state every producer period (0x1017, ms);
// a consumer (0x1016) declares the node lost when no heartbeat came within its timeout.
#pragma once

#include <cstdint>
#include <optional>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/watchdog.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen {

struct HeartbeatMessage {
  NodeId node{0};
  NmtState state{NmtState::initialising};
};

[[nodiscard]] CanFrame encode_heartbeat(NodeId node, NmtState state) noexcept;
// One byte, a known state, toggle bit clear (a set toggle bit is node guarding, not heartbeat).
[[nodiscard]] std::optional<HeartbeatMessage> decode_heartbeat(const CanFrame& frame) noexcept;

class HeartbeatProducer {
 public:
  HeartbeatProducer(NodeId node, std::uint16_t period_ms) noexcept : node_{node}, period_ms_{period_ms} {}

  // Sends when a period has passed since the last heartbeat (period 0: never).
  [[nodiscard]] bool poll(std::uint64_t now_us, NmtState state, FrameSink& out) noexcept;
  // The first heartbeat is due at first_due_us (after a boot-up message: one period later).
  void start(std::uint64_t first_due_us) noexcept { next_due_us_ = first_due_us; }
  void set_period_ms(std::uint16_t period_ms) noexcept { period_ms_ = period_ms; }
  [[nodiscard]] std::uint16_t period_ms() const noexcept { return period_ms_; }

 private:
  NodeId node_;
  std::uint16_t period_ms_;
  std::uint64_t next_due_us_{0};
};

enum class HeartbeatEvent : std::uint8_t {
  none,
  alive,          // first heartbeat, or the first after a loss
  boot_up,        // the node (re)started: whatever was configured on it is gone
  state_changed,  // the NMT state differs from the previous heartbeat
  lost,           // no heartbeat within the timeout (reported once per loss)
};

class HeartbeatConsumer {
 public:
  // Monitoring starts with the first heartbeat received, as CiA 301 specifies.
  HeartbeatConsumer(NodeId watched, std::uint16_t timeout_ms) noexcept;

  // Frames from other nodes or of other kinds return none and change nothing.
  [[nodiscard]] HeartbeatEvent on_frame(const CanFrame& frame, std::uint64_t now_us) noexcept;
  // The same for the state a frame carried that the caller has already matched to the watched
  // node's heartbeat (its identifier, one byte, a classic data frame, a known state).
  // Inline: RemoteDrive runs it for every heartbeat of its drive, in a servo tick.
  [[nodiscard]] HeartbeatEvent on_state(NmtState state, std::uint64_t now_us) noexcept {
    const bool was_lost = watchdog_.expired();
    const bool first = !seen_;
    const NmtState previous = state_;
    seen_ = true;
    state_ = state;
    if (first) {
      watchdog_.arm(timeout_us_, now_us);
    } else {
      watchdog_.feed(now_us);
    }
    if (state == NmtState::initialising) {
      return HeartbeatEvent::boot_up;
    }
    if (first || was_lost) {
      return HeartbeatEvent::alive;
    }
    return previous != state ? HeartbeatEvent::state_changed : HeartbeatEvent::none;
  }
  [[nodiscard]] HeartbeatEvent poll(std::uint64_t now_us) noexcept;
  void configure(NodeId watched, std::uint16_t timeout_ms) noexcept;

  [[nodiscard]] NodeId watched() const noexcept { return node_; }
  [[nodiscard]] bool alive() const noexcept { return seen_ && !watchdog_.expired(); }
  [[nodiscard]] std::optional<NmtState> state() const noexcept {
    return seen_ ? std::optional<NmtState>{state_} : std::nullopt;
  }

 private:
  NodeId node_;
  // 0x1016's timeout in microseconds, converted when configured (at most 65 535 000: 32 bits), not
  // multiplied out in the tick that takes the first heartbeat (a 64-bit multiply on a Cortex-M0).
  std::uint32_t timeout_us_;
  Watchdog watchdog_{};
  NmtState state_{NmtState::initialising};
  bool seen_{false};
};

}  // namespace settle::hal::canopen
