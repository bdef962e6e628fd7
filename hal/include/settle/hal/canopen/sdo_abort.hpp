// SPDX-License-Identifier: Apache-2.0
// The standard SDO abort codes (CiA 301 table 22). Object dictionary accesses return one of
// these directly, so the SDO server can put the reason on the wire without translating.
#pragma once

#include <array>
#include <cstdint>

namespace settle::hal::canopen {

enum class SdoAbort : std::uint32_t {
  none = 0,  // success: not an abort code on the wire
  toggle_bit = 0x0503'0000,
  timeout = 0x0504'0000,
  unknown_command = 0x0504'0001,
  invalid_block_size = 0x0504'0002,
  invalid_sequence = 0x0504'0003,
  crc_error = 0x0504'0004,
  out_of_memory = 0x0504'0005,
  unsupported_access = 0x0601'0000,
  write_only = 0x0601'0001,
  read_only = 0x0601'0002,
  no_object = 0x0602'0000,
  not_mappable = 0x0604'0041,
  pdo_too_long = 0x0604'0042,
  parameter_incompatible = 0x0604'0043,
  internal_incompatible = 0x0604'0047,
  hardware_error = 0x0606'0000,
  length_mismatch = 0x0607'0010,
  length_too_high = 0x0607'0012,
  length_too_low = 0x0607'0013,
  no_sub_index = 0x0609'0011,
  invalid_value = 0x0609'0030,
  value_too_high = 0x0609'0031,
  value_too_low = 0x0609'0032,
  max_below_min = 0x0609'0036,
  no_resource = 0x060A'0023,
  general_error = 0x0800'0000,
  cannot_store = 0x0800'0020,
  cannot_store_local_control = 0x0800'0021,
  cannot_store_device_state = 0x0800'0022,
  no_dictionary = 0x0800'0023,
  no_data = 0x0800'0024,
};

// Every standard code (CiA 301 table 22). is_known_abort searches it: a 31-case switch took
// 176 B of the Cortex-M4F's one-axis image (servo_size), the table and its loop 36 B less.
inline constexpr std::array<SdoAbort, 31> standard_aborts{
    SdoAbort::toggle_bit, SdoAbort::timeout, SdoAbort::unknown_command, SdoAbort::invalid_block_size,
    SdoAbort::invalid_sequence, SdoAbort::crc_error, SdoAbort::out_of_memory, SdoAbort::unsupported_access,
    SdoAbort::write_only, SdoAbort::read_only, SdoAbort::no_object, SdoAbort::not_mappable,
    SdoAbort::pdo_too_long, SdoAbort::parameter_incompatible, SdoAbort::internal_incompatible,
    SdoAbort::hardware_error, SdoAbort::length_mismatch, SdoAbort::length_too_high, SdoAbort::length_too_low,
    SdoAbort::no_sub_index, SdoAbort::invalid_value, SdoAbort::value_too_high, SdoAbort::value_too_low,
    SdoAbort::max_below_min, SdoAbort::no_resource, SdoAbort::general_error, SdoAbort::cannot_store,
    SdoAbort::cannot_store_local_control, SdoAbort::cannot_store_device_state, SdoAbort::no_dictionary,
    SdoAbort::no_data};

[[nodiscard]] constexpr bool is_known_abort(std::uint32_t code) noexcept {
  for (const SdoAbort a : standard_aborts) {
    if (static_cast<std::uint32_t>(a) == code) {
      return true;
    }
  }
  return false;
}

// The meaning CiA 301 gives each code (table 22), for people reading an abort; "unknown abort
// code" for one outside the standard set.
[[nodiscard]] constexpr const char* abort_meaning(std::uint32_t code) noexcept {
  switch (static_cast<SdoAbort>(code)) {
    case SdoAbort::toggle_bit: return "toggle bit not alternated";
    case SdoAbort::timeout: return "SDO protocol timed out";
    case SdoAbort::unknown_command: return "client/server command specifier not valid or unknown";
    case SdoAbort::invalid_block_size: return "invalid block size (block mode only)";
    case SdoAbort::invalid_sequence: return "invalid sequence number (block mode only)";
    case SdoAbort::crc_error: return "CRC error (block mode only)";
    case SdoAbort::out_of_memory: return "out of memory";
    case SdoAbort::unsupported_access: return "unsupported access to an object";
    case SdoAbort::write_only: return "attempt to read a write only object";
    case SdoAbort::read_only: return "attempt to write a read only object";
    case SdoAbort::no_object: return "object does not exist in the object dictionary";
    case SdoAbort::not_mappable: return "object cannot be mapped to the PDO";
    case SdoAbort::pdo_too_long: return "the number and length of the objects to be mapped would exceed the PDO length";
    case SdoAbort::parameter_incompatible: return "general parameter incompatibility reason";
    case SdoAbort::internal_incompatible: return "general internal incompatibility in the device";
    case SdoAbort::hardware_error: return "access failed due to a hardware error";
    case SdoAbort::length_mismatch: return "data type does not match, length of service parameter does not match";
    case SdoAbort::length_too_high: return "data type does not match, length of service parameter too high";
    case SdoAbort::length_too_low: return "data type does not match, length of service parameter too low";
    case SdoAbort::no_sub_index: return "sub-index does not exist";
    case SdoAbort::invalid_value: return "invalid value for parameter (download only)";
    case SdoAbort::value_too_high: return "value of parameter written too high (download only)";
    case SdoAbort::value_too_low: return "value of parameter written too low (download only)";
    case SdoAbort::max_below_min: return "maximum value is less than minimum value";
    case SdoAbort::no_resource: return "resource not available: SDO connection";
    case SdoAbort::general_error: return "general error";
    case SdoAbort::cannot_store: return "data cannot be transferred or stored to the application";
    case SdoAbort::cannot_store_local_control:
      return "data cannot be transferred or stored to the application because of local control";
    case SdoAbort::cannot_store_device_state:
      return "data cannot be transferred or stored to the application because of the present device state";
    case SdoAbort::no_dictionary: return "object dictionary dynamic generation fails or no object dictionary is present";
    case SdoAbort::no_data: return "no data available";
    case SdoAbort::none: break;
  }
  return "unknown abort code";
}

}  // namespace settle::hal::canopen
