// SPDX-License-Identifier: Apache-2.0
// In-process CAN bus: every port attached to a hub receives what the other ports send, in
// order, with the hub's virtual time as receive timestamp. Deterministic (no threads, no
// clock), so unit tests, benchmarks and hosts without any CAN all run the same protocol code.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "settle/hal/can_bus.hpp"
#include "settle/hal/ring.hpp"

namespace settle::hal {

class LoopbackPort;

class LoopbackHub {
 public:
  LoopbackHub() = default;
  LoopbackHub(const LoopbackHub&) = delete;
  LoopbackHub& operator=(const LoopbackHub&) = delete;

  // The timestamp given to frames delivered from now on; tests advance it to model time.
  void set_time_us(std::uint64_t now_us) noexcept { now_us_ = now_us; }
  [[nodiscard]] std::uint64_t time_us() const noexcept { return now_us_; }

 private:
  friend class LoopbackPort;
  void attach(LoopbackPort& port) noexcept;
  void detach(LoopbackPort& port) noexcept;
  void deliver(const LoopbackPort& from, const CanFrame& frame) noexcept;

  LoopbackPort* first_{nullptr};
  std::uint64_t now_us_{0};
};

struct LoopbackOptions {
  // Like CAN_RAW_RECV_OWN_MSGS: off by default, a node does not hear itself.
  bool receive_own{false};
};

// One node's connection to the hub. Its receive queue lives in storage the owner provides;
// when that queue is full the frame is dropped for this port only and counted as an overflow.
//
// The virtual overrides are defined here, inline, on purpose: a class whose key function sat
// in the -fno-rtti library would have no typeinfo, and code built with RTTI (tests, host
// tools) that derives from it, as LoopbackBus<N> does, would then fail to link.
class LoopbackPort : public CanBus {
 public:
  LoopbackPort(LoopbackHub& hub, std::span<CanFrame> rx_storage, LoopbackOptions options = {}) noexcept
      : hub_{hub}, rx_{rx_storage}, options_{options} {
    hub_.attach(*this);
  }
  LoopbackPort(const LoopbackPort&) = delete;
  LoopbackPort& operator=(const LoopbackPort&) = delete;
  ~LoopbackPort() override { hub_.detach(*this); }

  [[nodiscard]] std::size_t pending() const noexcept { return rx_.size(); }

 private:
  friend class LoopbackHub;
  void accept(const CanFrame& frame, std::uint64_t now_us) noexcept;

  [[nodiscard]] SendStatus do_send(const CanFrame& frame) noexcept override {
    hub_.deliver(*this, frame);
    return SendStatus::sent;
  }
  [[nodiscard]] ReceiveStatus do_receive(CanFrame& frame, std::uint32_t /*timeout_us*/) noexcept override {
    return rx_.pop(frame) ? ReceiveStatus::received : ReceiveStatus::empty;
  }
  [[nodiscard]] BusStatus do_set_filters(std::span<const CanFilter> filters) noexcept override {
    return filters_.assign(filters);
  }

  LoopbackHub& hub_;
  LoopbackPort* next_{nullptr};
  Ring<CanFrame> rx_;
  FilterSet filters_{};
  LoopbackOptions options_{};
};

namespace detail {
// Base-from-member: the queue storage must exist before LoopbackPort is given a span of it.
template <std::size_t N>
struct LoopbackStorage {
  std::array<CanFrame, N> rx_storage{};
};
}  // namespace detail

// A port that carries its own receive queue of RxCapacity frames.
template <std::size_t RxCapacity = 64>
class LoopbackBus final : private detail::LoopbackStorage<RxCapacity>, public LoopbackPort {
 public:
  explicit LoopbackBus(LoopbackHub& hub, LoopbackOptions options = {}) noexcept
      : LoopbackPort{hub, this->rx_storage, options} {}
};

}  // namespace settle::hal
