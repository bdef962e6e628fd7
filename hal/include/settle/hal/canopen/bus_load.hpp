// SPDX-License-Identifier: Apache-2.0
// Bus load of cyclic synchronous streaming on classic CAN: how many bits one SYNC period carries
// when the master sends one SYNC and every drive one RPDO and its TPDOs, and whether that fits in
// the period at a bit rate (docs/multi_axis.md, "Bus load").
//
// A classic CAN data frame with an 11-bit identifier and n payload bytes is 47 + 8n bits without
// stuffing: SOF 1, identifier 11, RTR 1, IDE 1, r0 1, DLC 4, data 8n, CRC 15 (the 34 + 8n bits
// that are stuffed), then CRC delimiter 1, ACK slot 1, ACK delimiter 1, EOF 7 and the intermission
// of 3 bits before the next frame. A transmitter inserts a stuff bit after five equal bits in the
// stuffed part; the worst case over all identifiers and data adds floor((34 + 8n - 1) / 4) bits
// (Davis, Burns, Bril, Lukkien, "Controller Area Network (CAN) schedulability analysis: Refuted,
// revisited and revised", Real-Time Systems 35, 2007, eq. 3). 6 bytes: 95 bits, 115 worst case;
// 8 bytes: 111, 135; SYNC (0 bytes): 47, 55.
//
// Freestanding: no heap, no exceptions (hal/CMakeLists.txt).
#pragma once

#include <cstdint>

#include "settle/hal/canopen/process_data.hpp"

namespace settle::hal::canopen {

// Bits on the bus of one classic CAN data frame (11-bit identifier) with `len` payload bytes
// (0..8), intermission included; with `worst_case_stuffing`, plus the most stuff bits its
// identifier and data can need.
[[nodiscard]] constexpr std::uint32_t classic_frame_bits(std::uint8_t len, bool worst_case_stuffing) noexcept {
  const std::uint32_t n = len > 8 ? 8U : len;
  const std::uint32_t unstuffed = 47U + 8U * n;
  return worst_case_stuffing ? unstuffed + (34U + 8U * n - 1U) / 4U : unstuffed;
}

// One SYNC period's cyclic frames: one SYNC, and per axis every RPDO and TPDO the layout uses
// (each as long as the layout makes it). Acyclic frames (heartbeats, EMCY, SDO) are not counted.
struct CyclicLoad {
  std::uint32_t frames{0};
  std::uint32_t bits_worst_case{0};  // with the worst-case stuffing of every frame
  std::uint32_t bits_unstuffed{0};   // without stuffing (the least the frames can take)
};
[[nodiscard]] CyclicLoad cyclic_load(const ProcessDataLayout& layout, std::uint32_t axes) noexcept;

// Bits one period of `period_us` carries at `bitrate` bit/s (rounded down).
[[nodiscard]] constexpr std::uint64_t bits_per_period(std::uint32_t bitrate, std::uint32_t period_us) noexcept {
  return static_cast<std::uint64_t>(bitrate) * period_us / 1'000'000U;
}

}  // namespace settle::hal::canopen
