// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/standard_objects.hpp"

namespace settle::hal::canopen {
namespace {

struct Row {
  std::uint16_t first, last;  // index range
  std::uint8_t sub_first, sub_last;
  StandardObject object;
};

constexpr const char* k301 = "CiA 301";
constexpr const char* k402 = "CiA 402";

// Sorted by index; within a record, sub 0 (the number of entries) is UNSIGNED8.
constexpr Row kRows[] = {
    {0x1000, 0x1000, 0, 0, {OdType::u32, "device type", k301}},
    {0x1001, 0x1001, 0, 0, {OdType::u8, "error register", k301}},
    {0x1005, 0x1005, 0, 0, {OdType::u32, "COB-ID SYNC", k301}},
    {0x1006, 0x1006, 0, 0, {OdType::u32, "communication cycle period", k301}},
    {0x1007, 0x1007, 0, 0, {OdType::u32, "synchronous window length", k301}},
    {0x1008, 0x1008, 0, 0, {OdType::visible_string, "manufacturer device name", k301}},
    {0x1009, 0x1009, 0, 0, {OdType::visible_string, "manufacturer hardware version", k301}},
    {0x100A, 0x100A, 0, 0, {OdType::visible_string, "manufacturer software version", k301}},
    {0x100C, 0x100C, 0, 0, {OdType::u16, "guard time", k301}},
    {0x100D, 0x100D, 0, 0, {OdType::u8, "life time factor", k301}},
    {0x1014, 0x1014, 0, 0, {OdType::u32, "COB-ID EMCY", k301}},
    {0x1015, 0x1015, 0, 0, {OdType::u16, "inhibit time EMCY", k301}},
    {0x1016, 0x1016, 0, 0, {OdType::u8, "consumer heartbeat time: number of entries", k301}},
    {0x1016, 0x1016, 1, 127, {OdType::u32, "consumer heartbeat time", k301}},
    {0x1017, 0x1017, 0, 0, {OdType::u16, "producer heartbeat time", k301}},
    {0x1018, 0x1018, 0, 0, {OdType::u8, "identity: number of entries", k301}},
    {0x1018, 0x1018, 1, 4, {OdType::u32, "identity (vendor id, product code, revision, serial number)", k301}},
    {0x1019, 0x1019, 0, 0, {OdType::u8, "synchronous counter overflow value", k301}},
    {0x1200, 0x1200, 0, 0, {OdType::u8, "SDO server parameter: number of entries", k301}},
    {0x1200, 0x1200, 1, 2, {OdType::u32, "SDO server COB-ID", k301}},
    {0x1200, 0x1200, 3, 3, {OdType::u8, "SDO server node id of the client", k301}},
    // RPDO communication (0x1400..0x15FF) and TPDO communication (0x1800..0x19FF) share a layout.
    {0x1400, 0x15FF, 0, 0, {OdType::u8, "RPDO communication parameter: highest sub-index", k301}},
    {0x1400, 0x15FF, 1, 1, {OdType::u32, "RPDO COB-ID", k301}},
    {0x1400, 0x15FF, 2, 2, {OdType::u8, "RPDO transmission type", k301}},
    {0x1400, 0x15FF, 3, 3, {OdType::u16, "RPDO inhibit time", k301}},
    {0x1400, 0x15FF, 5, 5, {OdType::u16, "RPDO event timer", k301}},
    {0x1600, 0x17FF, 0, 0, {OdType::u8, "RPDO mapping: number of mapped objects", k301}},
    {0x1600, 0x17FF, 1, 64, {OdType::u32, "RPDO mapping entry", k301}},
    {0x1800, 0x19FF, 0, 0, {OdType::u8, "TPDO communication parameter: highest sub-index", k301}},
    {0x1800, 0x19FF, 1, 1, {OdType::u32, "TPDO COB-ID", k301}},
    {0x1800, 0x19FF, 2, 2, {OdType::u8, "TPDO transmission type", k301}},
    {0x1800, 0x19FF, 3, 3, {OdType::u16, "TPDO inhibit time", k301}},
    {0x1800, 0x19FF, 5, 5, {OdType::u16, "TPDO event timer", k301}},
    {0x1800, 0x19FF, 6, 6, {OdType::u8, "TPDO SYNC start value", k301}},
    {0x1A00, 0x1BFF, 0, 0, {OdType::u8, "TPDO mapping: number of mapped objects", k301}},
    {0x1A00, 0x1BFF, 1, 64, {OdType::u32, "TPDO mapping entry", k301}},
    {0x6007, 0x6007, 0, 0, {OdType::i16, "abort connection option code", k402}},
    {0x603F, 0x603F, 0, 0, {OdType::u16, "error code", k402}},
    {0x6040, 0x6040, 0, 0, {OdType::u16, "controlword", k402}},
    {0x6041, 0x6041, 0, 0, {OdType::u16, "statusword", k402}},
    {0x605A, 0x605A, 0, 0, {OdType::i16, "quick stop option code", k402}},
    {0x605B, 0x605B, 0, 0, {OdType::i16, "shutdown option code", k402}},
    {0x605C, 0x605C, 0, 0, {OdType::i16, "disable operation option code", k402}},
    {0x605D, 0x605D, 0, 0, {OdType::i16, "halt option code", k402}},
    {0x605E, 0x605E, 0, 0, {OdType::i16, "fault reaction option code", k402}},
    {0x6060, 0x6060, 0, 0, {OdType::i8, "modes of operation", k402}},
    {0x6061, 0x6061, 0, 0, {OdType::i8, "modes of operation display", k402}},
    {0x6062, 0x6062, 0, 0, {OdType::i32, "position demand value", k402}},
    {0x6063, 0x6063, 0, 0, {OdType::i32, "position actual internal value", k402}},
    {0x6064, 0x6064, 0, 0, {OdType::i32, "position actual value", k402}},
    {0x6065, 0x6065, 0, 0, {OdType::u32, "following error window", k402}},
    {0x6066, 0x6066, 0, 0, {OdType::u16, "following error time out", k402}},
    {0x6067, 0x6067, 0, 0, {OdType::u32, "position window", k402}},
    {0x6068, 0x6068, 0, 0, {OdType::u16, "position window time", k402}},
    {0x606C, 0x606C, 0, 0, {OdType::i32, "velocity actual value", k402}},
    {0x607A, 0x607A, 0, 0, {OdType::i32, "target position", k402}},
    {0x607C, 0x607C, 0, 0, {OdType::i32, "home offset", k402}},
    {0x607D, 0x607D, 0, 0, {OdType::u8, "software position limit: highest sub-index", k402}},
    {0x607D, 0x607D, 1, 2, {OdType::i32, "software position limit", k402}},
    {0x607F, 0x607F, 0, 0, {OdType::u32, "max profile velocity", k402}},
    {0x6081, 0x6081, 0, 0, {OdType::u32, "profile velocity", k402}},
    {0x6083, 0x6083, 0, 0, {OdType::u32, "profile acceleration", k402}},
    {0x6084, 0x6084, 0, 0, {OdType::u32, "profile deceleration", k402}},
    {0x6085, 0x6085, 0, 0, {OdType::u32, "quick stop deceleration", k402}},
    {0x60C2, 0x60C2, 0, 0, {OdType::u8, "interpolation time period: highest sub-index", k402}},
    {0x60C2, 0x60C2, 1, 1, {OdType::u8, "interpolation time period value", k402}},
    {0x60C2, 0x60C2, 2, 2, {OdType::i8, "interpolation time index", k402}},
    {0x60F4, 0x60F4, 0, 0, {OdType::i32, "following error actual value", k402}},
    {0x6502, 0x6502, 0, 0, {OdType::u32, "supported drive modes", k402}},
};

}  // namespace

const StandardObject* find_standard_object(std::uint16_t index, std::uint8_t sub) noexcept {
  for (const Row& r : kRows) {
    if (index >= r.first && index <= r.last && sub >= r.sub_first && sub <= r.sub_last) return &r.object;
  }
  return nullptr;
}

const char* data_type_name(std::uint16_t type, const char* unknown) noexcept {
  switch (type) {
    case 0x0001: return "BOOLEAN";
    case 0x0002: return "INTEGER8";
    case 0x0003: return "INTEGER16";
    case 0x0004: return "INTEGER32";
    case 0x0005: return "UNSIGNED8";
    case 0x0006: return "UNSIGNED16";
    case 0x0007: return "UNSIGNED32";
    case 0x0008: return "REAL32";
    case 0x0009: return "VISIBLE_STRING";
    case 0x000A: return "OCTET_STRING";
    case 0x000B: return "UNICODE_STRING";
    case 0x000F: return "DOMAIN";
    case 0x0011: return "REAL64";
    case 0x0015: return "INTEGER64";
    case 0x001B: return "UNSIGNED64";
    default: return unknown;
  }
}

}  // namespace settle::hal::canopen
