// SPDX-License-Identifier: Apache-2.0
// Helpers for hal tests: build frames from byte lists and print them readably on failure.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <ostream>
#include <string>
#include <vector>

#include "settle/hal/can_frame.hpp"

namespace settle::hal {

// gtest prints this when two frames differ.
inline void PrintTo(const CanFrame& f, std::ostream* os) {
  static const char* hex = "0123456789ABCDEF";
  *os << "id=0x" << std::hex << f.id << std::dec << " flags=" << int{f.flags} << " len=" << int{f.len} << " [";
  for (const auto b : f.payload()) {
    *os << ' ' << hex[b >> 4U] << hex[b & 0xFU];
  }
  *os << " ]";
}

}  // namespace settle::hal

namespace settle::hal::test {

inline CanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  const std::vector<std::uint8_t> v{bytes};
  return make_frame(id, v);
}

inline std::vector<std::uint8_t> bytes_of(const CanFrame& f) {
  const auto p = f.payload();
  return {p.begin(), p.end()};
}

}  // namespace settle::hal::test
