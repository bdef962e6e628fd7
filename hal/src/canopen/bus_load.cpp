// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/bus_load.hpp"

namespace settle::hal::canopen {

CyclicLoad cyclic_load(const ProcessDataLayout& layout, std::uint32_t axes) noexcept {
  CyclicLoad load{1, classic_frame_bits(0, true), classic_frame_bits(0, false)};  // the SYNC
  for (const bool receive : {true, false}) {
    for (std::uint8_t number = 1; number <= layout_pdo_count; ++number) {
      const std::uint8_t len = layout_pdo_length(layout, receive, number);
      if (len == 0) continue;  // a PDO the layout does not use is not sent
      load.frames += axes;
      load.bits_worst_case += axes * classic_frame_bits(len, true);
      load.bits_unstuffed += axes * classic_frame_bits(len, false);
    }
  }
  return load;
}

}  // namespace settle::hal::canopen
