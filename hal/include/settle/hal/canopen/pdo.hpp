// SPDX-License-Identifier: Apache-2.0
// CiA 301 static PDO mapping: which objects, in which order, fill a PDO's bytes. A mapping is
// resolved against the object dictionary once (PdoBinding), so packing a TPDO or applying an
// RPDO at each SYNC is a copy of a few bytes with no lookups.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/object_dictionary.hpp"
#include "settle/hal/canopen/sdo_abort.hpp"

namespace settle::hal::canopen {

inline constexpr std::size_t pdo_max_entries = 8;

struct PdoMappingEntry {
  std::uint16_t index{0};
  std::uint8_t sub{0};
  std::uint8_t bits{0};
  // The mapping object's value (0x1600..., 0x1A00... sub 1..8): index, sub, length in bits.
  [[nodiscard]] constexpr std::uint32_t raw() const noexcept {
    return (std::uint32_t{index} << 16U) | (std::uint32_t{sub} << 8U) | bits;
  }
};

// Transmission types (comm parameter sub 2) Settle uses.
namespace pdo_transmission {
inline constexpr std::uint8_t synchronous = 1;  // every SYNC
inline constexpr std::uint8_t event_driven = 0xFF;
}  // namespace pdo_transmission

struct PdoMapping {
  std::uint32_t cob_id{0};
  std::uint8_t transmission_type{pdo_transmission::synchronous};
  std::uint8_t count{0};
  std::array<PdoMappingEntry, pdo_max_entries> entries{};

  [[nodiscard]] constexpr std::size_t bit_length() const noexcept {
    std::size_t bits = 0;
    for (std::size_t i = 0; i < count && i < pdo_max_entries; ++i) {
      bits += entries[i].bits;
    }
    return bits;
  }
  [[nodiscard]] constexpr std::size_t byte_length() const noexcept { return (bit_length() + 7U) / 8U; }
};

enum class PdoStatus : std::uint8_t {
  ok,
  unbound,      // bind() did not succeed
  wrong_id,     // not this PDO's COB-ID (or not a CANopen data frame)
  too_short,    // fewer bytes than mapped: not processed (EMCY 0x8210)
  applied_longer,  // more bytes than mapped: the mapped bytes applied, the rest ignored (EMCY
                   // 0x8220), as CANopenNode and Lely do
  rejected,     // a mapped object refused the value (range, owner's veto)
};

// Which way a PDO carries its objects: an RPDO writes them (each must be writable), a TPDO reads
// them (each must be readable). unchecked: mappability alone (a mapping tried on its own).
enum class PdoDirection : std::uint8_t { unchecked, receive, transmit };

// A mapping resolved to dictionary entries. Only whole-byte objects are mappable here
// (every CiA 402 process value is 8, 16 or 32 bits).
class PdoBinding {
 public:
  // Checks every entry exists (0x06020000, 0x06090011), is mappable and, for a direction, has
  // the access it needs (0x06040041), has its type's length (0x06070010), and that all fit eight
  // bytes (0x06040042). On failure the binding is left unbound.
  [[nodiscard]] SdoAbort bind(const PdoMapping& mapping, ObjectDictionary& od,
                              PdoDirection direction = PdoDirection::unchecked) noexcept;
  // Whether the mapping carries the object.
  [[nodiscard]] bool carries(std::uint16_t index, std::uint8_t sub) const noexcept;

  // Fills a TPDO from the current values of the mapped variables.
  [[nodiscard]] PdoStatus pack(CanFrame& out) const noexcept;
  // Applies an RPDO to the mapped variables. A frame shorter than the mapping is not processed;
  // a longer one is, from its mapped bytes (applied_longer, so the owner reports 0x8220). Values
  // are checked before any is stored, so a rejected frame leaves every variable untouched.
  [[nodiscard]] PdoStatus unpack(const CanFrame& in) noexcept;

  // The bytes the mapping fills (a frame shorter than this is not processed).
  [[nodiscard]] std::size_t byte_length() const noexcept { return bytes_; }
  [[nodiscard]] bool bound() const noexcept { return od_ != nullptr; }

 private:
  // The mapping is kept as its resolved entries only (each names its object and has its size):
  // a drive holds one binding per PDO, and the smallest image counts their bytes.
  std::array<const OdEntry*, pdo_max_entries> resolved_{};
  ObjectDictionary* od_{nullptr};
  std::uint32_t cob_id_{0};
  std::uint8_t count_{0};
  std::uint8_t bytes_{0};
};

}  // namespace settle::hal::canopen
