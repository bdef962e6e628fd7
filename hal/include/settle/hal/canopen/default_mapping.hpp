// SPDX-License-Identifier: Apache-2.0
// Settle's default PDO mapping for a CiA 402 drive streamed in cyclic synchronous position
// (the one the simulated drive's EDS, hal/eds/settle_drive.eds, declares), all PDOs
// synchronous (transmission type 1):
//   RPDO1 0x200+n: controlword 0x6040 (u16) + target position 0x607A (i32)     6 bytes
//   TPDO1 0x180+n: statusword 0x6041 (u16) + position actual 0x6064 (i32)      6 bytes
//   TPDO2 0x280+n: load position 0x2000 (i32) + velocity actual 0x606C (i32)   8 bytes
// The typed codecs below are the master's per-tick fast path; the drive applies the same
// mappings through its object dictionary (PdoBinding), and the tests check both agree.
#pragma once

#include <cstdint>
#include <optional>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/byte_order.hpp"
#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/canopen/pdo.hpp"

namespace settle::hal::canopen {

inline constexpr std::uint32_t default_sync_period_us = 1000;  // 0x1006

struct Rpdo1 {
  std::uint16_t controlword{0};
  std::int32_t target_position{0};  // counts
  friend constexpr bool operator==(const Rpdo1&, const Rpdo1&) = default;
};

struct Tpdo1 {
  std::uint16_t statusword{0};
  std::int32_t position_actual{0};  // counts
  friend constexpr bool operator==(const Tpdo1&, const Tpdo1&) = default;
};

struct Tpdo2 {
  std::int32_t load_position{0};    // counts, same scale as position
  std::int32_t velocity_actual{0};  // counts per second
  friend constexpr bool operator==(const Tpdo2&, const Tpdo2&) = default;
};

[[nodiscard]] CanFrame encode_rpdo1(NodeId node, const Rpdo1& pdo) noexcept;
// The same frame written over `out` (id, flags, length and the six bytes; bytes past the length
// are left as they were): the master's per-tick path, which keeps one frame and copies nothing.
constexpr void encode_rpdo1(NodeId node, const Rpdo1& pdo, CanFrame& out) noexcept {
  out.id = cob_id(cob::rpdo1, node);
  out.flags = 0;
  out.len = 6;
  store_le<std::uint16_t, 4>(&out.data[0], pdo.controlword);  // the payload is word-aligned
  store_le<std::uint32_t, 2>(&out.data[2], static_cast<std::uint32_t>(pdo.target_position));
}
[[nodiscard]] CanFrame encode_tpdo1(NodeId node, const Tpdo1& pdo) noexcept;
[[nodiscard]] CanFrame encode_tpdo2(NodeId node, const Tpdo2& pdo) noexcept;
// The fields of a frame already known to be the PDO (exact id, length, a classic data frame):
// the decoders below after their checks, and a master that has made those checks itself.
// The payload is word-aligned: the statusword is read as a half-word, the position at byte 2 as
// two, TPDO2's values as words.
template <typename Frame>  // CanFrame, or a receive record with the same word-aligned data
[[nodiscard]] constexpr Tpdo1 tpdo1_fields(const Frame& frame) noexcept {
  return Tpdo1{load_le<std::uint16_t, 4>(&frame.data[0]),
               static_cast<std::int32_t>(load_le<std::uint32_t, 2>(&frame.data[2]))};
}
template <typename Frame>
[[nodiscard]] constexpr Tpdo2 tpdo2_fields(const Frame& frame) noexcept {
  return Tpdo2{static_cast<std::int32_t>(load_le<std::uint32_t, 4>(&frame.data[0])),
               static_cast<std::int32_t>(load_le<std::uint32_t, 4>(&frame.data[4]))};
}
inline constexpr std::uint8_t tpdo1_len = 6;
inline constexpr std::uint8_t tpdo2_len = 8;

// Exact id and exact length, or nullopt.
[[nodiscard]] std::optional<Rpdo1> decode_rpdo1(const CanFrame& frame, NodeId node) noexcept;
[[nodiscard]] std::optional<Tpdo1> decode_tpdo1(const CanFrame& frame, NodeId node) noexcept;
[[nodiscard]] std::optional<Tpdo2> decode_tpdo2(const CanFrame& frame, NodeId node) noexcept;

[[nodiscard]] constexpr PdoMapping default_rpdo1_mapping(NodeId node) noexcept {
  return PdoMapping{cob_id(cob::rpdo1, node), pdo_transmission::synchronous, 2,
                    {PdoMappingEntry{obj::controlword, 0, 16}, PdoMappingEntry{obj::target_position, 0, 32}}};
}
[[nodiscard]] constexpr PdoMapping default_tpdo1_mapping(NodeId node) noexcept {
  return PdoMapping{cob_id(cob::tpdo1, node), pdo_transmission::synchronous, 2,
                    {PdoMappingEntry{obj::statusword, 0, 16}, PdoMappingEntry{obj::position_actual, 0, 32}}};
}
[[nodiscard]] constexpr PdoMapping default_tpdo2_mapping(NodeId node) noexcept {
  return PdoMapping{cob_id(cob::tpdo2, node), pdo_transmission::synchronous, 2,
                    {PdoMappingEntry{obj::load_position_actual, 0, 32}, PdoMappingEntry{obj::velocity_actual, 0, 32}}};
}

}  // namespace settle::hal::canopen
