#include <gtest/gtest.h>

#include <array>
#include <string>
#include <string_view>

#include "frame_helpers.hpp"
#include "settle/hal/candump_log.hpp"

namespace settle::hal {
namespace {

std::string format(const CanFrame& f, const char* iface = "vcan0") {
  std::array<char, candump_line_max> buf{};
  const std::size_t n = format_candump_line(f, iface, buf);
  return {buf.data(), n};
}

std::optional<CandumpRecord> parse(std::string_view line) { return parse_candump_line({line.data(), line.size()}); }

TEST(CandumpLog, FormatsLikeCandumpMinusL) {
  CanFrame f = test::frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF});
  f.timestamp_us = 1'700'000'000'123'456ULL;
  EXPECT_EQ(format(f), "(1700000000.123456) vcan0 123#DEADBEEF");
  CanFrame ext = test::frame(0x1234567, {0x01});
  ext.flags = can_flag::extended;
  ext.timestamp_us = 5;
  EXPECT_EQ(format(ext), "(0000000000.000005) vcan0 01234567#01");
  CanFrame rtr{};
  rtr.id = 0x7FF;
  rtr.flags = can_flag::rtr;
  EXPECT_EQ(format(rtr, "can1"), "(0000000000.000000) can1 7FF#R");
  rtr.len = 4;
  EXPECT_EQ(format(rtr, "can1"), "(0000000000.000000) can1 7FF#R4");
  CanFrame fd = test::frame(0x80, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12});
  fd.flags = can_flag::fd | can_flag::brs;
  EXPECT_EQ(format(fd), "(0000000000.000000) vcan0 080##10102030405060708090A0B0C");
  EXPECT_EQ(format(test::frame(0x000, {}), ""), "") << "an interface name is required";
}

TEST(CandumpLog, ParsesWhatItFormats) {
  for (const std::string line : {"(1700000000.123456) vcan0 123#DEADBEEF", "(0000000001.000000) vcan0 701#05",
                                 "(0000000001.000000) can0 080#", "(0000000000.000005) vcan0 01234567#01",
                                 "(0000000000.000000) can1 7FF#R4", "(0000000000.000000) vcan0 080##30102030405060708090A0B0C"}) {
    const auto rec = parse(line);
    ASSERT_TRUE(rec) << line;
    EXPECT_EQ(format(rec->frame, rec->iface.data()), line);
  }
  const auto rec = parse("(1.000001) vcan0 181#0102\n");
  ASSERT_TRUE(rec);
  EXPECT_EQ(rec->frame.timestamp_us, 1'000'001U);
  EXPECT_EQ(rec->frame, test::frame(0x181, {1, 2}));
  EXPECT_STREQ(rec->iface.data(), "vcan0");
}

TEST(CandumpLog, RejectsMalformedLines) {
  for (const std::string line :
       {"", "garbage", "(1.5) vcan0 123#00", "(1.000000) vcan0 12#00", "(1.000000) vcan0 123#0",
        "(1.000000) vcan0 123#000102030405060708", "(1.000000) vcan0 123 00", "(1.000000) vcan0 800#00",
        "(1.000000) vcan0 20000000#00", "(1.000000) vcan0 123#00 trailing", "(1.000000)vcan0 123#00",
        "(1.000000) averyveryverylongifname 123#00"}) {
    EXPECT_FALSE(parse(line)) << '"' << line << '"';
  }
}

}  // namespace
}  // namespace settle::hal
