// SPDX-License-Identifier: Apache-2.0
#pragma once
// The simulated drive, built in one place: hal's CiA 402 DriveNode configured as the --eds
// description describes it (simulated_drive_from_eds), or Settle's default drive (which
// hal/eds/settle_drive.eds describes exactly), at the requested node, with a DriveAxis (the drive
// model and the plant behind it) as a PlantNode. `settle plant`, the loopback bus of `settle
// stream` and `settle identify`, and the loopback drive of `settle drive` all build it here.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/eds_reader.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/testbed/drive_axis.hpp"
#include "settle/testbed/drive_from_eds.hpp"
#include "settle/testbed/plant_node.hpp"

namespace settle::testbed {

// What to build. Each optional setting left empty keeps what the description (or, without one,
// the default drive) says.
struct SimulatedDriveSpec {
  hal::canopen::NodeId node{1};
  const hal::eds::Description* eds{nullptr};  // null: the default drive; must outlive the build only
  DriveAxisConfig axis{};                     // the drive model behind the node
  // The machine behind the drive (its own copy). None: the seed's spring-damper (plant::SdofParams),
  // for a drive that only answers SDO (`settle drive --bus loopback`) and never moves it.
  std::optional<plant::ModalPlant> plant;
  std::optional<std::uint32_t> sync_period_us;             // 0x1006
  std::optional<std::uint16_t> heartbeat_period_ms;        // 0x1017
  std::optional<std::uint8_t> communication_loss_periods;  // 0x2001
  // With another vendor's description: the object it serves its load position in
  // (simulated_drive_from_eds's load_at); none: it reports no load position.
  std::optional<hal::eds::MappedObject> load_position;
};

// The drive node's configuration the spec describes: from the description (with its error, one
// line naming the object, when it describes a drive this one cannot be), or the default one, with
// the spec's node and settings applied. Its strings point into the result's `texts`.
[[nodiscard]] DriveFromEds simulated_drive_config(const SimulatedDriveSpec& spec);

// The drive: the node (its strings point into `source`, which lives as long as it) and its axis.
struct SimulatedDrive {
  std::unique_ptr<DriveFromEds> source;
  std::unique_ptr<PlantNode> node;
};

// Why a drive could not be built: the description (`eds`: simulated_drive_config's error), or the
// drive axis refusing its configuration (`axis`).
struct SimulatedDriveError {
  std::string eds;
  plant::SimStatus axis{plant::SimStatus::ok};
  [[nodiscard]] bool any() const noexcept { return !eds.empty() || axis != plant::SimStatus::ok; }
  // One line: the description's error as is, or "the simulated drive refused its configuration: ...".
  [[nodiscard]] std::string message() const;
};

// The drive the spec describes, its axis at rest at position 0; `node` null with `error` set when
// it cannot be built.
[[nodiscard]] SimulatedDrive build_simulated_drive(const SimulatedDriveSpec& spec, SimulatedDriveError& error);

}  // namespace settle::testbed
