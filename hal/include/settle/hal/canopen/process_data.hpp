// SPDX-License-Identifier: Apache-2.0
// Where the master's process data sit in a drive's PDOs: which RPDO carries the controlword and
// the target position, which TPDOs carry the statusword, the position actual and the optional
// feedback (load-side position, velocity actual, following error actual), at which byte, in how
// many bytes. The default is Settle's own mapping (default_mapping.hpp), which the master's
// per-tick codecs handle inline; any other layout goes through the generic code here.
//
// A layout is what start-up writes into a drive whose mapping is writable (CiA 301 dynamic
// mapping: RemoteDriveConfig::pdo_setup = dynamic), or what it derives from a drive's own
// mapping when that is static (place_mapped_object), or what the user asserts (assume).
#pragma once

#include <array>
#include <cstdint>

#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/hal/canopen/pdo.hpp"
#include "settle/hal/enum_text.hpp"

namespace settle::hal::canopen {

// RPDO1..4 and TPDO1..4: the predefined connection set's PDOs.
inline constexpr std::uint8_t layout_pdo_count = 4;
inline constexpr std::uint32_t pdo_cob_id_invalid = 0x8000'0000;  // COB-ID bit 31: the PDO does not exist
inline constexpr std::uint32_t pdo_cob_id_no_rtr = 0x4000'0000;   // COB-ID bit 30: no remote request

// One value's place: PDO number 1..4 (0 = not mapped), first byte, size in bytes.
struct PdoSlot {
  std::uint8_t pdo{0};
  std::uint8_t offset{0};
  std::uint8_t size{0};
  [[nodiscard]] constexpr bool mapped() const noexcept { return pdo != 0; }
  friend constexpr bool operator==(const PdoSlot&, const PdoSlot&) = default;
};

struct ProcessDataLayout {
  // Received by the drive, both in ONE RPDO.
  PdoSlot controlword{1, 0, 2};      // 0x6040 u16
  PdoSlot target_position{1, 2, 4};  // 0x607A i32
  // Sent by the drive. The statusword and the position actual may be in different TPDOs (a
  // drive's static mapping may split them): the master then takes a period's feedback only when
  // every TPDO carrying a value below has arrived for it (feedback_split, RemoteDrive).
  PdoSlot statusword{1, 0, 2};       // 0x6041 u16
  PdoSlot position_actual{1, 2, 4};  // 0x6064 i32
  PdoSlot load_position{2, 0, 4};    // load_position_index:sub, i32
  PdoSlot velocity_actual{2, 4, 4};  // 0x606C i32
  PdoSlot following_error{};         // 0x60F4 i32
  // The drive's object for the load-side position (vendor-specific; Settle's drive: 0x2000).
  std::uint16_t load_position_index{obj::load_position_actual};
  std::uint8_t load_position_sub{0};
  friend constexpr bool operator==(const ProcessDataLayout&, const ProcessDataLayout&) = default;
};

[[nodiscard]] constexpr bool is_default_layout(const ProcessDataLayout& layout) noexcept {
  return layout == ProcessDataLayout{};
}

// A layout with nothing mapped (what a static mapping's derivation starts from).
[[nodiscard]] constexpr ProcessDataLayout empty_layout(const ProcessDataLayout& keep_objects) noexcept {
  ProcessDataLayout l{};
  l.controlword = l.target_position = l.statusword = l.position_actual = PdoSlot{};
  l.load_position = l.velocity_actual = l.following_error = PdoSlot{};
  l.load_position_index = keep_objects.load_position_index;
  l.load_position_sub = keep_objects.load_position_sub;
  return l;
}

// Made from one list (enum_text.hpp): enumerator (= code, to_string) and sentence (describe).
#define SETTLE_HAL_LAYOUT_ERRORS(X) \
  X(none, "the layout is valid") \
  X(missing, "controlword, target position, statusword or position actual is not mapped") \
  X(split, "controlword and target position in different RPDOs (without split feedback: statusword and position too)") \
  X(bad_slot, "a PDO number over 4, or a size other than the object's") \
  X(too_long, "a value past a PDO's eight bytes") \
  X(overlap, "two values share bytes of a PDO") \
  X(gap, "dynamic mapping: a PDO's values are not back to back from byte 0")
enum class LayoutError : std::uint8_t { SETTLE_HAL_LAYOUT_ERRORS(SETTLE_ENUM_ENUMERATOR) };
[[nodiscard]] const char* to_string(LayoutError error) noexcept;
[[nodiscard]] const char* describe(LayoutError error) noexcept;

// `dynamic`: the layout is to be written into the drive, entry after entry, so no gaps.
[[nodiscard]] LayoutError check_layout(const ProcessDataLayout& layout, bool dynamic) noexcept;

// The mapping the layout gives PDO `number` (1..4) in the direction, entries in byte order, with
// the predefined COB-ID and synchronous transmission; count 0 when the layout does not use it.
[[nodiscard]] PdoMapping layout_mapping(const ProcessDataLayout& layout, bool receive, std::uint8_t number,
                                        NodeId node) noexcept;

// The predefined connection set's COB-ID of RPDO/TPDO `number` (1..4).
[[nodiscard]] constexpr std::uint32_t pdo_cob_id(bool receive, std::uint8_t number, NodeId node) noexcept {
  return (receive ? cob::rpdo1 : cob::tpdo1) + 0x100U * (number - 1U) + node;
}
[[nodiscard]] constexpr std::uint16_t pdo_communication_index(bool receive, std::uint8_t number) noexcept {
  return static_cast<std::uint16_t>((receive ? 0x1400U : 0x1800U) + number - 1U);
}
[[nodiscard]] constexpr std::uint16_t pdo_mapping_index(bool receive, std::uint8_t number) noexcept {
  return static_cast<std::uint16_t>((receive ? 0x1600U : 0x1A00U) + number - 1U);
}
// The communication object (0x1400.. / 0x1800..) of a PDO's mapping object (0x1600.. / 0x1A00..).
[[nodiscard]] constexpr std::uint16_t pdo_communication_of_mapping(std::uint16_t mapping_index) noexcept {
  return static_cast<std::uint16_t>(mapping_index - 0x200U);
}

// A drive's static mapping, entry by entry: places the object a mapping entry (raw 0x1600/0x1A00
// value) names at `offset_bytes` of PDO `number` when it is one the layout knows. Returns false
// for an object the master cannot fill in an RPDO (it would send zeros into it).
[[nodiscard]] bool place_mapped_object(ProcessDataLayout& layout, bool receive, std::uint8_t number,
                                       std::uint8_t offset_bytes, std::uint32_t raw_entry) noexcept;

// Split feedback (the statusword and the position actual in different TPDOs) is understood by
// the master unless the build leaves it out (SETTLE_HAL_SPLIT_FEEDBACK=0: the Cortex-M images,
// for flash); check_layout then refuses such a layout (split), as a static mapping would be.
#ifndef SETTLE_HAL_SPLIT_FEEDBACK
#define SETTLE_HAL_SPLIT_FEEDBACK 1
#endif
inline constexpr bool split_feedback_supported = SETTLE_HAL_SPLIT_FEEDBACK != 0;

// The statusword and the position actual are in different TPDOs: one period's feedback is the
// frames of every TPDO in feedback_tpdos, which the drive sends on the same SYNC.
[[nodiscard]] constexpr bool feedback_split(const ProcessDataLayout& layout) noexcept {
  return layout.statusword.mapped() && layout.position_actual.mapped() &&
         layout.statusword.pdo != layout.position_actual.pdo;
}
// The TPDOs (bit n - 1 for TPDO n, 1..4) that carry a value the layout reads.
[[nodiscard]] std::uint8_t feedback_tpdos(const ProcessDataLayout& layout) noexcept;

// A received TPDO `number` carries the value at `slot` (mapped there, within the frame's bytes).
[[nodiscard]] constexpr bool slot_carried(const PdoSlot& slot, std::uint8_t number, const CanFrame& frame) noexcept {
  return slot.mapped() && slot.pdo == number && slot.offset + slot.size <= frame.len;
}
// The value at `slot` of a frame that carries it, little-endian, zero-extended.
[[nodiscard]] std::uint32_t slot_value(const PdoSlot& slot, const CanFrame& frame) noexcept;
// The RPDO under a layout: id, length and the two values (other bytes zero).
void encode_layout_rpdo(const ProcessDataLayout& layout, NodeId node, std::uint16_t controlword,
                        std::int32_t target_position, CanFrame& out) noexcept;

// Bytes the layout puts in PDO `number` (the end of its last value).
[[nodiscard]] std::uint8_t layout_pdo_length(const ProcessDataLayout& layout, bool receive, std::uint8_t number) noexcept;

}  // namespace settle::hal::canopen
