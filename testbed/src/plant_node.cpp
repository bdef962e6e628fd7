// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/plant_node.hpp"

#include <utility>

namespace settle::testbed {

namespace {
// The simulated axis advances one period per SYNC, whenever the simulator gets to it and however
// the bus bunched the SYNCs: its clock is the SYNC count, not the host's.
hal::canopen::DriveNodeConfig moving_per_sync(hal::canopen::DriveNodeConfig c) {
  c.axis_moves_one_period_per_sync = true;
  return c;
}
}  // namespace

PlantNode::PlantNode(const hal::canopen::DriveNodeConfig& node, DriveAxis axis, std::size_t log_capacity)
    : node_{moving_per_sync(node)}, axis_{std::move(axis)}, log_(log_capacity) {}

void PlantNode::start(std::uint64_t now_us, hal::FrameSink& out) { node_.start(now_us, out); }

bool PlantNode::on_frame(const hal::CanFrame& frame, std::uint64_t now_us, hal::FrameSink& out) {
  const hal::canopen::DriveEvent ev = node_.on_frame(frame, now_us, out);
  if (ev == hal::canopen::DriveEvent::reset) {
    // NMT reset node: the drive reboots; the machine stays where it is.
    return false;
  }
  if (ev != hal::canopen::DriveEvent::sync) return false;
  SyncRecord rec{};
  rec.sync = syncs_++;
  rec.time_us = now_us;
  rec.following = node_.following();
  plant::SimStatus st = plant::SimStatus::ok;
  if (rec.following) {
    rec.target = node_.setpoint();
    st = axis_.step(rec.target);
  } else {
    // Not following (disabled, quick stop, fault): the axis holds. A quick stop of an ideal
    // drive is immediate, so report the stop complete at once.
    rec.target = axis_.feedback().position_actual;
    st = axis_.hold();
    if (node_.stopping()) node_.stop_complete();
  }
  if (st != plant::SimStatus::ok) status_ = st;
  rec.feedback = axis_.feedback();
  rec.load = axis_.load_position();
  rec.base = axis_.base_position();
  // Full: the oldest record is overwritten in place (no allocation); a zero capacity keeps none.
  if (log_.capacity() > 0) log_.push_back(rec);
  if (sink_ != nullptr) sink_->on_record(rec);
  node_.publish({rec.feedback.position_actual, rec.feedback.velocity_actual, rec.feedback.load_position}, now_us, out);
  return true;
}

}  // namespace settle::testbed
