// SPDX-License-Identifier: Apache-2.0
// A CAN controller's own buffers as the firmware of a drive master sees them: a few transmit
// mailboxes and a receive FIFO, each entry a 16-byte classic-frame record (identifier, flags,
// length, eight data bytes), as bxCAN, FlexCAN or an MCP2515 hold them. This is the bus the
// servo loop has on a microcontroller: sending a frame writes one record, receiving reads one,
// and neither ever touches a 64-byte FD buffer.
//
// The wire side belongs to whoever moves frames between the controller and the bus: on a target
// the transmit-complete and receive interrupts, in a simulation or a test the harness, through
// take_sent() and put_received(). Mailboxes leave in the order they were filled (bxCAN's TXFP
// FIFO mode). A classic controller refuses FD frames (error). All mailboxes pending -> busy, the
// frame is not queued; FIFO full -> the arriving frame is dropped and counted as an overrun;
// the receive filters act as the controller's acceptance filters.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "settle/hal/can_bus.hpp"
#include "settle/hal/ring.hpp"

namespace settle::hal {

template <std::size_t TxMailboxes = 3, std::size_t RxFifoDepth = 16>
class MailboxBus final : public CanBus {
  static_assert(TxMailboxes > 0 && RxFifoDepth > 0);

 public:
  // One mailbox or FIFO entry: a classic frame's identifier, flags, length and eight data bytes
  // (word-aligned), read where it is by received().
  struct Record {
    std::uint32_t id{0};
    std::uint8_t flags{0};
    std::uint8_t len{0};
    alignas(4) std::array<std::uint8_t, can_classic_max_len> data{};

    [[nodiscard]] constexpr bool is_extended() const noexcept { return (flags & can_flag::extended) != 0; }
  };

  MailboxBus() noexcept = default;
  MailboxBus(const MailboxBus&) = delete;
  MailboxBus& operator=(const MailboxBus&) = delete;
  ~MailboxBus() override = default;

  // CanBus's send() and receive(), the same validation and counting, for code that holds this bus
  // by its own type (the servo loop of firmware that knows its controller): the hooks below are
  // then called directly, no virtual dispatch, and inline into the caller. Through a CanBus& the
  // base's calls run, with the same result.
  [[nodiscard]] SendStatus send(const CanFrame& frame) noexcept {
    return counted_send(frame, [this](const CanFrame& f) { return send_record(f); });
  }
  [[nodiscard]] ReceiveStatus receive(CanFrame& frame, std::uint32_t timeout_us = 0) noexcept {
    return counted_receive(frame, timeout_us, [this](CanFrame& f, std::uint32_t) { return receive_record(f); });
  }

  // Wire side: the oldest pending mailbox, which is then free again; false when none is pending.
  [[nodiscard]] bool take_sent(CanFrame& out) noexcept {
    if (tx_.empty()) {
      return false;
    }
    unpack(tx_.front(), out);
    out.timestamp_us = 0;
    tx_.drop_front();
    return true;
  }
  // Wire side: a frame arrived. False when the filters reject it or it cannot be held (an FD
  // frame; a full FIFO, counted as an rx overflow).
  [[nodiscard]] bool put_received(const CanFrame& frame) noexcept {
    if (frame.is_fd() || !is_valid(frame) || !filters_.accepts(frame)) {
      return false;
    }
    if (rx_.full()) {
      count_rx_overflow(1);
      return false;
    }
    Received& r = rx_.back_slot();
    pack(frame, r.record);
    r.timestamp_us = frame.timestamp_us;
    rx_.commit_back();
    return true;
  }

  // Received frames read in place, where the controller holds them, for a caller that decides on a
  // record's identifier, length and data before anything is copied (the servo loop takes its
  // drives' process data and heartbeats so: firmware/README.md). received(i) is the i-th oldest
  // (i < pending_rx()); received_frame(i, f) copies it out as receive() would; consume_received(n)
  // drops the n oldest (n <= pending_rx()) and counts them as n calls of receive() would.
  [[nodiscard]] const Record& received(std::size_t i) const noexcept { return rx_.at(i).record; }
  void received_frame(std::size_t i, CanFrame& frame) const noexcept {
    const Received& r = rx_.at(i);
    unpack(r.record, frame);
    frame.timestamp_us = r.timestamp_us;
  }
  void consume_received(std::size_t n) noexcept {
    rx_.drop_front(n);
    count_received(n);
  }

  [[nodiscard]] std::size_t pending_tx() const noexcept { return tx_.size(); }
  [[nodiscard]] std::size_t pending_rx() const noexcept { return rx_.size(); }

 private:
  struct Received {
    Record record{};
    std::uint64_t timestamp_us{0};
  };

  template <typename T>
  [[nodiscard]] static T* aligned(T* p) noexcept {
    return static_cast<T*>(__builtin_assume_aligned(p, 4));
  }
  static void pack(const CanFrame& f, Record& r) noexcept {
    r.id = f.id;
    r.flags = f.flags;
    r.len = f.len;
    // Two aligned words (CanFrame::data is word-aligned); said so, GCC copies them inline even on
    // a Cortex-M0, where it would otherwise call a byte-wise memcpy.
    std::memcpy(aligned(r.data.data()), aligned(f.data.data()), can_classic_max_len);
  }
  static void unpack(const Record& r, CanFrame& f) noexcept {
    f.id = r.id;
    f.flags = r.flags;
    f.len = r.len;
    std::memcpy(aligned(f.data.data()), aligned(r.data.data()), can_classic_max_len);
  }

  [[nodiscard]] SendStatus send_record(const CanFrame& frame) noexcept {
    if (frame.is_fd()) {
      return SendStatus::error;
    }
    if (tx_.full()) {
      return SendStatus::busy;
    }
    pack(frame, tx_.back_slot());
    tx_.commit_back();
    return SendStatus::sent;
  }
  [[nodiscard]] ReceiveStatus receive_record(CanFrame& frame) noexcept {
    if (rx_.empty()) {
      return ReceiveStatus::empty;
    }
    received_frame(0, frame);
    rx_.drop_front();
    return ReceiveStatus::received;
  }
  [[nodiscard]] SendStatus do_send(const CanFrame& frame) noexcept override { return send_record(frame); }
  [[nodiscard]] ReceiveStatus do_receive(CanFrame& frame, std::uint32_t /*timeout_us*/) noexcept override {
    return receive_record(frame);
  }
  [[nodiscard]] BusStatus do_set_filters(std::span<const CanFilter> filters) noexcept override {
    return filters_.assign(filters);
  }

  std::array<Record, TxMailboxes> tx_storage_{};
  std::array<Received, RxFifoDepth> rx_storage_{};
  Ring<Record, TxMailboxes> tx_{tx_storage_};
  Ring<Received, RxFifoDepth> rx_{rx_storage_};
  FilterSet filters_{};
};

}  // namespace settle::hal
