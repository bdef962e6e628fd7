// SPDX-License-Identifier: Apache-2.0
// The ideal drive: the far end of the bus for tests, benchmarks and the firmware images. A real
// hal DriveNode (NMT, SDO, CiA 402 power states, the drive-side safety rules) whose axis reaches
// each target exactly one period after the SYNC that applies it, and reports that position and
// the velocity of the step it took. Heap-free, exception-free and freestanding, so the Cortex-M
// images run the same drive as the host tests.
//
// IdealAxis is the drive independent of the port its frames arrive on; IdealDrive<Port> owns a
// port (a loopback port on a hub, or a CAN controller's buffers) and drains it.
//
// Per SYNC (DriveEvent::sync): a following drive moves its axis to setpoint(); one that is not
// following holds where it is (setpoint() would be 0 before the node's first publish, which is
// not where an axis powered on away from zero stands). The velocity is the step times the SYNC
// rate, the step taken the short way round the counter's wrap as DriveNode does for its step
// limit, in 64 bits and saturated to 0x606C's int32: no overflow whatever the two positions.
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>

#include "settle/hal/can_bus.hpp"
#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/frame_sink.hpp"
#include "settle/hal/loopback_bus.hpp"

namespace settle::hal::testing {

// Velocity (counts/s) of an axis that moves from `from` to `to` in one period, at
// `periods_per_second` periods a second: the step the short way round the 2^32 wrap, times the
// rate, in 64 bits, saturated to int32.
[[nodiscard]] std::int32_t ideal_velocity(std::int32_t from, std::int32_t to, std::uint32_t periods_per_second) noexcept;

class IdealAxis {
 public:
  explicit IdealAxis(const canopen::DriveNodeConfig& config) noexcept;

  // Boot-up (the node announces itself on `out`).
  void start(std::uint64_t now_us, FrameSink& out) noexcept;
  // One received frame; on a SYNC the axis runs one period and the node publishes TPDO1/2.
  canopen::DriveEvent on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept;
  // Heartbeat, watchdogs: once per pass over the port.
  void poll(std::uint64_t now_us, FrameSink& out) noexcept { node_.poll(now_us, out); }

  // Where the axis stands (a drive powered on away from zero, or moved by hand between tests).
  // The node is told at once (DriveNode::set_feedback), so enabling before the first SYNC latches it.
  void set_position(std::int32_t counts) noexcept {
    position_ = counts;
    node_.set_feedback({counts, 0, counts});
  }
  // Reports its position this many counts short of where the axis is (a constant following error).
  void set_lag(std::uint32_t counts) noexcept { lag_ = counts; }

  // Applied setpoints (one per SYNC while following), oldest first, into `buffer` (the caller's
  // storage, which must outlive the recording); starts a new record. Without a buffer the drive
  // only counts them.
  void record_applied(std::span<std::int32_t> buffer) noexcept;
  void clear_applied() noexcept { applied_count_ = 0; }
  // The recorded setpoints since the last clear: the first min(applied_count(), capacity).
  [[nodiscard]] std::span<const std::int32_t> applied() const noexcept;
  // Setpoints applied since the last clear, recorded or not.
  [[nodiscard]] std::uint64_t applied_count() const noexcept { return applied_count_; }
  // More were applied than the buffer holds (applied() is the first part only).
  [[nodiscard]] bool applied_truncated() const noexcept { return applied_count_ > record_.size(); }

  [[nodiscard]] std::int32_t position() const noexcept { return position_; }
  [[nodiscard]] std::int32_t velocity() const noexcept { return velocity_; }
  [[nodiscard]] canopen::DriveNode& node() noexcept { return node_; }
  [[nodiscard]] const canopen::DriveNode& node() const noexcept { return node_; }

 private:
  canopen::DriveNode node_;
  std::uint32_t periods_per_second_;  // 10^6 / 0x1006 as configured (0 for a period of 0)
  std::int32_t position_{0};
  std::int32_t velocity_{0};
  std::uint32_t lag_{0};
  std::span<std::int32_t> record_{};
  std::uint64_t applied_count_{0};
};

// An IdealAxis with its own port. Port: any CanBus the drive owns, constructed from the hub
// (LoopbackBus<N>) or by default (a MailboxBus whose wire side the owner plays).
template <typename Port = LoopbackBus<256>>
class IdealDrive : public IdealAxis {
 public:
  IdealDrive(LoopbackHub& hub, const canopen::DriveNodeConfig& config) noexcept
    requires std::constructible_from<Port, LoopbackHub&>
      : IdealAxis{config}, port_{hub} {}
  explicit IdealDrive(const canopen::DriveNodeConfig& config) noexcept
    requires std::default_initializable<Port>
      : IdealAxis{config}, port_{} {}
  IdealDrive(const IdealDrive&) = delete;
  IdealDrive& operator=(const IdealDrive&) = delete;

  void start(std::uint64_t now_us) noexcept { IdealAxis::start(now_us, port_); }
  // Every frame waiting on the port, in order, then poll().
  void process(std::uint64_t now_us) noexcept {
    CanFrame f{};
    while (port_.receive(f, 0) == ReceiveStatus::received) (void)on_frame(f, now_us, port_);
    poll(now_us, port_);
  }
  [[nodiscard]] Port& port() noexcept { return port_; }
  [[nodiscard]] const Port& port() const noexcept { return port_; }

 private:
  Port port_;
};

}  // namespace settle::hal::testing
