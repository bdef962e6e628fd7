// SPDX-License-Identifier: Apache-2.0
// ProcessDataLayout: the default is Settle's mapping, what check_layout refuses, the mapping a
// layout gives each PDO, a static mapping read entry by entry, and the generic codecs.
#include <gtest/gtest.h>

#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/process_data.hpp"

namespace settle::hal::canopen {
namespace {

constexpr NodeId node = 5;

bool same(const PdoMapping& a, const PdoMapping& b) {
  if (a.cob_id != b.cob_id || a.transmission_type != b.transmission_type || a.count != b.count) return false;
  for (std::size_t i = 0; i < a.count; ++i) {
    if (a.entries[i].raw() != b.entries[i].raw()) return false;
  }
  return true;
}

TEST(ProcessDataLayout, TheDefaultIsSettlesMapping) {
  const ProcessDataLayout l{};
  EXPECT_TRUE(is_default_layout(l));
  EXPECT_EQ(check_layout(l, true), LayoutError::none);
  EXPECT_TRUE(same(layout_mapping(l, true, 1, node), default_rpdo1_mapping(node)));
  EXPECT_TRUE(same(layout_mapping(l, false, 1, node), default_tpdo1_mapping(node)));
  EXPECT_TRUE(same(layout_mapping(l, false, 2, node), default_tpdo2_mapping(node)));
  EXPECT_EQ(layout_mapping(l, true, 2, node).count, 0U);
  EXPECT_EQ(layout_mapping(l, false, 3, node).count, 0U);
  EXPECT_EQ(layout_pdo_length(l, false, 1), tpdo1_len);
  EXPECT_EQ(layout_pdo_length(l, false, 2), tpdo2_len);
  EXPECT_EQ(pdo_cob_id(true, 2, node), 0x305U);
  EXPECT_EQ(pdo_cob_id(false, 4, node), 0x485U);
}

TEST(ProcessDataLayout, WhatCannotStreamIsRefusedWithItsReason) {
  ProcessDataLayout l{};
  l.target_position = PdoSlot{};
  EXPECT_EQ(check_layout(l, false), LayoutError::missing);
  l = ProcessDataLayout{};
  l.target_position = PdoSlot{2, 0, 4};
  EXPECT_EQ(check_layout(l, false), LayoutError::split) << "controlword and target in one RPDO";
  l = ProcessDataLayout{};
  l.position_actual = PdoSlot{3, 0, 4};
  EXPECT_EQ(check_layout(l, false), LayoutError::none) << "a period's feedback may come in several TPDOs";
  l = ProcessDataLayout{};
  l.velocity_actual = PdoSlot{2, 2, 4};
  EXPECT_EQ(check_layout(l, false), LayoutError::overlap);
  l = ProcessDataLayout{};
  l.velocity_actual = PdoSlot{2, 6, 4};
  EXPECT_EQ(check_layout(l, false), LayoutError::too_long);
  l = ProcessDataLayout{};
  l.velocity_actual = PdoSlot{2, 4, 2};
  EXPECT_EQ(check_layout(l, false), LayoutError::bad_slot) << "0x606C is 32 bits";
  l = ProcessDataLayout{};
  l.following_error = PdoSlot{5, 0, 4};
  EXPECT_EQ(check_layout(l, false), LayoutError::bad_slot) << "TPDO5 is not in the predefined set";
  l = ProcessDataLayout{};
  l.load_position = PdoSlot{};
  EXPECT_EQ(check_layout(l, false), LayoutError::none);
  EXPECT_EQ(check_layout(l, true), LayoutError::gap) << "velocity at byte 4 of TPDO2 with nothing before it";
}

// A drive's static mapping, read entry by entry: RPDO1 = controlword alone, RPDO2 = controlword +
// target position, TPDO1 = statusword + mode display (0x6061) + position actual.
TEST(ProcessDataLayout, AStaticMappingIsPlacedWhereItsPartnersAre) {
  ProcessDataLayout l = empty_layout(ProcessDataLayout{});
  EXPECT_TRUE(place_mapped_object(l, true, 1, 0, 0x6040'0010));
  EXPECT_TRUE(place_mapped_object(l, true, 2, 0, 0x6040'0010));
  EXPECT_TRUE(place_mapped_object(l, true, 2, 2, 0x607A'0020));
  EXPECT_TRUE(place_mapped_object(l, false, 1, 0, 0x6041'0010));
  EXPECT_TRUE(place_mapped_object(l, false, 1, 2, 0x6061'0008)) << "a TPDO may carry more";
  EXPECT_TRUE(place_mapped_object(l, false, 1, 3, 0x6064'0020));
  EXPECT_EQ(l.controlword, (PdoSlot{2, 0, 2}));
  EXPECT_EQ(l.target_position, (PdoSlot{2, 2, 4}));
  EXPECT_EQ(l.position_actual, (PdoSlot{1, 3, 4}));
  EXPECT_EQ(check_layout(l, false), LayoutError::none);
  EXPECT_EQ(check_layout(l, true), LayoutError::gap);
  EXPECT_FALSE(place_mapped_object(l, true, 3, 0, 0x6060'0008)) << "the master cannot fill a mode in an RPDO";
  EXPECT_FALSE(place_mapped_object(l, true, 3, 1, 0x0005'0008)) << "nor a dummy entry";
}

// A static mapping that splits the feedback (a real drive's: TPDO1 = statusword + velocity actual,
// TPDO2 = position actual): placed as the drive maps it, valid, and its period spans both TPDOs.
// A PDO's mapping entries placed one after the other, as start-up reads them.
bool place_pdo(ProcessDataLayout& l, bool receive, std::uint8_t number, std::initializer_list<std::uint32_t> entries) {
  std::uint8_t at = 0;
  bool all = true;
  for (const std::uint32_t e : entries) {
    all = place_mapped_object(l, receive, number, at, e) && all;
    at = static_cast<std::uint8_t>(at + (e & 0xFFU) / 8U);
  }
  return all;
}

TEST(ProcessDataLayout, AStaticMappingMaySplitTheFeedbackAcrossTpdos) {
  ProcessDataLayout l = empty_layout(ProcessDataLayout{});
  EXPECT_TRUE(place_pdo(l, true, 1, {0x6040'0010, 0x607A'0020}));
  EXPECT_TRUE(place_pdo(l, false, 1, {0x6041'0010, 0x606C'0020}));
  EXPECT_TRUE(place_pdo(l, false, 2, {0x6064'0020}));
  EXPECT_EQ(l.statusword, (PdoSlot{1, 0, 2}));
  EXPECT_EQ(l.velocity_actual, (PdoSlot{1, 2, 4}));
  EXPECT_EQ(l.position_actual, (PdoSlot{2, 0, 4}));
  EXPECT_EQ(check_layout(l, false), LayoutError::none);
  EXPECT_TRUE(feedback_split(l));
  EXPECT_EQ(feedback_tpdos(l), 0b11U);
  EXPECT_FALSE(feedback_split(ProcessDataLayout{})) << "Settle's own: statusword and position in TPDO1";
  EXPECT_EQ(feedback_tpdos(ProcessDataLayout{}), 0b11U) << "TPDO2: load position and velocity";
}

TEST(ProcessDataLayout, TheGenericCodecsFollowTheLayout) {
  ProcessDataLayout l{};
  l.controlword = PdoSlot{2, 4, 2};
  l.target_position = PdoSlot{2, 0, 4};
  l.statusword = PdoSlot{3, 4, 2};
  l.position_actual = PdoSlot{3, 0, 4};
  l.load_position = PdoSlot{};
  l.velocity_actual = PdoSlot{1, 0, 4};
  l.following_error = PdoSlot{1, 4, 4};
  ASSERT_EQ(check_layout(l, true), LayoutError::none);
  CanFrame rpdo{};
  rpdo.data.fill(0xEE);
  encode_layout_rpdo(l, node, 0x000F, -2, rpdo);
  EXPECT_EQ(rpdo.id, 0x305U);
  EXPECT_EQ(rpdo.len, 6U);
  EXPECT_EQ(rpdo.flags, 0U);
  EXPECT_EQ((std::array<std::uint8_t, 8>{rpdo.data[0], rpdo.data[1], rpdo.data[2], rpdo.data[3], rpdo.data[4],
                                         rpdo.data[5], rpdo.data[6], rpdo.data[7]}),
            (std::array<std::uint8_t, 8>{0xFE, 0xFF, 0xFF, 0xFF, 0x0F, 0x00, 0, 0}));
  const CanFrame t3 = make_frame(0x385, std::array<std::uint8_t, 6>{0x10, 0x27, 0, 0, 0x37, 0x12});
  EXPECT_TRUE(slot_carried(l.statusword, 3, t3));
  EXPECT_EQ(slot_value(l.statusword, t3), 0x1237U);
  EXPECT_EQ(slot_value(l.position_actual, t3), 10'000U);
  EXPECT_FALSE(slot_carried(l.velocity_actual, 3, t3)) << "TPDO1's";
  const CanFrame t1 = make_frame(0x185, std::array<std::uint8_t, 8>{0x9C, 0xFF, 0xFF, 0xFF, 3, 0, 0, 0});
  EXPECT_TRUE(slot_carried(l.following_error, 1, t1));
  EXPECT_EQ(static_cast<std::int32_t>(slot_value(l.velocity_actual, t1)), -100);
  EXPECT_EQ(slot_value(l.following_error, t1), 3U);
  const CanFrame short_t1 = make_frame(0x185, std::array<std::uint8_t, 6>{0x9C, 0xFF, 0xFF, 0xFF, 3, 0});
  EXPECT_FALSE(slot_carried(l.following_error, 1, short_t1)) << "past the frame's bytes";
}

}  // namespace
}  // namespace settle::hal::canopen
