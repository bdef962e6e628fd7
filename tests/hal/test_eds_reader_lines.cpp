// SPDX-License-Identifier: Apache-2.0
// The EDS reader's INI layer: every line read whole whatever its length (no split tail read as a
// key of its own), CRLF, byte order mark, comments, white space and case as CiA 306 files and
// the tools that write them have them, and a refusal naming the line for what is not INI.
#include <gtest/gtest.h>

#include <string>

#include "settle/hal/eds_reader.hpp"

namespace settle::hal::eds {
namespace {

// Device type and 0x607F (max profile velocity, u32 rw): `name` is 0x607F's ParameterName.
std::string drive_with(const std::string& name, const std::string& file_info = "") {
  return "[FileInfo]\nFileName=long.eds\n" + file_info +
         "[1000]\nParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x00020192\n"
         "[607F]\nParameterName=" +
         name + "\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\nDefaultValue=10000000\n";
}

TEST(EdsLines, ALongParameterNameIsOneValueNotTwo) {
  // The tail after byte 199 of the line reads as a key of its own to a reader that splits lines
  // at 200 bytes: it would configure 0x607F to 0xFFFFFFFF.
  for (std::size_t pad : {185u, 186u, 199u, 210u, 1000u}) {
    const std::string name = std::string(pad, 'A') + "ParameterValue=0xFFFFFFFF";
    const LoadResult r = parse(drive_with(name));
    ASSERT_TRUE(r.description) << r.error;
    const Entry* e = r.description->find(0x607F, 0);
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->name, name);
    EXPECT_TRUE(e->parameter_value.empty()) << pad;
    EXPECT_EQ(e->value(1), 10000000) << pad;
  }
}

TEST(EdsLines, ALongHarmlessDescriptionIsRead) {
  const std::string description(5000, 'd');
  EXPECT_TRUE(parse(drive_with("Max profile velocity", "Description=" + description + "\n")).description);
  const std::string words = "A description with spaces, commas and no equals sign " + std::string(300, '.');
  EXPECT_TRUE(parse(drive_with("Max profile velocity", "Description=" + words + "\n")).description);
  // A value as long as the file may be.
  const std::string huge(max_file_bytes / 2, 'x');
  const LoadResult r = parse(drive_with(huge));
  ASSERT_TRUE(r.description) << r.error.substr(0, 200);
  EXPECT_EQ(r.description->find(0x607F, 0)->name.size(), huge.size());
}

TEST(EdsLines, CrlfBomCommentsWhiteSpaceAndCase) {
  std::string text =
      "\xEF\xBB\xBF; a comment\r\n"
      "# another comment\r\n"
      "\r\n"
      "  [fileinfo]  ; trailing comment\r\n"
      "  FileName =  crlf.eds  \r\n"
      "[1000]\r\n"
      "parametername=Device type ; the type\r\n"
      "OBJECTTYPE=0x7\r\n"
      "\tDataType\t=\t0x0007\r\n"
      "AccessType=RO\r\n"
      "DefaultValue=0x00020192\r\n"
      "[607f]\r\n"
      "ParameterName=Max;velocity\r\n"
      "DataType:0x0007\r\n"
      "AccessType=rw\r\n"
      "DefaultValue=10000000";  // no line end at the end of the file
  const LoadResult r = parse(text);
  ASSERT_TRUE(r.description) << r.error;
  const Entry* type = r.description->find(0x1000, 0);
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->name, "Device type");
  EXPECT_EQ(type->access, Access::ro);
  EXPECT_EQ(type->value(1), 0x00020192);
  const Entry* velocity = r.description->find(0x607F, 0);
  ASSERT_NE(velocity, nullptr);
  EXPECT_EQ(velocity->name, "Max;velocity");  // ';' starts a comment only after white space
  EXPECT_EQ(velocity->value(1), 10000000);
}

TEST(EdsLines, WhatIsNotIniIsRefusedNamingTheLine) {
  const std::string good = drive_with("Max profile velocity");
  const auto refusal = [&](const std::string& inserted) {
    const LoadResult r = parse(inserted + good);
    EXPECT_FALSE(r.description) << inserted;
    return r.error;
  };
  EXPECT_NE(refusal("[Comments]\nLines=1\nthis is not ini\n").find("line 3: [Comments] not an INI line"),
            std::string::npos);
  EXPECT_NE(refusal("[Comments\n").find("line 1: a section header without ']'"), std::string::npos);
  EXPECT_NE(refusal("[Comments] x\n").find("line 1: text after the section header"), std::string::npos);
  EXPECT_NE(refusal("[]\n").find("line 1: a section without a name"), std::string::npos);
  EXPECT_NE(refusal("[Comments]\n=1\n").find("line 2: [Comments] a value without a key"), std::string::npos);
  EXPECT_NE(refusal("Lines=1\n").find("line 1: Lines: a key before any [section]"), std::string::npos);
  EXPECT_NE(
      refusal("[FILEINFO]\nFileVersion=1\n").find("line 3: [FileInfo] the section is given twice (first on line 1)"),
      std::string::npos);
  const LoadResult twice = parse("[Comments]\nLines=1\nLINES=2\n" + good);
  EXPECT_EQ(twice.error, "line 3: [Comments] LINES: given twice in the section (first on line 2)");
  EXPECT_EQ(twice.refusal.section, "Comments");
  EXPECT_EQ(twice.refusal.key, "LINES");
  EXPECT_EQ(twice.refusal.line, 3);
}

}  // namespace
}  // namespace settle::hal::eds
