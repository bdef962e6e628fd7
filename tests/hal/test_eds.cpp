// SPDX-License-Identifier: Apache-2.0
// The shipped EDS (hal/eds/settle_drive.eds) and the drive's object dictionary describe the
// same device: every object, type, access right, PDO mappability, limit and default value.
// The EDS is read by the project's reader (settle::hal::eds), which eds_reader_test checks on
// its own against hand-written files.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <set>
#include <string>

#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/eds_reader.hpp"

namespace settle::hal::canopen {
namespace {

eds::Access eds_access(OdAccess a) {
  switch (a) {
    case OdAccess::ro: return eds::Access::ro;
    case OdAccess::wo: return eds::Access::wo;
    case OdAccess::rw: return eds::Access::rw;
    case OdAccess::constant: return eds::Access::constant;
  }
  return eds::Access::ro;
}

std::pair<std::int64_t, std::int64_t> type_limits(OdType t) {
  switch (t) {
    case OdType::i8: return {std::numeric_limits<std::int8_t>::min(), std::numeric_limits<std::int8_t>::max()};
    case OdType::i16: return {std::numeric_limits<std::int16_t>::min(), std::numeric_limits<std::int16_t>::max()};
    case OdType::i32: return {std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()};
    case OdType::u8: return {0, std::numeric_limits<std::uint8_t>::max()};
    case OdType::u16: return {0, std::numeric_limits<std::uint16_t>::max()};
    case OdType::u32: return {0, std::numeric_limits<std::uint32_t>::max()};
    case OdType::visible_string:
    case OdType::octet_string:
    case OdType::domain: return {0, 0};  // no value range: checked as bytes
  }
  return {0, 0};
}

class EdsMatchesDictionary : public ::testing::TestWithParam<NodeId> {};

TEST_P(EdsMatchesDictionary, EveryEntryAgreesAndNothingIsMissing) {
  const NodeId node = GetParam();
  const eds::LoadResult loaded = eds::load(SETTLE_DRIVE_EDS_PATH);
  ASSERT_TRUE(loaded.description) << loaded.error;
  const eds::Description& d = *loaded.description;
  DriveNode drive{DriveNodeConfig{node}};
  ASSERT_TRUE(drive.dictionary().is_well_formed());

  std::set<std::uint16_t> indices;
  for (const OdEntry& e : drive.dictionary().entries()) {
    indices.insert(e.index);
    const eds::Entry* x = d.find(e.index, e.sub);
    ASSERT_NE(x, nullptr) << "0x" << std::hex << e.index << ":" << int{e.sub} << " missing in the EDS";
    EXPECT_EQ(x->data_type, static_cast<std::uint16_t>(e.var.type())) << x->name;
    EXPECT_EQ(x->access, eds_access(e.access)) << x->name;
    EXPECT_EQ(x->pdo_mappable, e.pdo_mappable) << x->name;
    if (const OdBytes* bytes = e.var.bytes(); bytes != nullptr) {
      // A string's DefaultValue is its text; a byte string has no LowLimit/HighLimit.
      const auto value = bytes->view();
      EXPECT_EQ(x->default_value, std::string(value.begin(), value.end())) << x->name;
      EXPECT_FALSE(x->low_limit.has_value() || x->high_limit.has_value()) << x->name;
      continue;
    }
    EXPECT_EQ(x->value(node), e.var.value()) << x->name;
    const auto [type_min, type_max] = type_limits(e.var.type());
    EXPECT_EQ(x->low_limit.value_or(type_min), e.min) << x->name;
    EXPECT_EQ(x->high_limit.value_or(type_max), e.max) << x->name;
  }
  for (const eds::Entry& x : d.entries()) {
    EXPECT_NE(drive.dictionary().find(x.index, x.sub), nullptr)
        << "EDS entry the drive does not have: 0x" << std::hex << x.index << ":" << int{x.sub} << " " << x.name;
  }

  // The three object lists together name every object exactly once.
  std::multiset<std::uint16_t> listed(d.listed().begin(), d.listed().end());
  EXPECT_EQ(std::set<std::uint16_t>(listed.begin(), listed.end()), indices);
  EXPECT_EQ(listed.size(), indices.size()) << "an object is listed twice";
  EXPECT_EQ(d.device().product_number, drive.objects().comm.product_code);
}

INSTANTIATE_TEST_SUITE_P(Nodes, EdsMatchesDictionary, ::testing::Values(NodeId{1}, NodeId{42}, NodeId{127}),
                         [](const ::testing::TestParamInfo<NodeId>& p) { return "node" + std::to_string(p.param); });

}  // namespace
}  // namespace settle::hal::canopen
