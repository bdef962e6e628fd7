// SPDX-License-Identifier: Apache-2.0
#pragma once
// A CAN bus that writes every frame it sends as a candump line (`candump -L` / canplayer format)
// to a line sink, then passes the frame on to the bus behind it. This is how an image with no
// CAN controller makes its traffic visible: the sink is semihosting on a Cortex-M image and a
// stdio file on the host, and both format through hal's format_candump_line, so their logs can be
// compared byte for byte. Only sent frames are logged (busy and refused ones never reached a
// wire); received frames are not logged: the tap sits on one node's transmit path.
// Sending only copies the frame (as a CAN controller's mailbox write would); formatting and the
// sink's I/O happen in flush(), which the runner calls outside the timed servo tick.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "settle/hal/can_bus.hpp"
#include "settle/hal/candump_log.hpp"

namespace settle::firmware {

// LineSink: `void line(std::string_view text)` (the text includes the trailing newline).
template <typename LineSink>
class CandumpTapBus final : public hal::CanBus {
 public:
  CandumpTapBus(hal::CanBus& inner, LineSink& sink, const char* iface) noexcept
      : inner_{inner}, sink_{sink}, iface_{iface} {}

  // The time stamped on the frames logged from now on (the runner's clock, in µs).
  void set_time_us(std::uint64_t now_us) noexcept { now_us_ = now_us; }
  // Frames that could not be formatted (invalid, or the line did not fit).
  [[nodiscard]] std::uint64_t format_errors() const noexcept { return format_errors_; }
  // Times the pending list filled up and was flushed inside send().
  [[nodiscard]] std::uint64_t early_flushes() const noexcept { return early_flushes_; }

  // Writes every pending frame to the sink, in the order sent.
  void flush() noexcept {
    for (std::size_t i = 0; i < pending_count_; ++i) {
      const std::size_t n =
          hal::format_candump_line(pending_[i], iface_, std::span<char>{buf_.data(), buf_.size() - 1});
      if (n == 0) {
        ++format_errors_;
        continue;
      }
      buf_[n] = '\n';
      sink_.line(std::string_view{buf_.data(), n + 1});
    }
    pending_count_ = 0;
  }

 private:
  [[nodiscard]] hal::SendStatus do_send(const hal::CanFrame& frame) noexcept override {
    const hal::SendStatus st = inner_.send(frame);
    if (st != hal::SendStatus::sent) return st;
    if (pending_count_ == pending_.size()) {
      ++early_flushes_;
      flush();
    }
    hal::CanFrame& stamped = pending_[pending_count_++];
    stamped = frame;
    stamped.timestamp_us = now_us_;
    return st;
  }
  [[nodiscard]] hal::ReceiveStatus do_receive(hal::CanFrame& frame, std::uint32_t timeout_us) noexcept override {
    return inner_.receive(frame, timeout_us);
  }
  [[nodiscard]] hal::BusStatus do_set_filters(std::span<const hal::CanFilter> filters) noexcept override {
    return inner_.set_filters(filters);
  }

  hal::CanBus& inner_;
  LineSink& sink_;
  const char* iface_;
  std::uint64_t now_us_{0};
  std::uint64_t format_errors_{0};
  std::uint64_t early_flushes_{0};
  std::array<hal::CanFrame, 4> pending_{};
  std::size_t pending_count_{0};
  std::array<char, hal::candump_line_max + 1> buf_{};
};

}  // namespace settle::firmware
