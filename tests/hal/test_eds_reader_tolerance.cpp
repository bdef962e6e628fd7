// SPDX-License-Identifier: Apache-2.0
// The EDS reader reads what real tools write (CiA 306, and the Python canopen library's export):
// hex booleans and hex or decimal numbers in every numeric field, REAL limits and defaults as
// decimal fractions, 64-bit values in two's-complement hex, RECORDs typed by their sub-objects
// or without sub 0, a SubNumber that disagrees with the sections (read as present, with a
// warning). It stays strict where a wrong reading could move the machine: PDO mapping entries,
// COB-IDs, and the limits and values of objects the master writes; every refusal names the
// section, the key and the rule.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include "settle/hal/eds_reader.hpp"

namespace settle::hal::eds {
namespace {

// Device type, RPDO1 (writable mapping: controlword, target position) and the target position.
const std::string kBase = R"([DeviceInfo]
VendorNumber=171
ProductNumber=0x1234
RevisionNumber=0x00010000
NrOfRXPDO=1
[MandatoryObjects]
SupportedObjects=0x1
1=4096
[1000]
ParameterName=Device type
ObjectType=7
DataType=7
AccessType=ro
DefaultValue=0x00020192
PDOMapping=0x0
[1400]
ObjectType=0x9
SubNumber=0x3
[1400sub0]
DataType=0x0005
AccessType=const
DefaultValue=2
[1400sub1]
DataType=0x0007
AccessType=rw
DefaultValue=$NODEID+0x200
[1400sub2]
DataType=0x0005
AccessType=rw
DefaultValue=1
[1600]
ObjectType=0x8
SubNumber=3
[1600sub0]
DataType=0x0005
AccessType=rw
DefaultValue=2
[1600sub1]
DataType=0x0007
AccessType=rw
DefaultValue=0x60400010
[1600sub2]
DataType=0x0007
AccessType=rw
DefaultValue=0x607A0020
[6040]
ParameterName=Controlword
DataType=0x0006
AccessType=rww
PDOMapping=0x1
[607A]
ParameterName=Target position
DataType=0x0004
AccessType=rww
PDOMapping=1
DefaultValue=0
LowLimit=-1000000
HighLimit=1000000
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

Description must_parse(const std::string& text, LoadResult* out = nullptr) {
  LoadResult r = parse(text);
  EXPECT_TRUE(r.description) << r.error;
  if (out != nullptr) *out = r;
  return r.description ? *r.description : Description{};
}

// The refusal, checked to name the section and the key.
Problem must_refuse(const std::string& text, const std::string& section, const std::string& key) {
  const LoadResult r = parse(text);
  EXPECT_FALSE(r.description);
  EXPECT_EQ(r.refusal.section, section) << r.error;
  EXPECT_EQ(r.refusal.key, key) << r.error;
  EXPECT_GT(r.refusal.line, 0) << r.error;
  EXPECT_EQ(r.error, to_string(r.refusal));
  return r.refusal;
}

bool mentions(const Problem& p, const std::string& words) { return p.message.find(words) != std::string::npos; }

TEST(EdsTolerance, HexBooleansAndHexOrDecimalNumbersEverywhere) {
  LoadResult r;
  const Description d = must_parse(kBase, &r);
  EXPECT_TRUE(r.warnings.empty()) << to_string(r.warnings.front());
  EXPECT_FALSE(d.find(0x1000, 0)->pdo_mappable);              // PDOMapping=0x0
  EXPECT_TRUE(d.find(0x6040, 0)->pdo_mappable);               // PDOMapping=0x1
  EXPECT_TRUE(d.find(0x607A, 0)->pdo_mappable);               // PDOMapping=1
  EXPECT_EQ(d.find(0x1000, 0)->data_type, data_type::u32);    // DataType=7
  EXPECT_EQ(d.listed(), std::vector<std::uint16_t>{0x1000});  // SupportedObjects=0x1, 1=4096
  EXPECT_EQ(d.device().vendor_number, 171u);
  EXPECT_EQ(d.rpdos(5).at(0).cob_id, 0x205u);
  for (const char* bad : {"2", "0x2", "-1", "yes", "true"}) {
    const Problem p =
        must_refuse(replace(kBase, "PDOMapping=0x1", std::string{"PDOMapping="} + bad), "6040", "PDOMapping");
    EXPECT_TRUE(mentions(p, "0x6040:0: PDOMapping must be 0 or 1")) << p.message;
  }
  // The identity the master checks is read strictly; the PDO counts are not configured from.
  EXPECT_TRUE(
      mentions(must_refuse(replace(kBase, "VendorNumber=171", "VendorNumber=ACME"), "DeviceInfo", "VendorNumber"),
               "not an UNSIGNED32"));
  must_parse(replace(kBase, "NrOfRXPDO=1", "NrOfRXPDO=one"), &r);
  ASSERT_EQ(r.warnings.size(), 2u);
  EXPECT_EQ(to_string(r.warnings[0]), "line 5: [DeviceInfo] NrOfRXPDO: 'one' is not an UNSIGNED32: read as 0");
  EXPECT_EQ(to_string(r.warnings[1]), "line 5: [DeviceInfo] NrOfRXPDO: one but 1 RPDOs are described: the PDOs "
                                      "described are read");
}

TEST(EdsTolerance, RealValuesAndLimitsAreFloatingPoint) {
  const std::string reals = kBase +
                            "[2100]\nParameterName=Gain\nDataType=0x0008\nAccessType=rw\nLowLimit=-4.5\nHighLimit=4.5\n"
                            "DefaultValue=1.25\n"
                            "[2101]\nParameterName=Scale\nDataType=0x0011\nAccessType=rw\nLowLimit=1e-3\n"
                            "HighLimit=+1E6\nDefaultValue=0.5\n";
  const Description d = must_parse(reals);
  const Entry* gain = d.find(0x2100, 0);
  ASSERT_NE(gain, nullptr);
  EXPECT_EQ(gain->low_limit_real, -4.5);
  EXPECT_EQ(gain->high_limit_real, 4.5);
  EXPECT_EQ(gain->real_value(), 1.25);
  EXPECT_EQ(gain->low_limit, std::nullopt);
  EXPECT_EQ(gain->value(1), std::nullopt);
  EXPECT_EQ(data_type_bits(data_type::real64), 64u);
  const Entry* scale = d.find(0x2101, 0);
  EXPECT_EQ(scale->low_limit_real, 1e-3);
  EXPECT_EQ(scale->high_limit_real, 1e6);
  EXPECT_EQ(scale->real_value(), 0.5);
  EXPECT_TRUE(mentions(must_refuse(replace(reals, "HighLimit=4.5", "HighLimit=0x40900000"), "2100", "HighLimit"),
                       "a REAL32 is written in decimal"));
  EXPECT_TRUE(mentions(must_refuse(replace(reals, "DefaultValue=1.25", "DefaultValue=1.2.5"), "2100", "DefaultValue"),
                       "'1.2.5' is not a decimal number"));
  EXPECT_TRUE(
      mentions(must_refuse(replace(reals, "HighLimit=4.5", "HighLimit=1e39"), "2100", "HighLimit"), "outside REAL32"));
  EXPECT_TRUE(mentions(must_refuse(replace(reals, "DefaultValue=1.25", "DefaultValue=5"), "2100", "DefaultValue"),
                       "outside LowLimit..HighLimit"));
}

TEST(EdsTolerance, SixtyFourBitAndNegativeValuesInTwosComplementHex) {
  const std::string wide = kBase +
                           "[2200]\nDataType=0x0015\nAccessType=rw\nDefaultValue=0xFFFFFFFFFFFFFFFF\n"
                           "LowLimit=0x8000000000000000\nHighLimit=0x7FFFFFFFFFFFFFFF\n"
                           "[2201]\nDataType=0x001B\nAccessType=rw\nDefaultValue=0xFFFFFFFFFFFFFFFE\n"
                           "HighLimit=0xFFFFFFFFFFFFFFFF\nLowLimit=1\n"
                           "[2202]\nDataType=0x0002\nAccessType=rw\nDefaultValue=0xFF\n"
                           "[2203]\nDataType=0x0004\nAccessType=rw\nDefaultValue=0xFFFFFFFF\nLowLimit=-0x10\n"
                           "[2204]\nDataType=0x0015\nAccessType=rw\nDefaultValue=-9223372036854775808\n";
  const Description d = must_parse(wide);
  EXPECT_EQ(d.find(0x2200, 0)->value(1), -1);
  EXPECT_EQ(d.find(0x2200, 0)->low_limit, std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(d.find(0x2200, 0)->high_limit, std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(static_cast<std::uint64_t>(*d.find(0x2201, 0)->value(1)), 0xFFFFFFFFFFFFFFFEu);
  EXPECT_EQ(static_cast<std::uint64_t>(*d.find(0x2201, 0)->high_limit), 0xFFFFFFFFFFFFFFFFu);
  EXPECT_EQ(d.find(0x2202, 0)->value(1), -1);
  EXPECT_EQ(d.find(0x2203, 0)->value(1), -1);
  EXPECT_EQ(d.find(0x2203, 0)->low_limit, -16);
  EXPECT_EQ(d.find(0x2204, 0)->value(1), std::numeric_limits<std::int64_t>::min());
  // Beyond the type's width, in any notation.
  EXPECT_TRUE(
      mentions(must_refuse(replace(wide, "DefaultValue=0xFF\n", "DefaultValue=0x100\n"), "2202", "DefaultValue"),
               "'0x100' is outside INTEGER8 (-128..127)"));
  EXPECT_TRUE(mentions(must_refuse(replace(wide, "DefaultValue=0xFF\n", "DefaultValue=128\n"), "2202", "DefaultValue"),
                       "outside INTEGER8"));
  EXPECT_TRUE(
      mentions(must_refuse(replace(wide, "LowLimit=1\n", "LowLimit=-1\n"), "2201", "LowLimit"), "outside UNSIGNED64"));
  EXPECT_TRUE(mentions(must_refuse(replace(wide, "0xFFFFFFFFFFFFFFFE", "0x1FFFFFFFFFFFFFFFF"), "2201", "DefaultValue"),
                       "not an integer"));
  // An UNSIGNED64's limits compare as unsigned: 0xFFFFFFFFFFFFFFFE is within 1..0xFFFFFFFFFFFFFFFF.
  EXPECT_TRUE(
      mentions(must_refuse(replace(wide, "LowLimit=1\n", "LowLimit=0xFFFFFFFFFFFFFFFF\n"), "2201", "DefaultValue"),
               "18446744073709551614 is outside LowLimit..HighLimit"));
}

TEST(EdsTolerance, RecordsTypedBySubObjectsOrWithoutSubZero) {
  const std::string records = kBase +
                              "[2300]\nParameterName=Record\nObjectType=0x9\nSubNumber=2\n"
                              "[2300sub1]\nDataType=0x0007\nAccessType=ro\nDefaultValue=7\n"
                              "[2300sub2]\nDataType=0x0003\nAccessType=ro\nDefaultValue=-7\n"
                              "[2301]\nParameterName=Typed record\nObjectType=0x9\nDataType=0x0023\nSubNumber=2\n"
                              "[2301sub0]\nDataType=0x0005\nAccessType=const\nDefaultValue=1\n"
                              "[2301sub1]\nDataType=0x0007\nAccessType=ro\nDefaultValue=1\n";
  LoadResult r;
  const Description d = must_parse(records, &r);
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_TRUE(d.has(0x2300));
  EXPECT_EQ(d.find(0x2300, 0), nullptr);
  EXPECT_EQ(d.find(0x2300, 1)->value(1), 7);
  EXPECT_EQ(d.find(0x2300, 2)->value(1), -7);
  EXPECT_EQ(d.find(0x2301, 1)->data_type, data_type::u32);
  // An ARRAY or RECORD whose sub-objects are not described has no entries, and says so.
  must_parse(kBase + "[2302]\nObjectType=0x8\nSubNumber=0\n", &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].section, "2302");
  EXPECT_EQ(r.warnings[0].key, "ObjectType");
  // Two sections for one sub-index.
  const LoadResult twice = parse(kBase +
                                 "[2304]\nObjectType=0x9\nSubNumber=2\n[2304sub1]\nDataType=5\nAccessType=ro\n"
                                 "[2304sub01]\nDataType=5\nAccessType=ro\n");
  EXPECT_FALSE(twice.description);
  EXPECT_NE(twice.error.find("describes 0x2304:1 as ["), std::string::npos) << twice.error;
  // Compact sub-objects (CiA 306): sub 0 holds their number, subs 1..N share the object's type,
  // access, mapping and default, with names from [IIIIName] and values from [IIIIValue].
  const Description compact = must_parse(
      kBase +
          "[2303]\nParameterName=Gains\nObjectType=0x8\nCompactSubObj=4\nDataType=0x0007\nAccessType=ro\n"
          "DefaultValue=5\nPDOMapping=0x1\n[2303Name]\nNrOfEntries=1\n2=Second gain\n"
          "[2303Value]\nNrOfEntries=1\n3=0x10\n",
      &r);
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(compact.find(0x2303, 0)->value(1), 4);
  EXPECT_EQ(compact.find(0x2303, 0)->data_type, data_type::u8);
  ASSERT_NE(compact.find(0x2303, 4), nullptr);
  EXPECT_EQ(compact.find(0x2303, 5), nullptr);
  EXPECT_EQ(compact.find(0x2303, 1)->value(1), 5);
  EXPECT_EQ(compact.find(0x2303, 3)->value(1), 16);  // [2303Value] 3=0x10
  EXPECT_TRUE(compact.find(0x2303, 4)->pdo_mappable);
  EXPECT_EQ(compact.find(0x2303, 2)->name, "Second gain");
  EXPECT_EQ(compact.find(0x2303, 1)->name, "Gains 1");
  // Beside written sub-index sections, or on a VAR, or beyond 254: refused, naming the key.
  must_refuse(kBase + "[2305]\nObjectType=0x7\nCompactSubObj=2\nDataType=0x0007\nAccessType=ro\n", "2305",
              "CompactSubObj");
  must_refuse(kBase + "[2306]\nObjectType=0x8\nCompactSubObj=255\nDataType=0x0007\nAccessType=ro\n", "2306",
              "CompactSubObj");
  must_refuse(kBase +
                  "[2307]\nObjectType=0x8\nCompactSubObj=1\nDataType=0x0007\nAccessType=ro\n"
                  "[2307sub1]\nDataType=0x0007\nAccessType=ro\n",
              "2307", "CompactSubObj");
}

TEST(EdsTolerance, ObjectListsThatDisagreeWithTheFileAreWarnedAndReadAsPresent) {
  LoadResult r;
  // SupportedObjects counts 3, two entries present; one names an object with no section.
  const Description d = must_parse(
      replace(kBase, "SupportedObjects=0x1\n1=4096\n", "SupportedObjects=3\n1=4096\n2=0x6041\n"), &r);
  ASSERT_EQ(r.warnings.size(), 2u);
  EXPECT_EQ(r.warnings[0].section, "MandatoryObjects");
  EXPECT_EQ(r.warnings[0].key, "SupportedObjects");
  EXPECT_TRUE(mentions(r.warnings[0], "SupportedObjects=3 but 2 entries")) << r.warnings[0].message;
  EXPECT_EQ(r.warnings[1].key, "2");
  EXPECT_TRUE(mentions(r.warnings[1], "0x6041 is listed in [MandatoryObjects] but has no section [6041]"));
  EXPECT_EQ(d.listed(), std::vector<std::uint16_t>{0x1000});
  // [OptionalObjects] without SupportedObjects, entries out of order: read in the order of their numbers.
  must_parse(kBase + "[OptionalObjects]\n2=0x1600\n1=0x1400\n", &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_TRUE(mentions(r.warnings[0], "missing but 2 entries")) << r.warnings[0].message;
}

TEST(EdsTolerance, DeviceInfoAndIdentityObjectGiveOneIdentityAndAContradictionIsWarned) {
  const std::string identity = "[1018]\nObjectType=0x9\nSubNumber=3\n"
                               "[1018sub0]\nDataType=0x0005\nAccessType=ro\nDefaultValue=2\n"
                               "[1018sub1]\nDataType=0x0007\nAccessType=ro\nDefaultValue=VENDOR\n"
                               "[1018sub2]\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x1234\n";
  LoadResult r;
  // Agreeing: no warning.
  Description d = must_parse(kBase + replace(identity, "VENDOR", "0xAB"), &r);
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(d.device().vendor_number, 0xABu);
  // 0x1018:1 contradicts VendorNumber: 0x1018's is the one identity, and the warning says so.
  d = must_parse(kBase + replace(identity, "VENDOR", "0x00000099"), &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].section, "DeviceInfo");
  EXPECT_EQ(r.warnings[0].key, "VendorNumber");
  EXPECT_TRUE(mentions(r.warnings[0], "0x000000AB but 0x1018:1 gives 0x00000099: 0x00000099 (0x1018's)"))
      << r.warnings[0].message;
  EXPECT_EQ(d.device().vendor_number, 0x99u);
  // A placeholder 0 in 0x1018:1: [DeviceInfo]'s is used, and the warning says so.
  d = must_parse(kBase + replace(identity, "VENDOR", "0"), &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_TRUE(mentions(r.warnings[0], "0x000000AB ([DeviceInfo]'s)")) << r.warnings[0].message;
  EXPECT_EQ(d.device().vendor_number, 0xABu);
}

TEST(EdsTolerance, ASubNumberThatDisagreesIsAWarningAndTheSectionsPresentAreRead) {
  LoadResult r;
  Description d = must_parse(replace(kBase, "SubNumber=0x3", "SubNumber=5"), &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].section, "1400");
  EXPECT_EQ(r.warnings[0].key, "SubNumber");
  EXPECT_EQ(r.warnings[0].line, 18);
  EXPECT_TRUE(mentions(r.warnings[0], "SubNumber 5 but 3 sub-index sections")) << r.warnings[0].message;
  EXPECT_EQ(d.rpdos(1).at(0).transmission_type, 1);
  d = must_parse(replace(kBase, "SubNumber=0x3\n", ""), &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(to_string(r.warnings[0]), "line 16: [1400] SubNumber: missing: the 3 sub-index sections present are read");
}

TEST(EdsTolerance, PdoMappingEntriesAreReadStrictly) {
  const auto entry = [](const std::string& to) {
    return replace(kBase, "DefaultValue=0x607A0020", "DefaultValue=" + to);
  };
  EXPECT_TRUE(mentions(must_refuse(entry("0x607A0000"), "1600sub2", "DefaultValue"), "maps 0 bits"));
  EXPECT_TRUE(mentions(must_refuse(entry("0x607A0048"), "1600sub2", "DefaultValue"), "maps 72 bits"));
  EXPECT_TRUE(mentions(must_refuse(entry("0x607A0010"), "1600sub2", "DefaultValue"),
                       "maps 0x607A:0 with 16 bits, but it is described with 32"));
  EXPECT_TRUE(
      mentions(must_refuse(entry("$NODEID+0x607A0020"), "1600sub2", "DefaultValue"), "cannot depend on $NODEID"));
  EXPECT_TRUE(mentions(must_refuse(entry("0x1607A0020"), "1600sub2", "DefaultValue"), "outside UNSIGNED32"));
  EXPECT_TRUE(mentions(must_refuse(entry(""), "1600sub2", "DefaultValue"), "no value"));
  // More entries counted than described.
  EXPECT_TRUE(mentions(must_refuse(replace(kBase, "AccessType=rw\nDefaultValue=2\n", "AccessType=rw\nDefaultValue=3\n"),
                                   "1600sub0", "DefaultValue"),
                       "0x1600:0 maps 3 objects but 0x1600:3 is not described"));
  EXPECT_TRUE(
      mentions(must_refuse(replace(kBase, "AccessType=rw\nDefaultValue=2\n", "AccessType=rw\nDefaultValue=65\n"),
                           "1600sub0", "DefaultValue"),
               "more than 64 mapped objects"));
  // A mapping object without its count.
  const std::string no_count =
      replace(replace(kBase, "[1600sub0]\nDataType=0x0005\nAccessType=rw\nDefaultValue=2\n", ""),
              "SubNumber=3\n[1600sub1]", "SubNumber=2\n[1600sub1]");
  EXPECT_TRUE(mentions(must_refuse(no_count, "1600", ""), "has no sub-index 0"));
  // A DCF's configured entry is read as strictly as the default.
  const std::string dcf =
      replace(kBase, "DefaultValue=0x607A0020", "DefaultValue=0x607A0020\nParameterValue=0x607A0008");
  EXPECT_TRUE(mentions(must_refuse(dcf, "1600sub2", "ParameterValue"), "with 8 bits"));
}

TEST(EdsTolerance, CobIdsAreReadStrictly) {
  const auto cob = [](const std::string& to) {
    return replace(kBase, "DefaultValue=$NODEID+0x200", "DefaultValue=" + to);
  };
  EXPECT_EQ(must_parse(cob("0x80000200")).rpdos(1).at(0).cob_id, 0x80000200u);
  EXPECT_EQ(must_parse(cob("0x20000800")).rpdos(1).at(0).cob_id, 0x20000800u);  // 29-bit
  EXPECT_TRUE(mentions(must_refuse(cob("0x1200"), "1400sub1", "DefaultValue"),
                       "an 11-bit COB-ID (bit 29 clear) with bits 11..28 set"));
  // $NODEID+0x780 is 0x781..0x7FF: still 11 bits; $NODEID+0x7FF is not for node 127.
  must_parse(cob("$NODEID+0x780"));
  must_refuse(cob("$NODEID+0x7FF"), "1400sub1", "DefaultValue");
  EXPECT_TRUE(mentions(must_refuse(cob(""), "1400sub1", "DefaultValue"), "the COB-ID has no value"));
  EXPECT_TRUE(mentions(must_refuse(cob("0x100000000"), "1400sub1", "DefaultValue"), "outside UNSIGNED32"));
  EXPECT_TRUE(mentions(
      must_refuse(replace(kBase, "[1400sub1]\nDataType=0x0007", "[1400sub1]\nDataType=0x0006"), "1400sub1", "DataType"),
      "a COB-ID is UNSIGNED32"));
}

TEST(EdsTolerance, LimitsOfWhatTheMasterWritesAreStrictOthersAreWarnedAndDropped) {
  // 0x607A is rww: the master writes it.
  EXPECT_TRUE(mentions(must_refuse(replace(kBase, "LowLimit=-1000000", "LowLimit=2000000"), "607A", "LowLimit"),
                       "LowLimit is above HighLimit"));
  EXPECT_TRUE(mentions(must_refuse(replace(kBase, "LowLimit=-1000000", "LowLimit=-0x80000001"), "607A", "LowLimit"),
                       "outside INTEGER32"));
  EXPECT_TRUE(mentions(
      must_refuse(replace(kBase, "DefaultValue=0\nLowLimit", "DefaultValue=1000001\nLowLimit"), "607A", "DefaultValue"),
      "1000001 is outside LowLimit..HighLimit"));
  EXPECT_TRUE(mentions(must_refuse(replace(kBase, "LowLimit=-1000000", "LowLimit=low"), "607A", "LowLimit"),
                       "'low' is not an integer"));
  // The same on a read-only object: read, without the limits, and warned about.
  const std::string ro = replace(kBase, "AccessType=rww\nPDOMapping=1", "AccessType=ro\nPDOMapping=1");
  LoadResult r;
  Description d = must_parse(replace(ro, "LowLimit=-1000000", "LowLimit=2000000"), &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].key, "LowLimit");
  EXPECT_TRUE(mentions(r.warnings[0], "(ignored: the object is not writable)"));
  EXPECT_EQ(d.find(0x607A, 0)->low_limit, std::nullopt);
  EXPECT_EQ(d.find(0x607A, 0)->high_limit, std::nullopt);
  d = must_parse(replace(ro, "LowLimit=-1000000", "LowLimit=low"), &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(d.find(0x607A, 0)->low_limit, std::nullopt);
  EXPECT_EQ(d.find(0x607A, 0)->high_limit, 1000000);
}

TEST(EdsTolerance, TheBundledDescriptionsReadWithoutWarnings) {
  const std::string path = SETTLE_DRIVE_EDS_PATH;
  const std::string dir = path.substr(0, path.rfind('/') + 1);
  for (const char* name :
       {"settle_drive.eds", "split_rpdo_drive.eds", "static_mapping_drive.eds", "velocity_feedback_drive.eds"}) {
    const LoadResult r = load(dir + name);
    EXPECT_TRUE(r.description) << r.error;
    for (const Problem& w : r.warnings) ADD_FAILURE() << name << ": " << to_string(w);
  }
}

}  // namespace
}  // namespace settle::hal::eds
