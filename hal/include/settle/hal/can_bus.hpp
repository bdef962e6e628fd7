// SPDX-License-Identifier: Apache-2.0
// The bus interface the servo loop and the protocol nodes use: non-blocking send with a
// status, receive with an optional timeout, receive filters and counters. Nothing here
// allocates; every backend (SocketCAN, loopback, the fault-injecting double) implements it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal {

enum class SendStatus : std::uint8_t {
  sent,   // handed to the backend's transmit path
  busy,   // the backend had no room now (kernel queue full, injected); the frame was NOT queued
  error,  // invalid frame, FD frame on a classic bus, bus down, ...
};

enum class ReceiveStatus : std::uint8_t {
  received,  // a frame was written to the caller's frame
  empty,     // nothing arrived within the timeout
  error,     // the backend failed; see its own diagnostics
};

enum class BusStatus : std::uint8_t {
  ok,
  too_many_filters,
  not_supported,
  error,
};

// The controller's fault-confinement state (ISO 11898-1), as the backend last learnt it: from
// the controller's error frames or its driver. A backend without a controller stays error_active.
enum class BusState : std::uint8_t {
  error_active,   // normal
  error_warning,  // an error counter reached 96: still sending and receiving
  error_passive,  // an error counter reached 128: still sending, may no longer flag errors
  bus_off,        // the transmit error counter passed 255: the controller is off the bus
};

[[nodiscard]] constexpr const char* to_string(BusState s) noexcept {
  switch (s) {
    case BusState::error_active: return "error_active";
    case BusState::error_warning: return "error_warning";
    case BusState::error_passive: return "error_passive";
    case BusState::bus_off: return "bus_off";
  }
  return "?";
}

enum class FrameFormat : std::uint8_t { any, standard, extended };

// Accepts a frame when (frame.id & mask) == (id & mask) and the format matches.
// Same meaning as a SocketCAN can_filter, without the kernel's flag bits in the id.
struct CanFilter {
  std::uint32_t id{0};
  std::uint32_t mask{0};
  FrameFormat format{FrameFormat::any};
};

[[nodiscard]] constexpr bool matches(const CanFilter& filter, const CanFrame& frame) noexcept {
  if (filter.format == FrameFormat::standard && frame.is_extended()) {
    return false;
  }
  if (filter.format == FrameFormat::extended && !frame.is_extended()) {
    return false;
  }
  return ((frame.id ^ filter.id) & filter.mask) == 0;
}

inline constexpr std::size_t max_can_filters = 16;

// The filters of one receiver. No filters means "accept everything": a freshly opened bus
// receives all traffic, as a SocketCAN raw socket does.
class FilterSet {
 public:
  [[nodiscard]] BusStatus assign(std::span<const CanFilter> filters) noexcept {
    if (filters.size() > max_can_filters) {
      return BusStatus::too_many_filters;
    }
    count_ = filters.size();
    for (std::size_t i = 0; i < count_; ++i) {
      filters_[i] = filters[i];
    }
    return BusStatus::ok;
  }

  [[nodiscard]] bool accepts(const CanFrame& frame) const noexcept {
    if (count_ == 0) {
      return true;
    }
    for (std::size_t i = 0; i < count_; ++i) {
      if (matches(filters_[i], frame)) {
        return true;
      }
    }
    return false;
  }

  [[nodiscard]] std::span<const CanFilter> filters() const noexcept { return {filters_.data(), count_}; }

 private:
  std::array<CanFilter, max_can_filters> filters_{};
  std::size_t count_{0};
};

struct BusCounters {
  std::uint64_t sent{0};
  std::uint64_t received{0};
  std::uint64_t tx_busy{0};
  std::uint64_t tx_errors{0};
  std::uint64_t rx_overflow_drops{0};  // frames lost because a receive queue was full
  std::uint64_t rx_errors{0};
  std::uint64_t error_frames{0};       // controller error reports taken (never returned as frames)
  std::uint64_t bus_off_events{0};     // entries into bus-off
  std::uint64_t restart_requests{0};   // restart() calls
};

// Public calls are non-virtual so that every backend counts the same way; a backend only
// implements the do_* hooks and reports the drops only it can see (count_rx_overflow).
// One bus object belongs to one thread.
class CanBus : public FrameSink {
 public:
  [[nodiscard]] SendStatus send(const CanFrame& frame) noexcept {
    return counted_send(frame, [this](const CanFrame& f) { return do_send(f); });
  }

  // timeout_us == 0 polls. A backend without a clock (loopback) never waits: time in a
  // deterministic test moves only when the test moves it.
  [[nodiscard]] ReceiveStatus receive(CanFrame& frame, std::uint32_t timeout_us = 0) noexcept {
    return counted_receive(frame, timeout_us,
                           [this](CanFrame& f, std::uint32_t t) { return do_receive(f, t); });
  }

  // Replaces the receive filters; an empty span accepts every frame again.
  [[nodiscard]] BusStatus set_filters(std::span<const CanFilter> filters) noexcept {
    return do_set_filters(filters);
  }

  [[nodiscard]] const BusCounters& counters() const noexcept { return counters_; }

  // The controller's error state. Read every tick by the servo loop: a plain member, no call.
  [[nodiscard]] BusState bus_state() const noexcept { return bus_state_; }
  // Asks the controller to leave bus-off (CAN restart). not_supported: this backend cannot (a
  // virtual interface, a controller that restarts by itself or not at all); bus_state() says
  // when the controller is back. ok: requested; bus_state() changes when the controller is back.
  [[nodiscard]] BusStatus restart() noexcept {
    ++counters_.restart_requests;
    return do_restart();
  }

  // As a FrameSink a bus takes a frame when it was sent; busy and errors are counted above.
  [[nodiscard]] bool put(const CanFrame& frame) noexcept final { return send(frame) == SendStatus::sent; }

 protected:
  CanBus() = default;
  CanBus(const CanBus&) = delete;
  CanBus& operator=(const CanBus&) = delete;
  ~CanBus() override = default;

  void count_rx_overflow(std::uint64_t dropped) noexcept { counters_.rx_overflow_drops += dropped; }
  // Frames a backend's caller took other than through receive() (MailboxBus::consume_received).
  void count_received(std::uint64_t frames) noexcept { counters_.received += frames; }
  // A backend reports what its controller said (an error frame, the driver's state).
  void count_error_frame() noexcept { ++counters_.error_frames; }
  void set_bus_state(BusState state) noexcept {
    if (state == BusState::bus_off && bus_state_ != BusState::bus_off) ++counters_.bus_off_events;
    bus_state_ = state;
  }

  // send() and receive() around a given hook: the validation and counting every path shares. A
  // `final` backend uses them to offer the same two calls bound at compile time (its own hook,
  // called directly and inlinable) to code that holds it by its own type; see MailboxBus.
  template <typename SendHook>
  [[nodiscard, gnu::always_inline]] SendStatus counted_send(const CanFrame& frame, SendHook&& hook) noexcept {
    const SendStatus status = is_valid(frame) ? hook(frame) : SendStatus::error;
    switch (status) {
      case SendStatus::sent: ++counters_.sent; break;
      case SendStatus::busy: ++counters_.tx_busy; break;
      case SendStatus::error: ++counters_.tx_errors; break;
    }
    return status;
  }
  template <typename ReceiveHook>
  [[nodiscard, gnu::always_inline]] ReceiveStatus counted_receive(CanFrame& frame, std::uint32_t timeout_us, ReceiveHook&& hook) noexcept {
    const ReceiveStatus status = hook(frame, timeout_us);
    if (status == ReceiveStatus::received) {
      ++counters_.received;
    } else if (status == ReceiveStatus::error) {
      ++counters_.rx_errors;
    }
    return status;
  }

 private:
  [[nodiscard]] virtual SendStatus do_send(const CanFrame& frame) noexcept = 0;
  [[nodiscard]] virtual ReceiveStatus do_receive(CanFrame& frame, std::uint32_t timeout_us) noexcept = 0;
  [[nodiscard]] virtual BusStatus do_set_filters(std::span<const CanFilter> filters) noexcept = 0;
  [[nodiscard]] virtual BusStatus do_restart() noexcept { return BusStatus::not_supported; }

  BusCounters counters_{};
  BusState bus_state_{BusState::error_active};
};

}  // namespace settle::hal
