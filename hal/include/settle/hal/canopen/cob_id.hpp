// SPDX-License-Identifier: Apache-2.0
// CANopen (CiA 301) node ids and the predefined connection set: which 11-bit identifier
// carries which service for which node. Every encoder and decoder in hal/canopen uses these.
#pragma once

#include <cstdint>
#include <optional>

#include "settle/hal/can_frame.hpp"

namespace settle::hal::canopen {

using NodeId = std::uint8_t;  // 1..127; 0 addresses all nodes in NMT commands only

inline constexpr NodeId node_id_min = 1;
inline constexpr NodeId node_id_max = 127;

[[nodiscard]] constexpr bool is_valid_node(NodeId node) noexcept {
  return node >= node_id_min && node <= node_id_max;
}

// Function codes of the predefined connection set (the COB-ID is base + node id).
namespace cob {
inline constexpr std::uint16_t nmt = 0x000;
inline constexpr std::uint16_t sync = 0x080;
inline constexpr std::uint16_t emcy = 0x080;
inline constexpr std::uint16_t tpdo1 = 0x180;
inline constexpr std::uint16_t rpdo1 = 0x200;
inline constexpr std::uint16_t tpdo2 = 0x280;
inline constexpr std::uint16_t rpdo2 = 0x300;
inline constexpr std::uint16_t tpdo3 = 0x380;
inline constexpr std::uint16_t rpdo3 = 0x400;
inline constexpr std::uint16_t tpdo4 = 0x480;
inline constexpr std::uint16_t rpdo4 = 0x500;
inline constexpr std::uint16_t sdo_tx = 0x580;  // server -> client (responses)
inline constexpr std::uint16_t sdo_rx = 0x600;  // client -> server (requests)
inline constexpr std::uint16_t heartbeat = 0x700;
}  // namespace cob

[[nodiscard]] constexpr std::uint32_t cob_id(std::uint16_t function_code, NodeId node) noexcept {
  return static_cast<std::uint32_t>(function_code) + node;
}

// A frame CANopen could have sent: classic, standard id, not a remote request, no flag bits
// at all. Everything else on the bus is someone else's traffic and every decoder ignores it.
[[nodiscard]] constexpr bool is_canopen_data_frame(const CanFrame& f) noexcept {
  return f.flags == 0 && f.id <= can_standard_id_max && f.len <= can_classic_max_len;
}

// The node a frame with the given function code belongs to, when the frame is of that kind.
[[nodiscard]] constexpr std::optional<NodeId> node_of(const CanFrame& f, std::uint16_t function_code) noexcept {
  const std::uint32_t first = cob_id(function_code, node_id_min);
  const std::uint32_t last = cob_id(function_code, node_id_max);
  if (!is_canopen_data_frame(f) || f.id < first || f.id > last) {
    return std::nullopt;
  }
  return static_cast<NodeId>(f.id - function_code);
}

}  // namespace settle::hal::canopen
