// SPDX-License-Identifier: Apache-2.0
// CiA 301 emergency messages: a node reports an error (or its end, code 0) once, with its
// error register and five bytes of detail; the producer honours the inhibit time (0x1015).
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen {

// Error codes used by Settle's nodes (CiA 301 table 21 and CiA 402).
namespace emcy_code {
inline constexpr std::uint16_t no_error = 0x0000;        // error reset
inline constexpr std::uint16_t generic = 0x1000;
inline constexpr std::uint16_t communication = 0x8100;   // SYNC loss, SYNC counter/rate, NMT abort
inline constexpr std::uint16_t can_overrun = 0x8110;
inline constexpr std::uint16_t life_guard = 0x8130;      // heartbeat of the master lost
inline constexpr std::uint16_t pdo_length = 0x8210;      // RPDO shorter than its mapping
inline constexpr std::uint16_t pdo_length_exceeded = 0x8220;
inline constexpr std::uint16_t sync_data_length = 0x8240;  // SYNC without the counter 0x1019 asks for
inline constexpr std::uint16_t rpdo_timeout = 0x8250;
inline constexpr std::uint16_t velocity = 0x8400;        // CiA 402 "velocity speed controller": setpoint over 0x607F
inline constexpr std::uint16_t following_error = 0x8611;
inline constexpr std::uint16_t reference_limit = 0x8612;  // software position limit hit
}  // namespace emcy_code

// Bits of the error register (0x1001).
namespace error_register {
inline constexpr std::uint8_t generic = 0x01;
inline constexpr std::uint8_t current = 0x02;
inline constexpr std::uint8_t voltage = 0x04;
inline constexpr std::uint8_t temperature = 0x08;
inline constexpr std::uint8_t communication = 0x10;
inline constexpr std::uint8_t device_profile = 0x20;
inline constexpr std::uint8_t manufacturer = 0x80;
}  // namespace error_register

struct EmcyMessage {
  std::uint16_t error_code{0};
  std::uint8_t error_register{0};
  std::array<std::uint8_t, 5> data{};
  friend constexpr bool operator==(const EmcyMessage&, const EmcyMessage&) = default;
};

struct EmcyFrame {
  NodeId node{0};
  EmcyMessage message{};
};

[[nodiscard]] CanFrame encode_emcy(NodeId node, const EmcyMessage& message) noexcept;
// Exactly eight bytes on 0x81..0xFF (0x80 itself is SYNC).
[[nodiscard]] std::optional<EmcyFrame> decode_emcy(const CanFrame& frame) noexcept;

class EmcyProducer {
 public:
  EmcyProducer(NodeId node, std::uint32_t inhibit_us = 0) noexcept : node_{node}, inhibit_us_{inhibit_us} {}

  // Sends now unless an EMCY left less than the inhibit time ago; then the message waits
  // (the newest replaces an older waiting one: the latest state of the node is what matters)
  // and poll() sends it when the inhibit time is over.
  [[nodiscard]] bool emit(const EmcyMessage& message, std::uint64_t now_us, FrameSink& out) noexcept;
  [[nodiscard]] bool poll(std::uint64_t now_us, FrameSink& out) noexcept;
  void set_inhibit_us(std::uint32_t inhibit_us) noexcept { inhibit_us_ = inhibit_us; }
  [[nodiscard]] bool pending() const noexcept { return pending_.has_value(); }

 private:
  NodeId node_;
  std::uint32_t inhibit_us_;
  std::optional<std::uint64_t> last_sent_us_{};
  std::optional<EmcyMessage> pending_{};
};

class EmcyConsumer {
 public:
  explicit EmcyConsumer(NodeId watched) noexcept : node_{watched} {}

  // The message when the frame is an EMCY from the watched node.
  [[nodiscard]] std::optional<EmcyMessage> on_frame(const CanFrame& frame) noexcept;

  // The node is in error from a non-zero EMCY until it sends the error reset (code 0).
  [[nodiscard]] bool in_error() const noexcept { return last_.error_code != emcy_code::no_error; }
  [[nodiscard]] const EmcyMessage& last() const noexcept { return last_; }
  [[nodiscard]] std::uint32_t count() const noexcept { return count_; }

 private:
  NodeId node_;
  EmcyMessage last_{};
  std::uint32_t count_{0};
};

}  // namespace settle::hal::canopen
