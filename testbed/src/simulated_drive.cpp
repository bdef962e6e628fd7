// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/simulated_drive.hpp"

#include <utility>

namespace settle::testbed {

DriveFromEds simulated_drive_config(const SimulatedDriveSpec& spec) {
  DriveFromEds d{};
  if (spec.eds != nullptr) {
    d = simulated_drive_from_eds(*spec.eds, spec.node, spec.load_position);
    if (!d.config) return d;
  } else {
    d.config.emplace();
  }
  hal::canopen::DriveNodeConfig& c = *d.config;
  c.node = spec.node;
  if (spec.sync_period_us) c.sync_period_us = *spec.sync_period_us;
  if (spec.heartbeat_period_ms) c.heartbeat_period_ms = *spec.heartbeat_period_ms;
  if (spec.communication_loss_periods) c.communication_loss_periods = *spec.communication_loss_periods;
  return d;
}

std::string SimulatedDriveError::message() const {
  if (!eds.empty()) return eds;
  return std::string{"the simulated drive refused its configuration: "} + to_string(axis);
}

SimulatedDrive build_simulated_drive(const SimulatedDriveSpec& spec, SimulatedDriveError& error) {
  error = {};
  SimulatedDrive d{std::make_unique<DriveFromEds>(simulated_drive_config(spec)), nullptr};
  if (!d.source->config) {
    error.eds = d.source->error;
    return d;
  }
  plant::ModalPlant machine{};
  error.axis = spec.plant ? plant::SimStatus::ok : plant::ModalPlant::make_sdof(plant::SdofParams{}, machine);
  if (error.axis != plant::SimStatus::ok) return d;
  DriveAxis axis{};
  error.axis = DriveAxis::make(spec.axis, spec.plant ? *spec.plant : machine, 0, axis);
  if (error.axis != plant::SimStatus::ok) return d;
  d.node = std::make_unique<PlantNode>(*d.source->config, std::move(axis));
  return d;
}

}  // namespace settle::testbed
