// SPDX-License-Identifier: Apache-2.0
// The simulated drive's configuration (hal's DriveNodeConfig) from an EDS: which optional
// objects it has, its identity and device type, the defaults of its parameters, its PDOs'
// default mappings and whether they are writable (the mapping objects' AccessType). An EDS that
// describes something the simulated drive cannot be is refused with a line that names the object
// (an object it does not implement, one it always has that the EDS lacks, a default it cannot
// take, a default mapping that cannot be bound, naming the PDO and the entry). Settle's own
// descriptions ([SettleDrive]) are matched object for object; in another vendor's, the
// manufacturer objects 0x2000..0x5FFF are that vendor's: described, not simulated (an SDO to one
// aborts 0x06020000; the master never uses them). Host only (files, strings).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/eds_reader.hpp"

namespace settle::testbed {

// The drive's strings 0x1008..0x100A as the EDS gives them (DefaultValue).
struct DriveTexts {
  std::string device_name;
  std::string hardware_version;
  std::string software_version;
};

struct DriveFromEds {
  // Its device_name, hardware_version and software_version point into `texts`: keep this result
  // (it moves, it does not copy) for as long as a DriveNode built from the config lives.
  std::optional<hal::canopen::DriveNodeConfig> config;
  std::unique_ptr<const DriveTexts> texts;
  std::string error;  // why not, one line naming the object at fault
};

// The configuration for node `node` (values with $NODEID resolved for it). `load_at`: on another
// vendor's drive, the manufacturer object (0x2000 or 0x2002..0x5FFF) the drive serves its load
// position in (the user's --load-feedback on the loopback bus: the simulated drive is then the one
// the user says they have); it must be described as a readable, mappable INTEGER32, else the
// result is an error naming it. Settle's own drive keeps its 0x2000 and ignores it; without it
// another vendor's drive reports no load position.
[[nodiscard]] DriveFromEds simulated_drive_from_eds(const hal::eds::Description& eds, hal::canopen::NodeId node,
                                                    std::optional<hal::eds::MappedObject> load_at = std::nullopt);
// The same from a file: the reader's error (which names the file), or the path and the above.
[[nodiscard]] DriveFromEds load_drive_config(const std::string& path, hal::canopen::NodeId node);

}  // namespace settle::testbed
