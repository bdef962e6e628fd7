// SPDX-License-Identifier: Apache-2.0
// What a read description means for one node (host only): the checks no single key can make.
// Refused, naming the object: a valid PDO whose COB-ID is this node's NMT, SYNC, EMCY, SDO or
// heartbeat identifier, or another valid PDO's; a PDO transmission type CiA 301 reserves; a
// 0x607F (max profile velocity) of 0, which would stop every step; a DCF made for another node.
// Warned (real tools accept them): a COB-ID in a range CiA 301 restricts (another node's SDO,
// EMCY or heartbeat), a TPDO the drive sends only when asked by RTR or on events rather than per
// SYNC.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "settle/hal/eds_reader.hpp"

namespace settle::hal::eds {

struct Semantics {
  std::optional<Problem> refusal;  // the first, naming section, key and rule
  std::vector<Problem> warnings;   // in object order
};

// `node`: the node the description is used for (1..127).
[[nodiscard]] Semantics check_semantics(const Description& description, std::uint8_t node);

}  // namespace settle::hal::eds
