// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include <array>
#include <new>

#include "frame_helpers.hpp"
#include "settle/hal/can_frame.hpp"

namespace settle::hal {
namespace {

TEST(CanFrame, DlcAndLengthConvertBothWaysForEveryFdLength) {
  for (std::uint8_t dlc = 0; dlc < 16; ++dlc) {
    EXPECT_EQ(can_len_to_dlc(can_dlc_to_len(dlc)), dlc);
  }
  EXPECT_EQ(can_len_to_dlc(9), 9);    // 9 bytes need the 12-byte DLC
  EXPECT_EQ(can_len_to_dlc(33), 14);  // 48
  EXPECT_EQ(can_dlc_to_len(15), 64);
}

TEST(CanFrame, ValidityFollowsFormatRules) {
  CanFrame f{};
  f.id = 0x7FF;
  f.len = 8;
  EXPECT_TRUE(is_valid(f));
  f.id = 0x800;
  EXPECT_FALSE(is_valid(f)) << "11-bit id out of range";
  f.flags = can_flag::extended;
  EXPECT_TRUE(is_valid(f));
  f.id = 0x2000'0000;
  EXPECT_FALSE(is_valid(f)) << "29-bit id out of range";

  CanFrame classic{};
  classic.len = 9;
  EXPECT_FALSE(is_valid(classic)) << "classic frames carry at most 8 bytes";
  classic.flags = can_flag::fd;
  EXPECT_FALSE(is_valid(classic)) << "9 is not an FD length";
  classic.len = 12;
  EXPECT_TRUE(is_valid(classic));
  classic.flags = can_flag::fd | can_flag::rtr;
  EXPECT_FALSE(is_valid(classic)) << "FD has no remote frames";

  CanFrame brs_on_classic{};
  brs_on_classic.flags = can_flag::brs;
  EXPECT_FALSE(is_valid(brs_on_classic));
  CanFrame unknown_flag{};
  unknown_flag.flags = 0x80;
  EXPECT_FALSE(is_valid(unknown_flag));
}

TEST(CanFrame, EqualityIgnoresTimestampAndBytesBeyondLength) {
  CanFrame a = test::frame(0x123, {1, 2, 3});
  CanFrame b = a;
  b.timestamp_us = 42;
  b.data[5] = 0xAA;
  EXPECT_EQ(a, b);
  b.data[2] = 4;
  EXPECT_NE(a, b);
}

TEST(CanFrame, RemoteFrameCarriesNoPayload) {
  CanFrame f{};
  f.flags = can_flag::rtr;
  f.len = 4;
  f.data[0] = 9;
  EXPECT_TRUE(f.payload().empty());
  EXPECT_TRUE(is_valid(f));
}

// `CanFrame f{}` (every aggregate initialization) still clears all 64 payload bytes; only
// `CanFrame f;` leaves them to the writer (classic_frame).
TEST(CanFrame, ValueInitializationClearsTheWholePayload) {
  alignas(CanFrame) std::array<unsigned char, sizeof(CanFrame)> storage{};
  storage.fill(0xA5);
  const CanFrame* f = new (storage.data()) CanFrame{};
  EXPECT_EQ(f->id, 0U);
  EXPECT_EQ(f->flags, 0);
  EXPECT_EQ(f->len, 0);
  EXPECT_EQ(f->timestamp_us, 0U);
  for (const auto b : f->data) EXPECT_EQ(b, 0);
}

// classic_frame() does not clear the 56 bytes only an FD frame carries, but it writes the whole
// classic frame, whatever the storage held before: id, no flags, len, no timestamp, eight zeros.
TEST(CanFrame, ClassicFrameWritesTheWholeClassicFrameOverAnyStorage) {
  alignas(CanFrame) std::array<unsigned char, sizeof(CanFrame)> storage{};
  storage.fill(0xA5);
  const CanFrame* f = new (storage.data()) CanFrame(classic_frame(0x601, 8));
  EXPECT_EQ(f->id, 0x601U);
  EXPECT_EQ(f->flags, 0);
  EXPECT_EQ(f->len, 8);
  EXPECT_EQ(f->timestamp_us, 0U);
  for (std::size_t i = 0; i < can_classic_max_len; ++i) EXPECT_EQ(f->data[i], 0) << "byte " << i;
  EXPECT_TRUE(is_valid(*f));
  EXPECT_EQ(*f, test::frame(0x601, {0, 0, 0, 0, 0, 0, 0, 0}));
}

TEST(CanFrame, MakeFrameSwitchesToFdAboveEightBytes) {
  std::vector<std::uint8_t> twelve(12, 0x5A);
  const CanFrame f = make_frame(0x10, twelve);
  EXPECT_TRUE(f.is_fd());
  EXPECT_EQ(f.len, 12);
  EXPECT_TRUE(is_valid(f));
}

}  // namespace
}  // namespace settle::hal
