// SPDX-License-Identifier: Apache-2.0
// SDO frames byte for byte, against CiA 301: what a master sends and what Settle's drive
// answers, including the standard abort codes.
#include <gtest/gtest.h>

#include <array>
#include <new>
#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/sdo.hpp"

namespace settle::hal::canopen {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(SdoGoldenFrames, ClientRequestsHaveTheStandardCommandBytes) {
  EXPECT_EQ(test::bytes_of(encode_sdo_upload_request(5, 0x1000, 0)), (Bytes{0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}));
  EXPECT_EQ(encode_sdo_upload_request(5, 0x1000, 0).id, 0x605U);
  EXPECT_EQ(test::bytes_of(encode_sdo_download_request(5, 0x6060, 0, 8, 1)),
            (Bytes{0x2F, 0x60, 0x60, 0x00, 0x08, 0, 0, 0}));
  EXPECT_EQ(test::bytes_of(encode_sdo_download_request(5, 0x6040, 0, 0x000F, 2)),
            (Bytes{0x2B, 0x40, 0x60, 0x00, 0x0F, 0x00, 0, 0}));
  EXPECT_EQ(test::bytes_of(encode_sdo_download_request(5, 0x1234, 1, 0x00ABCDEF, 3)),
            (Bytes{0x27, 0x34, 0x12, 0x01, 0xEF, 0xCD, 0xAB, 0}));
  EXPECT_EQ(test::bytes_of(encode_sdo_download_request(5, 0x1006, 0, 1000, 4)),
            (Bytes{0x23, 0x06, 0x10, 0x00, 0xE8, 0x03, 0x00, 0x00}));
  EXPECT_EQ(test::bytes_of(encode_sdo_download_request(5, 0x1006, 0, 1000, 0)),
            (Bytes{0x22, 0x06, 0x10, 0x00, 0xE8, 0x03, 0x00, 0x00}))
      << "expedited without size indication";
  EXPECT_EQ(test::bytes_of(encode_sdo_abort(5, true, 0x1000, 0, SdoAbort::timeout)),
            (Bytes{0x80, 0x00, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05}));
}

// The encoders build their frames without clearing the bytes only FD frames carry
// (classic_frame): the unused bytes of an SDO frame still go out as zeros, and an NMT command
// is two bytes, whatever the memory the frame is built in held before.
TEST(SdoGoldenFrames, UnusedBytesAreZeroWhateverTheStorageHeld) {
  alignas(CanFrame) std::array<unsigned char, sizeof(CanFrame)> storage{};
  storage.fill(0xA5);
  const CanFrame* f = new (storage.data()) CanFrame(encode_sdo_upload_request(5, 0x1000, 0));
  EXPECT_EQ(test::bytes_of(*f), (Bytes{0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}));
  EXPECT_EQ(f->flags, 0);
  EXPECT_EQ(f->timestamp_us, 0U);
  storage.fill(0xA5);
  f = new (storage.data()) CanFrame(encode_sdo_download_request(5, 0x6060, 0, 8, 1));
  EXPECT_EQ(test::bytes_of(*f), (Bytes{0x2F, 0x60, 0x60, 0x00, 0x08, 0, 0, 0}));
  storage.fill(0xA5);
  f = new (storage.data()) CanFrame(encode_sdo_upload_segment_request(5, true));
  EXPECT_EQ(test::bytes_of(*f), (Bytes{0x70, 0, 0, 0, 0, 0, 0, 0}));
  storage.fill(0xA5);
  f = new (storage.data()) CanFrame(encode_nmt(NmtCommand::enter_pre_operational, 5));
  EXPECT_EQ(f->id, 0U);
  EXPECT_EQ(f->flags, 0);
  EXPECT_EQ(test::bytes_of(*f), (Bytes{0x80, 0x05}));
}

class SdoServerGolden : public ::testing::Test {
 protected:
  static constexpr NodeId node = 5;
  DriveNode drive{DriveNodeConfig{node}};
  FrameBuffer<4> out;

  std::vector<std::uint8_t> answer(const CanFrame& request) {
    out.clear();
    EXPECT_EQ(drive.on_frame(request, 0, out), DriveEvent::handled);
    EXPECT_EQ(out.size(), 1U);
    if (out.empty()) {
      return {};
    }
    EXPECT_EQ(out[0].id, 0x585U) << "answers go to 0x580 + node";
    EXPECT_EQ(out[0].len, 8U);
    return test::bytes_of(out[0]);
  }
};

TEST_F(SdoServerGolden, UploadOfDeviceTypeAnswers43WithProfile402ServoDrive) {
  EXPECT_EQ(answer(encode_sdo_upload_request(node, 0x1000, 0)),
            (Bytes{0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}));
}

TEST_F(SdoServerGolden, UploadsCarryTheObjectsSizeInTheCommandByte) {
  EXPECT_EQ(answer(encode_sdo_upload_request(node, 0x1017, 0)),
            (Bytes{0x4B, 0x17, 0x10, 0x00, 100, 0x00, 0x00, 0x00}))
      << "producer heartbeat time, UNSIGNED16 = 100 ms";
  EXPECT_EQ(answer(encode_sdo_upload_request(node, 0x6061, 0)),
            (Bytes{0x4F, 0x61, 0x60, 0x00, 0x08, 0x00, 0x00, 0x00}))
      << "modes of operation display, INTEGER8 = 8 (CSP)";
  EXPECT_EQ(answer(encode_sdo_upload_request(node, 0x1600, 2)),
            (Bytes{0x43, 0x00, 0x16, 0x02, 0x20, 0x00, 0x7A, 0x60}))
      << "RPDO1 mapping entry 2 = 0x607A0020";
  EXPECT_EQ(answer(encode_sdo_upload_request(node, 0x607D, 1)),
            (Bytes{0x43, 0x7D, 0x60, 0x01, 0x00, 0x00, 0x00, 0x80}));
}

TEST_F(SdoServerGolden, DownloadIsConfirmedWith60) {
  EXPECT_EQ(answer(encode_sdo_download_request(node, 0x6060, 0, 7, 1)),
            (Bytes{0x60, 0x60, 0x60, 0x00, 0, 0, 0, 0}));
  EXPECT_EQ(drive.objects().app.mode, 7);
  EXPECT_EQ(drive.objects().app.mode_display, 7);
}

TEST_F(SdoServerGolden, WriteToReadOnlyObjectAborts06010002) {
  EXPECT_EQ(answer(encode_sdo_download_request(node, 0x1000, 0, 0, 4)),
            (Bytes{0x80, 0x00, 0x10, 0x00, 0x02, 0x00, 0x01, 0x06}));
  EXPECT_EQ(drive.objects().comm.device_type, cia402_device_type);
}

TEST_F(SdoServerGolden, StandardAbortCodesForEachRefusal) {
  struct Case {
    CanFrame request;
    std::uint32_t code;
  };
  const Case cases[] = {
      {encode_sdo_upload_request(node, 0x5FFF, 0), 0x0602'0000},             // no such object
      {encode_sdo_upload_request(node, 0x1018, 9), 0x0609'0011},             // no such sub-index
      {encode_sdo_download_request(node, 0x6040, 0, 6, 4), 0x0607'0012},     // too many bytes
      {encode_sdo_download_request(node, 0x6040, 0, 6, 1), 0x0607'0013},     // too few bytes
      {encode_sdo_download_request(node, 0x6060, 0, 3, 1), 0x0609'0030},     // unsupported mode
      {encode_sdo_download_request(node, 0x605A, 0, 9, 2), 0x0609'0031},     // above the range
      {encode_sdo_download_request(node, 0x2001, 0, 0, 1), 0x0609'0032},     // below the range
      {encode_sdo_download_request(node, 0x1018, 0, 1, 1), 0x0601'0002},     // const
  };
  for (const Case& c : cases) {
    const Bytes got = answer(c.request);
    ASSERT_EQ(got.size(), 8U);
    EXPECT_EQ(got[0], 0x80);
    EXPECT_EQ(got[1], c.request.data[1]);
    EXPECT_EQ(got[2], c.request.data[2]);
    EXPECT_EQ(got[3], c.request.data[3]);
    const std::uint32_t code = got[4] | (got[5] << 8U) | (got[6] << 16U) | (std::uint32_t{got[7]} << 24U);
    EXPECT_EQ(code, c.code) << std::hex << "request " << int{c.request.data[0]} << " to 0x"
                            << (c.request.data[1] | (c.request.data[2] << 8));
  }
}

TEST_F(SdoServerGolden, PositionLimitsMayNotCross) {
  EXPECT_EQ(answer(encode_sdo_download_request(node, 0x607D, 2, 50, 4))[0], 0x60);
  EXPECT_EQ(answer(encode_sdo_download_request(node, 0x607D, 1, 100, 4)),
            (Bytes{0x80, 0x7D, 0x60, 0x01, 0x36, 0x00, 0x09, 0x06}));
  EXPECT_EQ(drive.objects().app.position_limit_min, std::numeric_limits<std::int32_t>::min());
}

TEST_F(SdoServerGolden, UnknownOrUnsupportedCommandSpecifierAborts05040001) {
  // Command 7 exists in no service; 6 and 5 are block download and upload, not supported.
  for (const std::uint8_t command : {std::uint8_t{0xE0}, std::uint8_t{0xC0}, std::uint8_t{0xC6}, std::uint8_t{0xA0},
                                     std::uint8_t{0xA4}}) {
    CanFrame request = encode_sdo_upload_request(node, 0x1000, 0);
    request.data[0] = command;
    EXPECT_EQ(answer(request), (Bytes{0x80, 0x00, 0x10, 0x00, 0x01, 0x00, 0x04, 0x05}))
        << "command byte " << std::hex << int{command};
  }
  // A segment (upload request 0x60, download 0x00) with no transfer running: its bytes 1-3 are
  // no multiplexer, so the abort names none.
  for (const std::uint8_t command : {std::uint8_t{0x60}, std::uint8_t{0x00}}) {
    CanFrame request = encode_sdo_upload_request(node, 0x1000, 0);
    request.data[0] = command;
    EXPECT_EQ(answer(request), (Bytes{0x80, 0x00, 0x00, 0x00, 0x01, 0x00, 0x04, 0x05}))
        << "command byte " << std::hex << int{command};
  }
}

TEST_F(SdoServerGolden, SegmentedDownloadToAReadOnlyObjectAborts06010002) {
  EXPECT_EQ(answer(encode_sdo_download_segmented_request(node, 0x1000, 0, 4)),
            (Bytes{0x80, 0x00, 0x10, 0x00, 0x02, 0x00, 0x01, 0x06}));
  EXPECT_EQ(answer(encode_sdo_download_segmented_request(node, 0x1008, 0, 4)),
            (Bytes{0x80, 0x08, 0x10, 0x00, 0x02, 0x00, 0x01, 0x06}))
      << "the device name is const";
}

TEST_F(SdoServerGolden, HardwareVersionUploadsInTwoSegments) {
  // "simulated", nine bytes: written from the CiA 301 layout.
  EXPECT_EQ(answer(encode_sdo_upload_request(node, 0x1009, 0)),
            (Bytes{0x41, 0x09, 0x10, 0x00, 0x09, 0x00, 0x00, 0x00}))  // scs 2, e 0, s 1, size 9
      ;
  EXPECT_EQ(answer(test::frame(0x605, {0x60, 0, 0, 0, 0, 0, 0, 0})),  // ccs 3, t 0
            (Bytes{0x00, 's', 'i', 'm', 'u', 'l', 'a', 't'}));       // scs 0, t 0, n 0, c 0
  EXPECT_EQ(answer(test::frame(0x605, {0x70, 0, 0, 0, 0, 0, 0, 0})),  // ccs 3, t 1
            (Bytes{0x1B, 'e', 'd', 0, 0, 0, 0, 0}));                 // scs 0, t 1, n 5, c 1
}

TEST_F(SdoServerGolden, ClientAbortNeedsNoAnswer) {
  out.clear();
  EXPECT_EQ(drive.on_frame(encode_sdo_abort(node, true, 0x1000, 0, SdoAbort::general_error), 0, out),
            DriveEvent::handled);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace settle::hal::canopen
