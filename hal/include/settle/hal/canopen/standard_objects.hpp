// SPDX-License-Identifier: Apache-2.0
// The data types CiA 301 (communication profile) and CiA 402 (drives) give the standard objects a
// CiA 402 drive has, so a master can check a value's type before it writes one without an EDS:
// SDO transfers carry bytes, not types, and a 4-character string fits an UNSIGNED32 object.
// Covers the objects Settle reads, writes or maps (cia402.hpp's obj names) and the PDO
// communication and mapping records; any other index (manufacturer-specific ones above all) is
// unknown here and only its EDS can say.
#pragma once

#include <cstdint>

#include "settle/hal/canopen/object_dictionary.hpp"

namespace settle::hal::canopen {

struct StandardObject {
  OdType type;
  const char* name;     // as the standard names it, e.g. "max profile velocity"
  const char* profile;  // "CiA 301" or "CiA 402"
};

// The standard type of (index, sub), or nullptr when this table does not know the object.
[[nodiscard]] const StandardObject* find_standard_object(std::uint16_t index, std::uint8_t sub) noexcept;

// "UNSIGNED32", "VISIBLE_STRING", ...: the name CiA 301 gives a data type index (an EDS's
// DataType, an OdType's value); `unknown` for an index this list does not name.
[[nodiscard]] const char* data_type_name(std::uint16_t type, const char* unknown) noexcept;

}  // namespace settle::hal::canopen
