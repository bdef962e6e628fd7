// SPDX-License-Identifier: Apache-2.0
// A drive's description from its EDS or DCF file (CiA 306, INI format, read here): every
// object's index, sub-index, name, data type, access, PDO mappability, limits and default (or,
// in a DCF, configured) value, the device's identity, and its PDO communication and mapping
// objects. Host only (files, strings, the heap): the master configures a drive from it and the
// simulated drive builds its dictionary from it; neither runs it in the servo loop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace settle::hal::eds {

// Bounds checked before anything is read or grows (a first pass over the text counts the lines
// of each kind): a description beyond one of them is refused, the refusal naming the bound.
// Reading is linear in the file's size within them (sections are indexed by object once).
inline constexpr std::size_t max_file_bytes = 4u << 20;  // the whole file, bytes
inline constexpr std::size_t max_objects = 16384;        // object sections [IIII], index >= 0x1000
inline constexpr std::size_t max_sections = 65536;       // all [sections], sub-index ones included
inline constexpr std::size_t max_keys = 524288;          // all key=value lines

enum class Access : std::uint8_t { ro, wo, rw, rwr, rww, constant };
[[nodiscard]] const char* to_string(Access access) noexcept;

// CiA 301 data type indices (the EDS's DataType), the ones a drive's objects use.
namespace data_type {
inline constexpr std::uint16_t boolean = 0x0001;
inline constexpr std::uint16_t i8 = 0x0002;
inline constexpr std::uint16_t i16 = 0x0003;
inline constexpr std::uint16_t i32 = 0x0004;
inline constexpr std::uint16_t u8 = 0x0005;
inline constexpr std::uint16_t u16 = 0x0006;
inline constexpr std::uint16_t u32 = 0x0007;
inline constexpr std::uint16_t real32 = 0x0008;
inline constexpr std::uint16_t visible_string = 0x0009;
inline constexpr std::uint16_t octet_string = 0x000A;
inline constexpr std::uint16_t unicode_string = 0x000B;
inline constexpr std::uint16_t domain = 0x000F;
inline constexpr std::uint16_t real64 = 0x0011;
inline constexpr std::uint16_t i64 = 0x0015;
inline constexpr std::uint16_t u64 = 0x001B;
}  // namespace data_type

// Size in bits of a fixed-size type (what a PDO mapping entry states); 0 for strings and domains.
[[nodiscard]] unsigned data_type_bits(std::uint16_t type) noexcept;
[[nodiscard]] bool data_type_is_integer(std::uint16_t type) noexcept;
[[nodiscard]] bool data_type_is_signed(std::uint16_t type) noexcept;
[[nodiscard]] bool data_type_is_real(std::uint16_t type) noexcept;  // REAL32, REAL64

// Where in the file, and what: a warning about what the reader tolerated, or the reason it
// refused the file (naming the section, the key and the rule).
struct Problem {
  std::string section;  // as written, without the brackets; empty when about the whole file
  std::string key;      // as written; empty when about the section as a whole
  std::string message;  // the rule, or what was read instead
  int line{0};          // the key's (else the section's) line; 0 when about the whole file
};
// "line 12: [607Fsub0] LowLimit: message", leaving out what is empty.
[[nodiscard]] std::string to_string(const Problem& problem);

struct Entry {
  std::uint16_t index{0};
  std::uint8_t sub{0};
  std::string name;
  std::uint16_t data_type{0};
  Access access{Access::ro};
  bool pdo_mappable{false};
  std::string default_value;    // as written (integers may use $NODEID); empty when absent
  std::string parameter_value;  // a DCF's configured value; empty when absent
  // LowLimit/HighLimit of an integer type (UNSIGNED64: the value's bits, as value() gives them).
  std::optional<std::int64_t> low_limit;
  std::optional<std::int64_t> high_limit;
  // LowLimit/HighLimit of a REAL32 or REAL64.
  std::optional<double> low_limit_real;
  std::optional<double> high_limit_real;
  // Where it is written, for messages about its value: the section (as written) and the line of
  // the value used (ParameterValue, else DefaultValue, else the section's line).
  std::string section;
  int line{0};

  [[nodiscard]] bool readable() const noexcept { return access != Access::wo; }
  [[nodiscard]] bool writable() const noexcept {
    return access == Access::wo || access == Access::rw || access == Access::rwr || access == Access::rww;
  }
  // The value the object holds after start-up: the DCF's ParameterValue, else DefaultValue, as
  // an integer with $NODEID resolved; nullopt for non-integer types or when neither is given.
  // A hex value of a signed type is its two's complement (0xFFFFFFFFFFFFFFFF is an INTEGER64's
  // -1); an UNSIGNED64 above 2^63 - 1 comes as its bits (cast to std::uint64_t).
  [[nodiscard]] std::optional<std::int64_t> value(std::uint8_t node) const;
  // The same for REAL32/REAL64 (decimal text such as 4.5 or 1e-3); nullopt for other types.
  [[nodiscard]] std::optional<double> real_value() const;
};

struct DeviceInfo {
  std::string vendor_name;
  std::uint32_t vendor_number{0};
  std::string product_name;
  std::uint32_t product_number{0};
  std::uint32_t revision_number{0};
  unsigned nr_rx_pdo{0};
  unsigned nr_tx_pdo{0};
  unsigned granularity{0};  // 0: mapping is not dynamic (CiA 306); 8: byte granularity
};

struct MappedObject {
  std::uint16_t index{0};
  std::uint8_t sub{0};
  std::uint8_t bits{0};
};

// One PDO as the description defines it: its communication object (0x1400/0x1800 + n) and its
// mapping object (0x1600/0x1A00 + n).
struct Pdo {
  bool receive{false};          // RPDO (the drive receives it) or TPDO
  unsigned number{1};           // 1-based: RPDO1 is 0x1400/0x1600
  std::uint32_t cob_id{0};      // with $NODEID resolved; bit 31 set = not valid (disabled)
  std::uint8_t transmission_type{0};
  bool mapping_writable{false};  // sub 0 of the mapping object is writable: dynamic mapping
  std::vector<MappedObject> mapping;  // the default (or a DCF's configured) entries

  [[nodiscard]] std::uint16_t communication_index() const noexcept {
    return static_cast<std::uint16_t>((receive ? 0x1400 : 0x1800) + number - 1);
  }
  [[nodiscard]] std::uint16_t mapping_index() const noexcept {
    return static_cast<std::uint16_t>((receive ? 0x1600 : 0x1A00) + number - 1);
  }
};

class Description {
 public:
  [[nodiscard]] const std::vector<Entry>& entries() const noexcept { return entries_; }
  [[nodiscard]] const Entry* find(std::uint16_t index, std::uint8_t sub) const noexcept;
  [[nodiscard]] bool has(std::uint16_t index) const noexcept;
  [[nodiscard]] const DeviceInfo& device() const noexcept { return device_; }
  // The indices the object lists ([Mandatory|Optional|ManufacturerObjects]) name, in file order.
  [[nodiscard]] const std::vector<std::uint16_t>& listed() const noexcept { return listed_; }
  // Settle's own mark, a section other tools ignore: [SettleDrive] says the dictionary is
  // Settle's simulated drive (hal's DriveNode), whose manufacturer objects are Settle's (0x2001
  // communication loss periods); its LoadPosition=INDEX:SUB names the object that measures the
  // load (0x2000:0 on that drive), read strictly: described, INTEGER32, readable and mappable.
  [[nodiscard]] bool settle_drive() const noexcept { return settle_drive_; }
  [[nodiscard]] const std::optional<MappedObject>& load_position() const noexcept { return load_position_; }
  // A DCF's [DeviceComissioning] NodeID, when it has one.
  [[nodiscard]] std::optional<std::uint8_t> dcf_node_id() const noexcept { return dcf_node_id_; }
  // The PDOs whose communication and mapping objects are both described, by number.
  // Values with $NODEID are resolved for `node`.
  [[nodiscard]] std::vector<Pdo> rpdos(std::uint8_t node) const;
  [[nodiscard]] std::vector<Pdo> tpdos(std::uint8_t node) const;

 private:
  friend struct Builder;
  std::vector<Entry> entries_;  // sorted by (index, sub), unique
  DeviceInfo device_;
  std::vector<std::uint16_t> listed_;
  std::optional<std::uint8_t> dcf_node_id_;
  bool settle_drive_{false};
  std::optional<MappedObject> load_position_;  // bits: 32
};

struct LoadResult {
  std::optional<Description> description;
  std::string error;  // why not: to_string(refusal), after the file's path when load() read it
  Problem refusal;    // the same, by part
  // What was read otherwise than written (a SubNumber that does not match the sub-index
  // sections, a limit dropped from an object the master does not write, ...), in file order;
  // also when the file is refused. Callers print them: the file is read, but should be fixed.
  std::vector<Problem> warnings;
};

// Reads an EDS or DCF file (within the bounds above).
[[nodiscard]] LoadResult load(const std::string& path);
// The same from text held in memory (tests, descriptions received over SDO 0x1021).
[[nodiscard]] LoadResult parse(std::string_view text);

// An EDS integer as CiA 306 writes it: decimal, 0x hex, leading-0 octal, optionally with a
// sign, or $NODEID+value / value+$NODEID. nullopt when the text is none of these.
[[nodiscard]] std::optional<std::int64_t> parse_integer(std::string_view text, std::uint8_t node);

}  // namespace settle::hal::eds
