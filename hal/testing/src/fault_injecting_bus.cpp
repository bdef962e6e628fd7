// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/testing/fault_injecting_bus.hpp"

namespace settle::hal::testing {

FaultInjectingBus::FaultInjectingBus(CanBus& inner) noexcept : inner_{inner} {}

void FaultInjectingBus::fail_sends(std::uint32_t count, SendStatus status) noexcept {
  fail_count_ = count;
  fail_status_ = status;
}

void FaultInjectingBus::drop_sends(std::uint32_t count) noexcept { drop_tx_count_ = count; }

void FaultInjectingBus::drop_receives(std::uint32_t count) noexcept { drop_rx_count_ = count; }

void FaultInjectingBus::set_random(std::uint32_t seed, const FaultRates& rates) noexcept {
  rates_ = rates;
  rng_ = seed == 0 ? 0x9E37'79B9U : seed;  // xorshift must not start at zero
}

void FaultInjectingBus::clear_faults() noexcept {
  fail_count_ = 0;
  drop_tx_count_ = 0;
  drop_rx_count_ = 0;
  tx_delay_us_ = 0;
  rx_delay_us_ = 0;
  rates_ = FaultRates{};
  target_.reset();
}

bool FaultInjectingBus::targeted(const CanFrame& frame) const noexcept {
  return !target_ || matches(*target_, frame);
}

bool FaultInjectingBus::chance(std::uint32_t ppm) noexcept {
  if (ppm == 0) {
    return false;
  }
  rng_ ^= rng_ << 13U;
  rng_ ^= rng_ >> 17U;
  rng_ ^= rng_ << 5U;
  return rng_ % 1'000'000U < ppm;
}

bool FaultInjectingBus::HoldQueue::pop_due(std::uint64_t now_us, CanFrame& out) noexcept {
  if (ring_.empty() || ring_.front().due_us > now_us) {
    return false;
  }
  out = ring_.front().frame;
  ring_.drop_front();
  return true;
}

void FaultInjectingBus::set_time_us(std::uint64_t now_us) noexcept {
  now_us_ = now_us;
  CanFrame frame{};
  while (tx_hold_.pop_due(now_us_, frame)) {
    // A busy backend now loses the delayed frame; the double reports it as a drop.
    if (inner_.send(frame) != SendStatus::sent) {
      ++stats_.tx_dropped;
    }
  }
}

SendStatus FaultInjectingBus::do_send(const CanFrame& frame) noexcept {
  if (bus_state() == BusState::bus_off) {
    ++stats_.tx_errors;
    return SendStatus::error;  // a controller off the bus sends nothing
  }
  if (targeted(frame)) {
    if (fail_count_ > 0) {
      --fail_count_;
      ++(fail_status_ == SendStatus::error ? stats_.tx_errors : stats_.tx_busy);
      return fail_status_;
    }
    if (chance(rates_.tx_busy_ppm)) {
      ++stats_.tx_busy;
      return SendStatus::busy;
    }
    if (chance(rates_.tx_error_ppm)) {
      ++stats_.tx_errors;
      return SendStatus::error;
    }
    if (drop_tx_count_ > 0 || chance(rates_.tx_drop_ppm)) {
      if (drop_tx_count_ > 0) {
        --drop_tx_count_;
      }
      ++stats_.tx_dropped;
      return SendStatus::sent;
    }
    if (tx_delay_us_ > 0) {
      ++stats_.delayed;
      if (!tx_hold_.push(frame, now_us_ + tx_delay_us_)) {
        return SendStatus::busy;  // the hold queue is this double's transmit queue
      }
      return SendStatus::sent;
    }
  }
  return inner_.send(frame);
}

ReceiveStatus FaultInjectingBus::do_receive(CanFrame& frame, std::uint32_t timeout_us) noexcept {
  for (;;) {
    if (rx_hold_.pop_due(now_us_, frame)) {
      return ReceiveStatus::received;
    }
    // Held frames must keep their order, so nothing overtakes a frame still waiting.
    const bool queue_waiting = rx_hold_.size() > 0;
    const ReceiveStatus status = inner_.receive(frame, queue_waiting ? 0 : timeout_us);
    if (status != ReceiveStatus::received) {
      return status;
    }
    if (bus_state() == BusState::bus_off) {
      ++stats_.bus_off_rx_lost;  // off the bus: the controller never saw it
      continue;
    }
    if (targeted(frame) && (drop_rx_count_ > 0 || chance(rates_.rx_drop_ppm))) {
      if (drop_rx_count_ > 0) {
        --drop_rx_count_;
      }
      ++stats_.rx_dropped;
      continue;
    }
    if ((targeted(frame) && rx_delay_us_ > 0) || queue_waiting) {
      ++stats_.delayed;
      if (!rx_hold_.push(frame, now_us_ + (targeted(frame) ? rx_delay_us_ : 0))) {
        count_rx_overflow(1);
      }
      continue;
    }
    return ReceiveStatus::received;
  }
}

BusStatus FaultInjectingBus::do_restart() noexcept {
  if (restart_answer_ == BusStatus::ok && restart_completes_ && bus_state() == BusState::bus_off) {
    set_bus_state(BusState::error_active);
  }
  return restart_answer_;
}

BusStatus FaultInjectingBus::do_set_filters(std::span<const CanFilter> filters) noexcept {
  return inner_.set_filters(filters);
}

}  // namespace settle::hal::testing
