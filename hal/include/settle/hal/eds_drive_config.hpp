// SPDX-License-Identifier: Apache-2.0
// From a drive's EDS or DCF to the master's start-up configuration (host only): checks that the
// objects streaming needs exist with the right type, access and PDO mappability, and chooses how
// the PDOs are set up: dynamic mapping of a layout when the description says the mapping is
// writable, the drive's own (static) mapping, read and checked at start-up, when it is not. What
// cannot work is refused here, before any frame is sent, with an error naming the object.
//
// The `settle drive config` and `settle stream --eds` commands call drive_config_from_eds and hand
// the result to RemoteDrive (directly, or through runtime::AxisConfig::drive).
#pragma once

#include <cstdint>
#include <string>
#include <variant>

#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/eds_reader.hpp"

namespace settle::hal::eds {

// The feedback the user wants besides the statusword and the position actual.
struct FeedbackRequest {
  bool velocity_actual{false};        // 0x606C
  bool following_error{false};        // 0x60F4
  std::uint16_t load_position_index{0};  // the drive's load-side position object; 0 = none
  std::uint8_t load_position_sub{0};
};

struct DriveConfigResult {
  canopen::RemoteDriveConfig config{};  // valid when error is empty
  bool mapping_writable{false};         // the description's PDO mapping is dynamic
  std::string error;                    // why the drive cannot stream, naming the object
  [[nodiscard]] bool ok() const noexcept { return error.empty(); }
};

// `base` supplies the node, mode, periods and supervision; the result adds the expected identity
// (vendor and product code from the description, when it states them), pdo_setup and layout.
// Dynamic layout: RPDO1 controlword + target position; TPDO1 statusword + position actual; the
// requested feedback packed into TPDO2 (load position, velocity) and TPDO3 (following error).
[[nodiscard]] DriveConfigResult drive_config_from_eds(const Description& description,
                                                      const canopen::RemoteDriveConfig& base,
                                                      const FeedbackRequest& feedback);

}  // namespace settle::hal::eds
