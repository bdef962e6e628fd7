// SPDX-License-Identifier: Apache-2.0
// The EDS reader's size bounds: a description as large as they allow is read (16 000 ARRAY
// objects, each with two sub-objects: the case that took the quadratic reader 25 s of CPU before
// refusing it), and one beyond a bound is refused by a first count, the refusal naming the bound.
// How the time grows with the size is measured by bench/hal/eds_bench.cpp, not asserted here.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "settle/hal/eds_reader.hpp"

namespace settle::hal::eds {
namespace {

// Device type and `n` ARRAY objects 0x2000.. of one UNSIGNED32 element each.
std::string arrays(unsigned n) {
  std::string text =
      "[1000]\nParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\n"
      "DefaultValue=0x00020192\n";
  text.reserve(n * 200u);
  for (unsigned i = 0; i < n; ++i) {
    char object[256];
    const unsigned index = 0x2000 + i;
    std::snprintf(object, sizeof object,
                  "[%04X]\nParameterName=Array %u\nObjectType=0x8\nSubNumber=2\n"
                  "[%04Xsub0]\nParameterName=Highest sub-index\nDataType=0x0005\nAccessType=const\nDefaultValue=1\n"
                  "[%04Xsub1]\nParameterName=Element\nDataType=0x0007\nAccessType=rw\nDefaultValue=%u\n",
                  index, i, index, index, i);
    text += object;
  }
  return text;
}

TEST(EdsBounds, SixteenThousandArraysAreRead) {
  const std::string text = arrays(16000);
  ASSERT_LE(text.size(), max_file_bytes);
  const LoadResult r = parse(text);
  ASSERT_TRUE(r.description) << r.error;
  EXPECT_EQ(r.description->entries().size(), 1u + 2u * 16000u);
  const Entry* last = r.description->find(0x2000 + 15999, 1);
  ASSERT_NE(last, nullptr);
  EXPECT_EQ(last->value(1), 15999);
  EXPECT_EQ(r.description->find(0x2000 + 15999, 0)->value(1), 1);
}

std::string refusal(const std::string& text) {
  const LoadResult r = parse(text);
  EXPECT_FALSE(r.description);
  return r.error;
}

TEST(EdsBounds, BeyondABoundIsRefusedNamingIt) {
  EXPECT_NE(refusal(std::string(max_file_bytes + 1, ';')).find("larger than max_file_bytes (4194304 bytes)"),
            std::string::npos);
  // Counted before anything is read: these are refused by the count, not by what they say.
  std::string sections;
  for (std::size_t i = 0; i <= max_sections; ++i) sections += "[S]\n";
  EXPECT_EQ(refusal(sections), "more than max_sections (65536) sections");
  std::string keys = "[S]\n";
  for (std::size_t i = 0; i <= max_keys; ++i) keys += "k=\n";
  EXPECT_EQ(refusal(keys), "more than max_keys (524288) key=value lines");
  std::string objects;
  for (std::size_t i = 0; i <= max_objects; ++i) objects += "[1000]\n";
  EXPECT_EQ(refusal(objects), "more than max_objects (16384) object sections [IIII]");
  // At the bound, each is read.
  const std::string at_bound = arrays(static_cast<unsigned>(max_objects) - 1);
  ASSERT_LE(at_bound.size(), max_file_bytes);
  EXPECT_TRUE(parse(at_bound).description);
}

}  // namespace
}  // namespace settle::hal::eds
