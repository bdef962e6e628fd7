// SPDX-License-Identifier: Apache-2.0
#pragma once
// The simulated drive on the bus (`settle plant`): hal's CiA 402 DriveNode (NMT, heartbeat,
// SDO server, power state machine, drive-side safety) with a DriveAxis behind it. SYNC-driven,
// never timer-driven: at each SYNC it applies the last received target, advances the plant by
// exactly one period and publishes TPDO1/TPDO2 with the state at the end of that period.
#include <cstddef>
#include <cstdint>

#include <boost/circular_buffer.hpp>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/frame_sink.hpp"
#include "settle/testbed/drive_axis.hpp"
#include "settle/testbed/sync_log.hpp"

namespace settle::testbed {

class PlantNode {
 public:
  // The last records kept in memory (the whole log goes to a SyncSink, e.g. a SyncCsvLog).
  static constexpr std::size_t kDefaultLogCapacity = 4096;

  // The ring is allocated here, once; on_frame never allocates.
  PlantNode(const hal::canopen::DriveNodeConfig& node, DriveAxis axis,
            std::size_t log_capacity = kDefaultLogCapacity);

  // Each record goes to `sink` as it is made (nullptr: none). The sink must outlive the node.
  void set_sink(SyncSink* sink) noexcept { sink_ = sink; }

  void start(std::uint64_t now_us, hal::FrameSink& out);
  // Returns true when the frame was a SYNC and the plant advanced.
  bool on_frame(const hal::CanFrame& frame, std::uint64_t now_us, hal::FrameSink& out);
  void poll(std::uint64_t now_us, hal::FrameSink& out) { node_.poll(now_us, out); }

  // The last log_capacity records, oldest first; its capacity never changes.
  [[nodiscard]] const boost::circular_buffer<SyncRecord>& log() const noexcept { return log_; }
  // SYNCs that advanced the plant since start (records made, kept or not).
  [[nodiscard]] std::uint64_t syncs() const noexcept { return syncs_; }
  [[nodiscard]] const DriveAxis& axis() const noexcept { return axis_; }
  [[nodiscard]] hal::canopen::DriveNode& node() noexcept { return node_; }
  [[nodiscard]] plant::SimStatus status() const noexcept { return status_; }

 private:
  hal::canopen::DriveNode node_;
  DriveAxis axis_;
  boost::circular_buffer<SyncRecord> log_;
  SyncSink* sink_{nullptr};
  std::uint64_t syncs_{0};
  plant::SimStatus status_{plant::SimStatus::ok};
};

}  // namespace settle::testbed
