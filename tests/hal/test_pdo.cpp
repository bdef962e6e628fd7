// SPDX-License-Identifier: Apache-2.0
// Static PDO mapping: the default CSP mapping's bytes, the typed codecs against the generic
// mapping through the drive's dictionary, and whole-or-nothing application of an RPDO.
#include <gtest/gtest.h>

#include <array>
#include <type_traits>
#include <utility>
#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/byte_order.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/pdo.hpp"

namespace settle::hal::canopen {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(DefaultMapping, GoldenBytesAreLittleEndianInMappingOrder) {
  const CanFrame rpdo = encode_rpdo1(2, Rpdo1{0x000F, -2});
  EXPECT_EQ(rpdo.id, 0x202U);
  EXPECT_EQ(test::bytes_of(rpdo), (Bytes{0x0F, 0x00, 0xFE, 0xFF, 0xFF, 0xFF}));
  const CanFrame tpdo1 = encode_tpdo1(2, Tpdo1{0x1237, 0x01020304});
  EXPECT_EQ(tpdo1.id, 0x182U);
  EXPECT_EQ(test::bytes_of(tpdo1), (Bytes{0x37, 0x12, 0x04, 0x03, 0x02, 0x01}));
  const CanFrame tpdo2 = encode_tpdo2(2, Tpdo2{-1, 256});
  EXPECT_EQ(tpdo2.id, 0x282U);
  EXPECT_EQ(test::bytes_of(tpdo2), (Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0x00, 0x01, 0x00, 0x00}));
}

TEST(ByteOrder, AlignedLoadsAndStoresAreTheByteWiseLittleEndianOnes) {
  // load_le/store_le at every offset of a word-aligned buffer whose alignment they may assume,
  // against get_le/put_le byte by byte; and the same at compile time (the portable path).
  alignas(4) std::array<std::uint8_t, 12> buf{};
  // T: the field's type (uint16_t or uint32_t), A: the alignment the call may assume.
  const auto check = [&](auto value, auto align_tag, std::size_t at) {
    using T = decltype(value);
    constexpr std::size_t A = decltype(align_tag)::value;
    buf.fill(0xA5);
    store_le<T, A>(&buf[at], value);
    EXPECT_EQ(get_le(std::span<const std::uint8_t>(&buf[at], sizeof(T)), sizeof(T)), value) << at;
    EXPECT_EQ(buf[at + sizeof(T)], 0xA5) << "nothing past the field";
    EXPECT_EQ(at == 0 ? 0xA5 : buf[at - 1], 0xA5) << "nothing before it";
    EXPECT_EQ((load_le<T, A>(&buf[at])), value) << at;
  };
  using A1 = std::integral_constant<std::size_t, 1>;
  using A2 = std::integral_constant<std::size_t, 2>;
  using A4 = std::integral_constant<std::size_t, 4>;
  for (const std::uint32_t v : {0U, 1U, 0x01020304U, 0x8000'0000U, 0xFFFF'FFFFU, 0xDEAD'BEEFU}) {
    for (std::size_t at = 0; at <= 7; ++at) {
      check(v, A1{}, at);
      check(static_cast<std::uint16_t>(v), A1{}, at);
      if (at % 2 == 0) {
        check(v, A2{}, at);
        check(static_cast<std::uint16_t>(v >> 8U), A2{}, at);
      }
      if (at % 4 == 0) {
        check(v, A4{}, at);
        check(static_cast<std::uint16_t>(v >> 16U), A4{}, at);
      }
    }
  }
  constexpr auto at_compile_time = [] {
    std::array<std::uint8_t, 8> b{};
    store_le<std::uint32_t, 2>(&b[2], 0x0A0B0C0DU);
    return std::pair{b[2] == 0x0D && b[5] == 0x0A, load_le<std::uint32_t, 2>(&b[2])};
  }();
  static_assert(at_compile_time.first && at_compile_time.second == 0x0A0B0C0DU);
}

TEST(DefaultMapping, TheFieldReadersAreTheDecodersWithoutTheirChecks) {
  for (const std::int32_t v : {0, 1, -1, 123456789, -2147483647 - 1, 2147483647}) {
    const Tpdo1 t1{static_cast<std::uint16_t>(v >> 7), v};
    EXPECT_EQ(tpdo1_fields(encode_tpdo1(5, t1)), t1);
    const Tpdo2 t2{v, ~v};
    EXPECT_EQ(tpdo2_fields(encode_tpdo2(5, t2)), t2);
    CanFrame kept{};
    kept.data.fill(0xEE);
    encode_rpdo1(5, Rpdo1{static_cast<std::uint16_t>(v), v}, kept);
    EXPECT_EQ(kept, encode_rpdo1(5, Rpdo1{static_cast<std::uint16_t>(v), v}));
    EXPECT_EQ(kept.data[6], 0xEE) << "bytes past the length are left as they were";
  }
}

TEST(DefaultMapping, DecodersInvertEncoders) {
  for (const std::int32_t v : {0, 1, -1, 123456789, -2147483647 - 1, 2147483647}) {
    const Rpdo1 r{static_cast<std::uint16_t>(v), v};
    EXPECT_EQ(decode_rpdo1(encode_rpdo1(9, r), 9), r);
    const Tpdo1 t1{static_cast<std::uint16_t>(v >> 3), v};
    EXPECT_EQ(decode_tpdo1(encode_tpdo1(9, t1), 9), t1);
    const Tpdo2 t2{v, -v / 2};
    EXPECT_EQ(decode_tpdo2(encode_tpdo2(9, t2), 9), t2);
  }
}

TEST(DefaultMapping, DecodersRejectOtherNodesAndLengths) {
  CanFrame f = encode_rpdo1(9, Rpdo1{1, 2});
  EXPECT_FALSE(decode_rpdo1(f, 8));
  f.len = 5;
  EXPECT_FALSE(decode_rpdo1(f, 9));
  f.len = 7;
  EXPECT_FALSE(decode_rpdo1(f, 9));
  EXPECT_FALSE(decode_tpdo1(encode_tpdo2(9, {}), 9)) << "TPDO2 id is not TPDO1";
}

TEST(PdoBinding, TypedCodecsAgreeWithTheDrivesMapping) {
  DriveNode drive{DriveNodeConfig{4}};
  PdoBinding rpdo;
  PdoBinding tpdo1;
  PdoBinding tpdo2;
  ASSERT_EQ(rpdo.bind(default_rpdo1_mapping(4), drive.dictionary()), SdoAbort::none);
  ASSERT_EQ(tpdo1.bind(default_tpdo1_mapping(4), drive.dictionary()), SdoAbort::none);
  ASSERT_EQ(tpdo2.bind(default_tpdo2_mapping(4), drive.dictionary()), SdoAbort::none);

  ASSERT_EQ(rpdo.unpack(encode_rpdo1(4, Rpdo1{0x0006, -77})), PdoStatus::ok);
  EXPECT_EQ(drive.objects().app.controlword, 0x0006);
  EXPECT_EQ(drive.objects().app.target_position, -77);

  FrameBuffer<4> out;
  drive.publish(DriveFeedback{4242, -5, 99}, 0, out);  // sets actual values (not operational: no TPDOs)
  EXPECT_TRUE(out.empty());
  CanFrame f{};
  ASSERT_EQ(tpdo1.pack(f), PdoStatus::ok);
  EXPECT_EQ(f, encode_tpdo1(4, Tpdo1{drive.objects().app.statusword, 4242}));
  ASSERT_EQ(tpdo2.pack(f), PdoStatus::ok);
  EXPECT_EQ(f, encode_tpdo2(4, Tpdo2{99, -5}));
}

TEST(PdoBinding, MappingObjectsDescribeTheMapping) {
  DriveNode drive{DriveNodeConfig{4}};
  std::uint32_t raw = 0;
  std::uint8_t size = 0;
  ASSERT_EQ(drive.dictionary().read(0x1A01, 1, raw, size), SdoAbort::none);
  EXPECT_EQ(raw, 0x2000'0020U);
  ASSERT_EQ(drive.dictionary().read(0x1800, 1, raw, size), SdoAbort::none);
  EXPECT_EQ(raw, 0x184U);
  ASSERT_EQ(drive.dictionary().read(0x1400, 2, raw, size), SdoAbort::none);
  EXPECT_EQ(raw, 1U) << "synchronous";
}

TEST(PdoBinding, BindRefusesWhatCannotBeMapped) {
  DriveNode drive{DriveNodeConfig{4}};
  PdoBinding b;
  PdoMapping m{0x200, 1, 1, {PdoMappingEntry{0x1000, 0, 32}}};
  EXPECT_EQ(b.bind(m, drive.dictionary()), SdoAbort::not_mappable);
  m.entries[0] = PdoMappingEntry{0x607A, 0, 16};
  EXPECT_EQ(b.bind(m, drive.dictionary()), SdoAbort::length_mismatch);
  m.entries[0] = PdoMappingEntry{0x5555, 0, 32};
  EXPECT_EQ(b.bind(m, drive.dictionary()), SdoAbort::no_object);
  m = PdoMapping{0x200, 1, 3, {PdoMappingEntry{0x607A, 0, 32}, PdoMappingEntry{0x6064, 0, 32}, PdoMappingEntry{0x6040, 0, 16}}};
  EXPECT_EQ(b.bind(m, drive.dictionary()), SdoAbort::pdo_too_long);
  EXPECT_FALSE(b.bound());
  CanFrame f{};
  EXPECT_EQ(b.pack(f), PdoStatus::unbound);
}

TEST(PdoBinding, WrongLengthOrIdLeavesEveryVariableUntouched) {
  DriveNode drive{DriveNodeConfig{4}};
  PdoBinding rpdo;
  ASSERT_EQ(rpdo.bind(default_rpdo1_mapping(4), drive.dictionary()), SdoAbort::none);
  const DriveObjects before = drive.objects();
  CanFrame f = encode_rpdo1(4, Rpdo1{0x000F, 1000});
  f.len = 5;
  EXPECT_EQ(rpdo.unpack(f), PdoStatus::too_short);
  f = encode_rpdo1(5, Rpdo1{0x000F, 1000});
  EXPECT_EQ(rpdo.unpack(f), PdoStatus::wrong_id);
  EXPECT_EQ(drive.objects().app.controlword, before.app.controlword);
  EXPECT_EQ(drive.objects().app.target_position, before.app.target_position);
}

TEST(PdoBinding, ALongerFrameIsAppliedFromItsMappedBytes) {
  DriveNode drive{DriveNodeConfig{4}};
  PdoBinding rpdo;
  ASSERT_EQ(rpdo.bind(default_rpdo1_mapping(4), drive.dictionary()), SdoAbort::none);
  CanFrame f = encode_rpdo1(4, Rpdo1{0x000F, 1000});
  f.len = 8;
  f.data[6] = 0xFF;
  f.data[7] = 0xFF;
  EXPECT_EQ(rpdo.unpack(f), PdoStatus::applied_longer);
  EXPECT_EQ(drive.objects().app.controlword, 0x000F);
  EXPECT_EQ(drive.objects().app.target_position, 1000);
}

}  // namespace
}  // namespace settle::hal::canopen
