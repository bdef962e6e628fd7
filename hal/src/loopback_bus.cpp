// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/loopback_bus.hpp"

namespace settle::hal {

void LoopbackHub::attach(LoopbackPort& port) noexcept {
  // Appended at the end so delivery order follows attach order, which keeps tests stable.
  LoopbackPort** link = &first_;
  while (*link != nullptr) {
    link = &(*link)->next_;
  }
  *link = &port;
  port.next_ = nullptr;
}

void LoopbackHub::detach(LoopbackPort& port) noexcept {
  for (LoopbackPort** link = &first_; *link != nullptr; link = &(*link)->next_) {
    if (*link == &port) {
      *link = port.next_;
      port.next_ = nullptr;
      return;
    }
  }
}

void LoopbackHub::deliver(const LoopbackPort& from, const CanFrame& frame) noexcept {
  for (LoopbackPort* port = first_; port != nullptr; port = port->next_) {
    if (port != &from || port->options_.receive_own) {
      port->accept(frame, now_us_);
    }
  }
}

void LoopbackPort::accept(const CanFrame& frame, std::uint64_t now_us) noexcept {
  if (!filters_.accepts(frame)) {
    return;
  }
  if (rx_.full()) {
    count_rx_overflow(1);
    return;
  }
  // Stamped in its slot: one copy per delivered frame.
  CanFrame& slot = rx_.back_slot();
  slot = frame;
  slot.timestamp_us = now_us;
  rx_.commit_back();
}

}  // namespace settle::hal
