// SPDX-License-Identifier: Apache-2.0
// check_semantics: what a description means for one node. A valid PDO on another service's or
// another PDO's identifier, a reserved transmission type, a 0x607F of 0 and a DCF made for
// another node are refused naming the object; a COB-ID in a range CiA 301 restricts and a TPDO
// the drive never sends per SYNC are warnings. Each case is checked against a clean description
// that passes, so that the refusal is the change's and nothing else's.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "settle/hal/eds_reader.hpp"
#include "settle/hal/eds_semantics.hpp"

namespace settle::hal::eds {
namespace {

std::string comm(const std::string& n, const std::string& cob, const std::string& type) {
  return "[" + n + "]\nObjectType=0x9\nSubNumber=3\n[" + n + "sub0]\nDataType=0x0005\nAccessType=ro\nDefaultValue=2\n[" +
         n + "sub1]\nDataType=0x0007\nAccessType=rw\nDefaultValue=" + cob + "\n[" + n +
         "sub2]\nDataType=0x0005\nAccessType=rw\nDefaultValue=" + type + "\n";
}
std::string map(const std::string& n, const std::string& entry) {
  return "[" + n + "]\nObjectType=0x8\nSubNumber=2\n[" + n + "sub0]\nDataType=0x0005\nAccessType=rw\nDefaultValue=1\n[" +
         n + "sub1]\nDataType=0x0007\nAccessType=rw\nDefaultValue=" + entry + "\n";
}

struct Text {
  std::string rpdo1_cob{"$NODEID+0x200"};
  std::string tpdo1_cob{"$NODEID+0x180"};
  std::string tpdo2_cob{"$NODEID+0x280"};
  std::string tpdo1_type{"1"};
  std::string rpdo1_type{"1"};
  std::string max_velocity{"1000000"};
  std::string extra;
  [[nodiscard]] std::string text() const {
    return "[DeviceInfo]\nVendorNumber=1\n[1000]\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x00020192\n"
           "[1005]\nDataType=0x0007\nAccessType=rw\nDefaultValue=0x80\n" +
           comm("1400", rpdo1_cob, rpdo1_type) + map("1600", "0x60400010") + comm("1800", tpdo1_cob, tpdo1_type) +
           map("1A00", "0x60410010") + comm("1801", tpdo2_cob, "1") + map("1A01", "0x60640020") +
           "[6040]\nDataType=0x0006\nAccessType=rw\nPDOMapping=1\n[6041]\nDataType=0x0006\nAccessType=ro\nPDOMapping=1\n"
           "[6064]\nDataType=0x0004\nAccessType=ro\nPDOMapping=1\n[607F]\nDataType=0x0007\nAccessType=rw\nDefaultValue=" +
           max_velocity + "\n" + extra;
  }
};

Semantics check(const Text& t, std::uint8_t node = 5) {
  const LoadResult r = parse(t.text());
  EXPECT_TRUE(r.description) << r.error;
  return r.description ? check_semantics(*r.description, node) : Semantics{};
}

void expect_refused(const Text& t, const std::string& section, const std::string& words, std::uint8_t node = 5) {
  const Semantics s = check(t, node);
  ASSERT_TRUE(s.refusal) << words;
  EXPECT_EQ(s.refusal->section, section) << to_string(*s.refusal);
  EXPECT_NE(s.refusal->message.find(words), std::string::npos) << to_string(*s.refusal);
}

TEST(EdsSemantics, AValidDescriptionPassesForEveryNode) {
  for (unsigned node = 1; node <= 127; ++node) {
    const Semantics s = check(Text{}, static_cast<std::uint8_t>(node));
    EXPECT_FALSE(s.refusal) << node << ": " << to_string(*s.refusal);
    EXPECT_TRUE(s.warnings.empty()) << node << ": " << to_string(s.warnings.front());
  }
}

TEST(EdsSemantics, ACobIdOnAnotherServiceOrAnotherPdoIsRefusedNamingIt) {
  Text t;
  t.rpdo1_cob = "0x80";  // SYNC
  expect_refused(t, "1400sub1", "SYNC (0x1005)");
  t.rpdo1_cob = "$NODEID+0x80";  // this node's EMCY
  expect_refused(t, "1400sub1", "EMCY");
  t.rpdo1_cob = "$NODEID+0x600";
  expect_refused(t, "1400sub1", "SDO request");
  t = Text{};
  t.tpdo1_cob = "$NODEID+0x580";
  expect_refused(t, "1800sub1", "SDO response");
  t.tpdo1_cob = "$NODEID+0x700";
  expect_refused(t, "1800sub1", "heartbeat");
  t.tpdo1_cob = "0";
  expect_refused(t, "1800sub1", "NMT");
  t = Text{};
  t.tpdo2_cob = "$NODEID+0x180";  // TPDO1's
  expect_refused(t, "1801sub1", "is also TPDO1's");
  t.tpdo2_cob = "$NODEID+0x200";  // RPDO1's
  expect_refused(t, "1801sub1", "is also RPDO1's");
  // A SYNC moved by 0x1005 moves the collision with it.
  t = Text{};
  t.extra = "";
  t.rpdo1_cob = "0x81";
  Text moved = t;
  const std::string text = moved.text();
  const LoadResult r = parse(text.substr(0, text.find("DefaultValue=0x80")) + "DefaultValue=0x81" +
                             text.substr(text.find("DefaultValue=0x80") + 17));
  ASSERT_TRUE(r.description) << r.error;
  const Semantics s = check_semantics(*r.description, 5);
  ASSERT_TRUE(s.refusal);
  EXPECT_NE(s.refusal->message.find("SYNC"), std::string::npos) << to_string(*s.refusal);
  // A disabled PDO (bit 31) is never on the bus: no collision.
  t = Text{};
  t.tpdo2_cob = "0x80000080";
  EXPECT_FALSE(check(t).refusal);
}

TEST(EdsSemantics, ARestrictedRangeIsAWarningNotARefusal) {
  Text t;
  t.tpdo2_cob = "0x581";  // node 1's SDO response, used by node 5
  const Semantics s = check(t);
  EXPECT_FALSE(s.refusal);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].section, "1801sub1");
  EXPECT_EQ(s.warnings[0].key, "DefaultValue");
  EXPECT_NE(s.warnings[0].message.find("restricts: SDO server to client"), std::string::npos) << s.warnings[0].message;
}

TEST(EdsSemantics, TransmissionTypesReservedAreRefusedAndTheNeverPerSyncOnesWarned) {
  for (const char* reserved : {"241", "251", "0xF1"}) {
    Text t;
    t.tpdo1_type = reserved;
    expect_refused(t, "1800sub2", "reserved by CiA 301");
  }
  Text r;
  r.rpdo1_type = "252";
  expect_refused(r, "1400sub2", "reserved by CiA 301");
  r.rpdo1_type = "255";  // an RPDO applied on arrival: fine
  EXPECT_FALSE(check(r).refusal);
  EXPECT_TRUE(check(r).warnings.empty());
  for (const char* never : {"0", "252", "253", "254", "255"}) {
    Text t;
    t.tpdo1_type = never;
    const Semantics s = check(t);
    EXPECT_FALSE(s.refusal) << never;
    ASSERT_EQ(s.warnings.size(), 1u) << never;
    EXPECT_NE(s.warnings[0].message.find("the drive sends it"), std::string::npos) << s.warnings[0].message;
  }
}

TEST(EdsSemantics, AZeroMaxProfileVelocityIsRefused) {
  Text t;
  t.max_velocity = "0";
  expect_refused(t, "607F", "0x607F:0 (max profile velocity) is 0");
  t.max_velocity = "0x0";
  expect_refused(t, "607F", "max profile velocity");
}

TEST(EdsSemantics, ADcfForAnotherNodeIsRefusedNamingTheNodeId) {
  Text t;
  t.extra = "[DeviceComissioning]\nNodeID=0x05\n";
  EXPECT_FALSE(check(t, 5).refusal);
  expect_refused(t, "DeviceComissioning", "the DCF configures node 5, not node 6 (give --node 5", 6);
}

// Malformed $NODEID forms are refused by the reader, naming the object and the key.
TEST(EdsSemantics, MalformedNodeIdFormsAreRefusedByTheReader) {
  for (const char* bad : {"$NODEID+$NODEID", "$NODEID*2+0x180", "0x180+$NODEID+1", "$NODEID-0x10", "$NODEIDX",
                          "$NODEID+", "+$NODEID", "0x180 $NODEID"}) {
    Text t;
    t.tpdo1_cob = bad;
    const LoadResult r = parse(t.text());
    EXPECT_FALSE(r.description) << bad;
    EXPECT_EQ(r.refusal.section, "1800sub1") << bad << ": " << r.error;
    EXPECT_EQ(r.refusal.key, "DefaultValue") << bad << ": " << r.error;
  }
}

}  // namespace
}  // namespace settle::hal::eds
