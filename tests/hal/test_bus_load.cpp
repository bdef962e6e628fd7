// SPDX-License-Identifier: Apache-2.0
// Bus load of cyclic streaming: the frame-length formula against a hand count of the fields and
// against frames built bit by bit (identifier, control, data, CRC-15) and stuffed as a CAN
// controller stuffs them; the cyclic load of Settle's default mapping for one to three axes.
#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <random>
#include <vector>

#include "settle/hal/canopen/bus_load.hpp"
#include "settle/hal/canopen/default_mapping.hpp"

namespace settle::hal::canopen {
namespace {

// The fields of an 11-bit-identifier data frame, counted one by one (ISO 11898-1).
std::uint32_t hand_count(std::uint32_t n) {
  const std::uint32_t sof = 1, id = 11, rtr = 1, ide = 1, r0 = 1, dlc = 4, crc = 15;
  const std::uint32_t crc_delimiter = 1, ack_slot = 1, ack_delimiter = 1, eof = 7, intermission = 3;
  return sof + id + rtr + ide + r0 + dlc + 8 * n + crc + crc_delimiter + ack_slot + ack_delimiter + eof + intermission;
}

void push(std::vector<int>& bits, std::uint32_t value, int width) {
  for (int i = width - 1; i >= 0; --i) bits.push_back(static_cast<int>((value >> i) & 1U));
}

// The stuff bits a transmitter inserts into the frame: SOF through CRC, a complementary bit after
// every five equal bits (the stuff bit itself starting the next run).
std::uint32_t stuff_bits(std::uint32_t id, const std::vector<std::uint8_t>& data) {
  std::vector<int> bits;
  push(bits, 0, 1);  // SOF (dominant)
  push(bits, id, 11);
  push(bits, 0, 3);  // RTR, IDE, r0
  push(bits, static_cast<std::uint32_t>(data.size()), 4);
  for (const std::uint8_t b : data) push(bits, b, 8);
  std::uint32_t crc = 0;  // CRC-15/CAN, polynomial 0x4599, over SOF .. data
  for (const int b : bits) {
    const std::uint32_t next = static_cast<std::uint32_t>(b) ^ ((crc >> 14) & 1U);
    crc = (crc << 1) & 0x7FFFU;
    if (next != 0) crc ^= 0x4599U;
  }
  push(bits, crc, 15);
  EXPECT_EQ(bits.size(), 34 + 8 * data.size());
  std::uint32_t stuffed = 0;
  int last = -1, run = 0;
  for (const int b : bits) {
    run = b == last ? run + 1 : 1;
    last = b;
    if (run == 5) {
      ++stuffed;
      last = 1 - b;
      run = 1;
    }
  }
  return stuffed;
}

TEST(BusLoad, FrameBitsAreTheHandCountOfTheFields) {
  for (std::uint8_t n = 0; n <= 8; ++n) {
    EXPECT_EQ(classic_frame_bits(n, false), hand_count(n)) << int{n};
  }
  EXPECT_EQ(classic_frame_bits(0, false), 47U);
  EXPECT_EQ(classic_frame_bits(6, false), 95U);
  EXPECT_EQ(classic_frame_bits(8, false), 111U);
  // Worst-case stuffing: 55, 115 and 135 bits.
  EXPECT_EQ(classic_frame_bits(0, true), 55U);
  EXPECT_EQ(classic_frame_bits(6, true), 115U);
  EXPECT_EQ(classic_frame_bits(8, true), 135U);
}

// No frame needs more stuff bits than the worst case allows: random frames, and those that stuff
// most (long runs of one value, and the alternating runs of four the bound is built on).
TEST(BusLoad, NoFrameStuffsMoreThanTheWorstCase) {
  std::mt19937 rng(17);
  std::uint32_t most[9] = {};
  auto check = [&](std::uint32_t id, const std::vector<std::uint8_t>& data) {
    const auto n = static_cast<std::uint8_t>(data.size());
    const std::uint32_t s = stuff_bits(id, data);
    EXPECT_LE(classic_frame_bits(n, false) + s, classic_frame_bits(n, true)) << "id " << id << ", " << int{n} << " bytes";
    if (s > most[n]) most[n] = s;
  };
  for (int k = 0; k < 20000; ++k) {
    std::vector<std::uint8_t> data(rng() % 9);
    for (auto& b : data) b = static_cast<std::uint8_t>(rng());
    check(rng() & 0x7FFU, data);
  }
  const std::initializer_list<std::uint8_t> fills{0x00, 0xFF, 0x0F, 0xF0, 0x3C, 0xC3, 0x78, 0x87, 0x1E, 0xE1};
  for (const std::uint8_t fill : fills) {
    for (std::uint32_t id = 0; id < 0x800; ++id) {
      for (std::size_t n = 0; n <= 8; ++n) check(id, std::vector<std::uint8_t>(n, fill));
    }
  }
  // The search comes within a few bits of the bound: it is not loose by a wide margin.
  for (std::uint8_t n = 0; n <= 8; ++n) {
    EXPECT_GE(most[n] + 6, classic_frame_bits(n, true) - classic_frame_bits(n, false)) << int{n};
  }
}

// Settle's default mapping: RPDO1 6 bytes, TPDO1 6, TPDO2 8, and the SYNC.
TEST(BusLoad, DefaultMappingPerAxis) {
  const ProcessDataLayout l{};
  const CyclicLoad one = cyclic_load(l, 1);
  EXPECT_EQ(one.frames, 4U);
  EXPECT_EQ(one.bits_unstuffed, 47U + 95U + 95U + 111U);
  EXPECT_EQ(one.bits_worst_case, 55U + 115U + 115U + 135U);
  const CyclicLoad three = cyclic_load(l, 3);
  EXPECT_EQ(three.frames, 10U);
  EXPECT_EQ(three.bits_unstuffed, 950U);    // fits 1 ms at 1 Mbit/s without stuffing ...
  EXPECT_EQ(three.bits_worst_case, 1150U);  // ... not in the worst case
  EXPECT_EQ(cyclic_load(l, 2).bits_worst_case, 785U);
  // A layout with following error in TPDO3 (4 bytes) adds that frame to every axis.
  ProcessDataLayout fe{};
  fe.following_error = PdoSlot{3, 0, 4};
  EXPECT_EQ(cyclic_load(fe, 1).bits_worst_case, 420U + classic_frame_bits(4, true));
  EXPECT_EQ(bits_per_period(1'000'000, 1000), 1000U);
  EXPECT_EQ(bits_per_period(125'000, 1000), 125U);
  EXPECT_EQ(bits_per_period(1'000'000, 100'000), 100'000U);
}

}  // namespace
}  // namespace settle::hal::canopen
