// The shipped EDS (hal/eds/settle_drive.eds) and the drive's object dictionary describe the
// same device: every object, type, access right, PDO mappability, limit and default value.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "settle/hal/canopen/drive_node.hpp"

namespace settle::hal::canopen {
namespace {

using Section = std::map<std::string, std::string>;
using Eds = std::map<std::string, Section>;

std::string upper(std::string s) {
  for (char& c : s) {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return s;
}

Eds parse_eds(const std::string& path) {
  std::ifstream in{path};
  EXPECT_TRUE(in) << path;
  Eds eds;
  std::string line;
  std::string current;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') {
      line.pop_back();
    }
    if (line.empty() || line[0] == ';') {
      continue;
    }
    if (line[0] == '[') {
      current = upper(line.substr(1, line.find(']') - 1));
      eds[current];
      continue;
    }
    const auto eq = line.find('=');
    if (eq != std::string::npos) {
      eds[current][line.substr(0, eq)] = line.substr(eq + 1);
    }
  }
  return eds;
}

// Integer values as CiA 306 writes them: decimal, 0x hex, or $NODEID+<value>.
std::int64_t eds_value(std::string text, NodeId node) {
  std::int64_t base = 0;
  const std::string prefix = "$NODEID+";
  if (upper(text).rfind(prefix, 0) == 0) {
    base = node;
    text = text.substr(prefix.size());
  }
  return base + std::stoll(text, nullptr, 0);
}

const char* access_name(OdAccess a) {
  switch (a) {
    case OdAccess::ro: return "ro";
    case OdAccess::wo: return "wo";
    case OdAccess::rw: return "rw";
    case OdAccess::constant: return "const";
  }
  return "?";
}

std::string section_name(const OdEntry& e, bool has_subs) {
  char buf[16];
  if (has_subs) {
    std::snprintf(buf, sizeof buf, "%04XSUB%X", e.index, e.sub);
  } else {
    std::snprintf(buf, sizeof buf, "%04X", e.index);
  }
  return buf;
}

std::pair<std::int64_t, std::int64_t> type_limits(OdType t) {
  switch (t) {
    case OdType::i8: return {std::numeric_limits<std::int8_t>::min(), std::numeric_limits<std::int8_t>::max()};
    case OdType::i16: return {std::numeric_limits<std::int16_t>::min(), std::numeric_limits<std::int16_t>::max()};
    case OdType::i32: return {std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()};
    case OdType::u8: return {0, std::numeric_limits<std::uint8_t>::max()};
    case OdType::u16: return {0, std::numeric_limits<std::uint16_t>::max()};
    case OdType::u32: return {0, std::numeric_limits<std::uint32_t>::max()};
  }
  return {0, 0};
}

class EdsMatchesDictionary : public ::testing::TestWithParam<NodeId> {};

TEST_P(EdsMatchesDictionary, EveryEntryAgreesAndNothingIsMissing) {
  const NodeId node = GetParam();
  const Eds eds = parse_eds(SETTLE_DRIVE_EDS_PATH);
  DriveNode drive{DriveNodeConfig{node}};
  ASSERT_TRUE(drive.dictionary().is_well_formed());

  std::set<std::string> object_sections;
  for (const auto& [name, section] : eds) {
    if (section.count("ObjectType") != 0 && eds_value(section.at("ObjectType"), node) == 0x7) {
      object_sections.insert(name);
    }
  }

  std::set<std::uint16_t> indices;
  for (const OdEntry& e : drive.dictionary().entries()) {
    indices.insert(e.index);
    char index_name[8];
    std::snprintf(index_name, sizeof index_name, "%04X", e.index);
    ASSERT_TRUE(eds.count(index_name)) << "object 0x" << index_name << " missing in the EDS";
    const bool has_subs = eds.at(index_name).count("SubNumber") != 0;
    const std::string name = section_name(e, has_subs);
    ASSERT_TRUE(eds.count(name)) << name << " missing in the EDS";
    const Section& s = eds.at(name);
    object_sections.erase(name);
    EXPECT_EQ(eds_value(s.at("DataType"), node), static_cast<std::int64_t>(e.var.type())) << name;
    EXPECT_EQ(s.at("AccessType"), access_name(e.access)) << name;
    EXPECT_EQ(eds_value(s.at("PDOMapping"), node), e.pdo_mappable ? 1 : 0) << name;
    EXPECT_EQ(eds_value(s.at("DefaultValue"), node), e.var.value()) << name;
    const auto [type_min, type_max] = type_limits(e.var.type());
    EXPECT_EQ(s.count("LowLimit") ? eds_value(s.at("LowLimit"), node) : type_min, e.min) << name;
    EXPECT_EQ(s.count("HighLimit") ? eds_value(s.at("HighLimit"), node) : type_max, e.max) << name;
    if (has_subs && e.sub == 0) {
      EXPECT_EQ(eds_value(eds.at(index_name).at("SubNumber"), node),
                std::count_if(drive.dictionary().entries().begin(), drive.dictionary().entries().end(),
                              [&](const OdEntry& x) { return x.index == e.index; }))
          << index_name;
    }
  }
  EXPECT_TRUE(object_sections.empty()) << "EDS entries the drive does not have, e.g. " << *object_sections.begin();

  // The three object lists together name every object exactly once.
  std::set<std::uint16_t> listed;
  for (const char* list : {"MANDATORYOBJECTS", "OPTIONALOBJECTS", "MANUFACTUREROBJECTS"}) {
    const Section& s = eds.at(list);
    const auto n = eds_value(s.at("SupportedObjects"), node);
    for (std::int64_t i = 1; i <= n; ++i) {
      EXPECT_TRUE(listed.insert(static_cast<std::uint16_t>(eds_value(s.at(std::to_string(i)), node))).second);
    }
  }
  EXPECT_EQ(listed, indices);
  EXPECT_EQ(eds_value(eds.at("DEVICEINFO").at("ProductNumber"), node), drive.objects().comm.product_code);
}

INSTANTIATE_TEST_SUITE_P(Nodes, EdsMatchesDictionary, ::testing::Values(NodeId{1}, NodeId{42}, NodeId{127}),
                         [](const ::testing::TestParamInfo<NodeId>& p) { return "node" + std::to_string(p.param); });

}  // namespace
}  // namespace settle::hal::canopen
