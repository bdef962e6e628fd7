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
#include <vector>

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

// Settle's own drive (hal's DriveNode, hal/eds/settle_drive.eds and its variants), as its
// description marks it ([SettleDrive], Description::settle_drive): only there are Settle's
// manufacturer objects (0x2001 communication loss periods) what Settle means by them; in another
// vendor's dictionary 0x2000.. are that vendor's.
[[nodiscard]] bool is_settle_drive(const Description& description) noexcept;

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
// The objects the master uses besides what streaming needs are written only to a drive that has
// them: 0x1006 and 0x60C2 (the period; one of the two is needed), 0x1016/0x1017 (heartbeats),
// 0x6065/0x6066 (following error), 0x2001 (Settle's drive only).
[[nodiscard]] DriveConfigResult drive_config_from_eds(const Description& description,
                                                      const canopen::RemoteDriveConfig& base,
                                                      const FeedbackRequest& feedback);

// One object of the drive as the master's configuration uses it (`settle drive config` lists them):
// what streaming needs, and what the master uses when the drive has it.
struct Capability {
  std::uint16_t index{0};
  std::uint8_t sub{0};
  std::string name;
  bool needed{false};   // streaming cannot run without it
  bool found{false};    // the description has it
  std::string use;      // "written", "checked", "read", "RPDO1", "TPDO2"...; "" when not used
  std::string without;  // what the master does without it (objects not needed)
};
// From the plan the configuration makes (canopen::plan_start_up) and its layout: every object
// listed is either used as `use` says, or done without.
[[nodiscard]] std::vector<Capability> capabilities(const Description& description, const DriveConfigResult& plan,
                                                   const FeedbackRequest& feedback);

}  // namespace settle::hal::eds
