#pragma once
// Test double for the far end of the bus: a real hal DriveNode whose axis reaches each target
// exactly one period after the SYNC that applies it (an ideal position-following drive), with a
// log of every setpoint it applied, in order.
#include <cstdint>
#include <vector>

#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/loopback_bus.hpp"

namespace settle::test {

class IdealDrive {
 public:
  IdealDrive(hal::LoopbackHub& hub, hal::canopen::DriveNodeConfig cfg) : bus_{hub}, node_{cfg} {}
  void start(std::uint64_t now_us) { node_.start(now_us, bus_); }
  void process(std::uint64_t now_us) {
    hal::CanFrame f{};
    while (bus_.receive(f, 0) == hal::ReceiveStatus::received) {
      if (node_.on_frame(f, now_us, bus_) == hal::canopen::DriveEvent::sync) {
        // Only a following drive moves its axis (otherwise setpoint() is the position it last
        // published, or 0 before its first publish).
        const std::int32_t sp = node_.following() ? node_.setpoint() : position_;
        if (node_.following()) applied.push_back(sp);
        // Counts wrap modulo 2^32, as a drive's position counter does.
        velocity_ = static_cast<std::int32_t>((static_cast<std::uint32_t>(sp) - static_cast<std::uint32_t>(position_)) * 1000U);
        position_ = sp;
        if (node_.stopping()) node_.stop_complete();
        const auto reported = static_cast<std::int32_t>(static_cast<std::uint32_t>(position_) - lag_);
        node_.publish({reported, velocity_, reported}, now_us, bus_);
      }
    }
    node_.poll(now_us, bus_);
  }
  // Where the axis stands before start-up (a drive powered on away from zero).
  void set_position(std::int32_t counts) { position_ = counts; }
  // Reports its position this many counts short of where the axis is (a constant following error).
  void set_lag(std::uint32_t counts) { lag_ = counts; }
  hal::canopen::DriveNode& node() { return node_; }
  hal::LoopbackBus<256>& bus() { return bus_; }
  std::int32_t position() const { return position_; }
  std::vector<std::int32_t> applied;

 private:
  hal::LoopbackBus<256> bus_;
  hal::canopen::DriveNode node_;
  std::int32_t position_{0};
  std::int32_t velocity_{0};
  std::uint32_t lag_{0};
};

}  // namespace settle::test
