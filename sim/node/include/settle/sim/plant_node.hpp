#pragma once
// The simulated drive on the bus (`settle plant`): hal's CiA 402 DriveNode (NMT, heartbeat,
// SDO server, power state machine, drive-side safety) with a DriveAxis behind it. SYNC-driven,
// never timer-driven: at each SYNC it applies the last received target, advances the plant by
// exactly one period and publishes TPDO1/TPDO2 with the state at the end of that period.
#include <cstdint>
#include <vector>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/frame_sink.hpp"
#include "settle/sim/drive_axis.hpp"

namespace settle::sim {

// One SYNC as the drive saw it: what it applied and where the machine was one period later.
struct SyncRecord {
  std::uint64_t sync{0};       // index of the SYNC since start
  std::uint64_t time_us{0};
  bool following{false};       // a target was applied (operation enabled)
  std::int32_t target{0};      // counts (the applied setpoint, or the held position)
  AxisFeedback feedback{};
  double load{0.0};            // unquantised output position at the end of the period
  double base{0.0};
};

class PlantNode {
 public:
  PlantNode(const hal::canopen::DriveNodeConfig& node, DriveAxis axis);

  void start(std::uint64_t now_us, hal::FrameSink& out);
  // Returns true when the frame was a SYNC and the plant advanced.
  bool on_frame(const hal::CanFrame& frame, std::uint64_t now_us, hal::FrameSink& out);
  void poll(std::uint64_t now_us, hal::FrameSink& out) { node_.poll(now_us, out); }

  [[nodiscard]] const std::vector<SyncRecord>& log() const noexcept { return log_; }
  [[nodiscard]] const DriveAxis& axis() const noexcept { return axis_; }
  [[nodiscard]] hal::canopen::DriveNode& node() noexcept { return node_; }
  [[nodiscard]] SimStatus status() const noexcept { return status_; }

 private:
  hal::canopen::DriveNode node_;
  DriveAxis axis_;
  std::vector<SyncRecord> log_;
  std::uint64_t syncs_{0};
  SimStatus status_{SimStatus::ok};
};

}  // namespace settle::sim
