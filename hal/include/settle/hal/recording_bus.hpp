// SPDX-License-Identifier: Apache-2.0
// A CAN bus that records every frame passing through it, both ways: each frame the bus behind it
// took for sending and each frame it delivered, in the order this process saw them. The records
// wait in a fixed ring until the owner takes them (to write a candump log, say) outside its timed
// work; a record that finds the ring full is counted, never dropped silently. So a log written
// from the records, with overflows() == 0, holds exactly counters().sent + counters().received
// frames of the bus behind it: a capture that cannot drop a frame unnoticed, unlike a separate
// sniffer socket (candump), whose receive queue can overflow on a loaded host.
//
// Busy and refused sends are not recorded: they never reached the wire. Received frames keep the
// backend's timestamp; sent ones are stamped with the clock given (the backend's time base, so
// both directions share one), or 0 without one.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "settle/hal/can_bus.hpp"
#include "settle/hal/ring.hpp"

namespace settle::hal {

enum class FrameDirection : std::uint8_t { sent, received };

struct RecordedFrame {
  CanFrame frame{};
  FrameDirection direction{FrameDirection::sent};
};

template <std::size_t Capacity>
class RecordingBus final : public CanBus {
 public:
  using Clock = std::uint64_t (*)() noexcept;

  explicit RecordingBus(CanBus& inner, Clock clock = nullptr) noexcept : inner_{inner}, clock_{clock} {}

  // The oldest record not taken yet; false when there is none.
  [[nodiscard]] bool take(RecordedFrame& out) noexcept { return ring_.pop(out); }
  [[nodiscard]] std::size_t pending() const noexcept { return ring_.size(); }
  // Frames that passed (sent or received) and were recorded.
  [[nodiscard]] std::uint64_t recorded() const noexcept { return recorded_; }
  // Frames that passed while the ring was full: passed on, but missing from the records.
  [[nodiscard]] std::uint64_t overflows() const noexcept { return overflows_; }

 private:
  [[nodiscard]] SendStatus do_send(const CanFrame& frame) noexcept override {
    const SendStatus status = inner_.send(frame);
    if (status == SendStatus::sent) {
      record(frame, FrameDirection::sent, clock_ != nullptr ? clock_() : 0);
    }
    return status;
  }
  [[nodiscard]] ReceiveStatus do_receive(CanFrame& frame, std::uint32_t timeout_us) noexcept override {
    const ReceiveStatus status = inner_.receive(frame, timeout_us);
    if (status == ReceiveStatus::received) {
      record(frame, FrameDirection::received, frame.timestamp_us);
    }
    return status;
  }
  [[nodiscard]] BusStatus do_set_filters(std::span<const CanFilter> filters) noexcept override {
    return inner_.set_filters(filters);
  }

  void record(const CanFrame& frame, FrameDirection direction, std::uint64_t timestamp_us) noexcept {
    if (ring_.full()) {
      ++overflows_;
      return;
    }
    RecordedFrame& r = ring_.back_slot();
    r.frame = frame;
    r.frame.timestamp_us = timestamp_us;
    r.direction = direction;
    ring_.commit_back();
    ++recorded_;
  }

  CanBus& inner_;
  Clock clock_;
  std::array<RecordedFrame, Capacity> storage_{};
  Ring<RecordedFrame, Capacity> ring_{std::span<RecordedFrame, Capacity>{storage_}};
  std::uint64_t recorded_{0};
  std::uint64_t overflows_{0};
};

}  // namespace settle::hal
