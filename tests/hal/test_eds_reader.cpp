// SPDX-License-Identifier: Apache-2.0
// The EDS/DCF reader against hand-written descriptions: what CiA 306 says each key means, the
// PDO objects decoded, $NODEID resolved, and a specific error for every kind of bad file.
#include <gtest/gtest.h>

#include <string>

#include "settle/hal/eds_reader.hpp"

namespace settle::hal::eds {
namespace {

// A small but complete drive: device type, identity (a RECORD), RPDO1 with a writable mapping,
// TPDO1 with a read-only one, and a manufacturer object.
const char* const kDrive = R"(
[FileInfo]
FileName=mini.eds
[DeviceInfo]
VendorName=Acme Motion
VendorNumber=0x000000AB
ProductName=Mini servo
ProductNumber=0x1234
RevisionNumber=0x00020001
NrOfRXPDO=1
NrOfTXPDO=1
Granularity=8
[MandatoryObjects]
SupportedObjects=2
1=0x1000
2=0x1018
[OptionalObjects]
SupportedObjects=5
1=0x1400
2=0x1600
3=0x1800
4=0x1A00
5=0x607A
[ManufacturerObjects]
SupportedObjects=1
1=0x2001
[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00020192
PDOMapping=0
[1018]
ParameterName=Identity
ObjectType=0x9
SubNumber=2
[1018sub0]
ParameterName=Highest sub-index
ObjectType=0x7
DataType=0x0005
AccessType=const
DefaultValue=1
[1018SUB1]
ParameterName=Vendor-ID
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0xAB
[1400]
ObjectType=0x9
SubNumber=3
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
DefaultValue=0xFF
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
[1800]
ObjectType=0x9
SubNumber=3
[1800sub0]
DataType=0x0005
AccessType=const
DefaultValue=2
[1800sub1]
DataType=0x0007
AccessType=rw
DefaultValue=0x180+$NODEID
[1800sub2]
DataType=0x0005
AccessType=rw
DefaultValue=1
[1A00]
ObjectType=0x8
SubNumber=2
[1A00sub0]
DataType=0x0005
AccessType=ro
DefaultValue=1
[1A00sub1]
DataType=0x0007
AccessType=ro
DefaultValue=0x60640020
[607A]
ParameterName=Target position
ObjectType=0x7
DataType=0x0004
AccessType=rww
PDOMapping=1
DefaultValue=0
LowLimit=-1000000
HighLimit=0x000F4240
[2001]
ParameterName=Vendor string
DataType=0x0009
AccessType=ro
DefaultValue=hello $NODEID
)";

Description must_parse(const std::string& text) {
  LoadResult r = parse(text);
  EXPECT_TRUE(r.description) << r.error;
  return r.description ? *r.description : Description{};
}

std::string must_fail(const std::string& text) {
  LoadResult r = parse(text);
  EXPECT_FALSE(r.description);
  EXPECT_FALSE(r.error.empty());
  return r.error;
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(EdsIntegers, AsCia306WritesThem) {
  EXPECT_EQ(parse_integer("16", 0), 16);
  EXPECT_EQ(parse_integer("0x10", 0), 16);
  EXPECT_EQ(parse_integer("0X1f", 0), 31);
  EXPECT_EQ(parse_integer("010", 0), 8);  // a leading zero is octal
  EXPECT_EQ(parse_integer("0", 0), 0);
  EXPECT_EQ(parse_integer("-5", 0), -5);
  EXPECT_EQ(parse_integer(" 7 ", 0), 7);
  EXPECT_EQ(parse_integer("$NODEID+0x180", 5), 0x185);
  EXPECT_EQ(parse_integer("0x180+$NODEID", 5), 0x185);
  EXPECT_EQ(parse_integer("$nodeid + 0x600", 127), 0x67F);
  EXPECT_EQ(parse_integer("$NODEID", 9), 9);
  for (const char* bad : {"", "0x", "abc", "12a", "08", "0x1G", "$NODEID-1", "1+2", "99999999999999999999999"}) {
    EXPECT_EQ(parse_integer(bad, 1), std::nullopt) << bad;
  }
}

TEST(EdsReader, ReadsObjectsIdentityAndLists) {
  const Description d = must_parse(kDrive);
  ASSERT_EQ(d.entries().size(), 16u);
  const Entry* dt = d.find(0x1000, 0);
  ASSERT_NE(dt, nullptr);
  EXPECT_EQ(dt->name, "Device type");
  EXPECT_EQ(dt->data_type, data_type::u32);
  EXPECT_EQ(dt->access, Access::ro);
  EXPECT_EQ(dt->value(1), 0x00020192);
  EXPECT_TRUE(dt->readable());
  EXPECT_FALSE(dt->writable());
  const Entry* vendor = d.find(0x1018, 1);  // [1018SUB1]: section names are case-insensitive
  ASSERT_NE(vendor, nullptr);
  EXPECT_EQ(vendor->value(1), 0xAB);
  EXPECT_EQ(d.find(0x1018, 2), nullptr);
  const Entry* target = d.find(0x607A, 0);
  ASSERT_NE(target, nullptr);
  EXPECT_EQ(target->access, Access::rww);
  EXPECT_TRUE(target->writable());
  EXPECT_TRUE(target->pdo_mappable);
  EXPECT_EQ(target->low_limit, -1000000);
  EXPECT_EQ(target->high_limit, 1000000);
  const Entry* text = d.find(0x2001, 0);
  ASSERT_NE(text, nullptr);
  EXPECT_EQ(text->default_value, "hello $NODEID");  // strings are kept as written
  EXPECT_EQ(text->value(1), std::nullopt);
  EXPECT_TRUE(d.has(0x1600));
  EXPECT_FALSE(d.has(0x1601));
  EXPECT_EQ(d.device().vendor_name, "Acme Motion");
  EXPECT_EQ(d.device().vendor_number, 0xABu);
  EXPECT_EQ(d.device().product_number, 0x1234u);
  EXPECT_EQ(d.device().revision_number, 0x00020001u);
  EXPECT_EQ(d.device().nr_rx_pdo, 1u);
  EXPECT_EQ(d.device().granularity, 8u);
  EXPECT_EQ(d.listed(), (std::vector<std::uint16_t>{0x1000, 0x1018, 0x1400, 0x1600, 0x1800, 0x1A00, 0x607A, 0x2001}));
  EXPECT_EQ(d.dcf_node_id(), std::nullopt);
}

TEST(EdsReader, DecodesThePdoObjectsForANode) {
  const Description d = must_parse(kDrive);
  const auto rpdos = d.rpdos(3);
  ASSERT_EQ(rpdos.size(), 1u);
  EXPECT_TRUE(rpdos[0].receive);
  EXPECT_EQ(rpdos[0].number, 1u);
  EXPECT_EQ(rpdos[0].cob_id, 0x203u);
  EXPECT_EQ(rpdos[0].transmission_type, 0xFF);
  EXPECT_TRUE(rpdos[0].mapping_writable);
  ASSERT_EQ(rpdos[0].mapping.size(), 2u);
  EXPECT_EQ(rpdos[0].mapping[0].index, 0x6040);
  EXPECT_EQ(rpdos[0].mapping[0].sub, 0);
  EXPECT_EQ(rpdos[0].mapping[0].bits, 16);
  EXPECT_EQ(rpdos[0].mapping[1].index, 0x607A);
  EXPECT_EQ(rpdos[0].mapping[1].bits, 32);
  const auto tpdos = d.tpdos(3);
  ASSERT_EQ(tpdos.size(), 1u);
  EXPECT_EQ(tpdos[0].cob_id, 0x183u);
  EXPECT_EQ(tpdos[0].transmission_type, 1);
  EXPECT_FALSE(tpdos[0].mapping_writable);
  ASSERT_EQ(tpdos[0].mapping.size(), 1u);
  EXPECT_EQ(tpdos[0].mapping[0].index, 0x6064);
  EXPECT_EQ(tpdos[0].communication_index(), 0x1800);
  EXPECT_EQ(tpdos[0].mapping_index(), 0x1A00);
}

TEST(EdsReader, ADcfConfiguredValueAndNodeIdWin) {
  std::string dcf = replace(kDrive, "DefaultValue=0x60640020", "DefaultValue=0x60640020\nParameterValue=0x606C0020");
  dcf += "[DeviceComissioning]\nNodeID=0x21\n";
  const Description d = must_parse(dcf);
  EXPECT_EQ(d.dcf_node_id(), 0x21);
  EXPECT_EQ(d.tpdos(0x21)[0].mapping[0].index, 0x606C);
  EXPECT_EQ(d.find(0x1A00, 1)->default_value, "0x60640020");
}

TEST(EdsReader, EveryBadFileGetsASpecificError) {
  EXPECT_NE(must_fail(replace(kDrive, "DataType=0x0004\n", "")).find("0x607A:0"), std::string::npos);
  EXPECT_NE(must_fail(replace(kDrive, "AccessType=rww", "AccessType=readwrite")).find("AccessType"), std::string::npos);
  EXPECT_NE(must_fail(replace(kDrive, "PDOMapping=1", "PDOMapping=2")).find("PDOMapping"), std::string::npos);
  EXPECT_NE(must_fail(replace(kDrive, "LowLimit=-1000000", "LowLimit=low")).find("LowLimit"), std::string::npos);
  EXPECT_NE(must_fail(replace(kDrive, "DefaultValue=0x00020192", "DefaultValue=0x0002019Z")).find("0x1000:0"),
            std::string::npos);
  {  // An object list naming an object the file does not describe: read without it, warned.
    const LoadResult listed = parse(replace(kDrive, "5=0x607A", "5=0x6060"));
    ASSERT_TRUE(listed.description) << listed.error;
    ASSERT_EQ(listed.warnings.size(), 1u);
    EXPECT_NE(listed.warnings[0].message.find("0x6060 is listed"), std::string::npos);
    EXPECT_EQ(listed.warnings[0].key, "5");
  }
  EXPECT_NE(must_fail(replace(kDrive, "[1018]\nParameterName=Identity\nObjectType=0x9\nSubNumber=2\n", ""))
                .find("no object section [1018]"),
            std::string::npos);
  EXPECT_NE(must_fail(replace(kDrive, "[1600]\nObjectType=0x8", "[1600]\nObjectType=0x7")).find("ARRAY or RECORD"),
            std::string::npos);
  EXPECT_NE(must_fail(replace(kDrive, "ParameterName=Device type\n", "ParameterName=Device type\nParameterName=x\n"))
                .find("twice"),
            std::string::npos);
  EXPECT_NE(must_fail(replace(kDrive, "[FileInfo]", "this is not ini\n[FileInfo]")).find("line "), std::string::npos);
  std::string no_device_type = replace(kDrive, "1=0x1000\n2=0x1018", "1=0x1018\n2=0x1018");
  no_device_type = replace(no_device_type, "[1000]\n", "[1001]\n");
  EXPECT_NE(must_fail(no_device_type).find("0x1000"), std::string::npos);
  EXPECT_NE(must_fail(std::string(kDrive) + "[DeviceComissioning]\nNodeID=128\n").find("NodeID"), std::string::npos);
}

TEST(EdsReader, SizesAreBoundedBeforeAnythingGrows) {
  std::string huge(max_file_bytes + 1, ';');
  EXPECT_NE(must_fail(huge).find("larger than"), std::string::npos);
  const LoadResult missing = load("/nonexistent/drive.eds");
  EXPECT_FALSE(missing.description);
  EXPECT_NE(missing.error.find("cannot be opened"), std::string::npos);
  // More objects than max_objects: refused by count, long before the file limit.
  std::string many = "[1000]\nDataType=7\nAccessType=ro\n";
  for (unsigned i = 0; i < max_objects + 1; ++i) {
    char section[40];
    std::snprintf(section, sizeof section, "[%04X]\nDataType=5\nAccessType=rw\n", 0x2000 + i);
    many += section;
  }
  EXPECT_NE(must_fail(many).find("more than"), std::string::npos);
}

}  // namespace
}  // namespace settle::hal::eds
