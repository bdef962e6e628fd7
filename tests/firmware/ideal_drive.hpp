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
        const std::int32_t sp = node_.setpoint();
        if (node_.following()) applied.push_back(sp);
        velocity_ = (sp - position_) * 1000;
        position_ = sp;
        if (node_.stopping()) node_.stop_complete();
        node_.publish({position_, velocity_, position_}, now_us, bus_);
      }
    }
    node_.poll(now_us, bus_);
  }
  hal::canopen::DriveNode& node() { return node_; }
  hal::LoopbackBus<256>& bus() { return bus_; }
  std::int32_t position() const { return position_; }
  std::vector<std::int32_t> applied;

 private:
  hal::LoopbackBus<256> bus_;
  hal::canopen::DriveNode node_;
  std::int32_t position_{0};
  std::int32_t velocity_{0};
};

}  // namespace settle::test
