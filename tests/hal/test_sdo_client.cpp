// SPDX-License-Identifier: Apache-2.0
// The SDO client against the drive's server through a loopback bus, on a virtual clock.
#include <gtest/gtest.h>

#include <array>
#include <set>
#include <string>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/loopback_bus.hpp"

namespace settle::hal::canopen {
namespace {

class SdoClientTest : public ::testing::Test {
 protected:
  static constexpr NodeId node = 3;
  LoopbackHub hub;
  LoopbackBus<16> master_bus{hub};
  LoopbackBus<16> drive_bus{hub};
  DriveNode drive{DriveNodeConfig{node}};
  SdoClient client{node, 50'000};

  // Lets the drive answer everything pending, then hands the answers to the client.
  void exchange(std::uint64_t now_us) {
    CanFrame f{};
    while (drive_bus.receive(f) == ReceiveStatus::received) {
      (void)drive.on_frame(f, now_us, drive_bus);
    }
    while (master_bus.receive(f) == ReceiveStatus::received) {
      (void)client.on_frame(f, now_us, master_bus);
    }
  }
};

TEST_F(SdoClientTest, UploadReturnsTheValueAndSize) {
  ASSERT_TRUE(client.upload(0x1000, 0, 0, master_bus));
  EXPECT_TRUE(client.busy());
  EXPECT_FALSE(client.upload(0x1001, 0, 0, master_bus)) << "one transfer at a time";
  exchange(0);
  ASSERT_EQ(client.status(), SdoClientStatus::done);
  EXPECT_EQ(client.result().value, cia402_device_type);
  EXPECT_EQ(client.result().size, 4);
}

// An expedited answer's value is its low `size` bytes (the rest of the frame may hold anything),
// into an integer (upload) as into the caller's bytes (upload_bytes).
TEST(SdoClientExpedited, TheValueIsTheIndicatedBytesOnly) {
  struct Case {
    std::uint8_t command;  // scs 2, n, e = 1, s
    std::uint32_t value;
    std::uint8_t size;
    std::uint32_t length;
  };
  const Case cases[] = {{0x4F, 0x08, 1, 1}, {0x4B, 0x3412, 2, 2}, {0x47, 0x563412, 3, 3},
                        {0x43, 0xCC563412, 4, 4}, {0x42, 0xCC563412, 0, 4}};
  for (const Case& c : cases) {
    FrameBuffer<4> out;
    const CanFrame answer = test::frame(0x583, {c.command, 0x60, 0x60, 0x00, c.value == 8 ? std::uint8_t{8} : std::uint8_t{0x12},
                                                0x34, 0x56, 0xCC});
    SdoClient client{3, 50'000};
    ASSERT_TRUE(client.upload(0x6060, 0, 0, out));
    ASSERT_TRUE(client.on_frame(answer, 0, out));
    ASSERT_EQ(client.status(), SdoClientStatus::done) << int{c.command};
    EXPECT_EQ(client.result().value, c.value) << int{c.command};
    EXPECT_EQ(client.result().size, c.size) << int{c.command};
    EXPECT_EQ(client.result().length, c.length) << int{c.command};

    std::array<std::uint8_t, 8> buffer{};
    SdoClient bytes_client{3, 50'000};
    ASSERT_TRUE(bytes_client.upload_bytes(0x6060, 0, buffer, 0, out));
    ASSERT_TRUE(bytes_client.on_frame(answer, 0, out));
    ASSERT_EQ(bytes_client.status(), SdoClientStatus::done) << int{c.command};
    EXPECT_EQ(bytes_client.result().value, c.value) << int{c.command};
    EXPECT_EQ(bytes_client.result().length, c.length) << int{c.command};
    for (std::size_t i = 0; i < buffer.size(); ++i) {
      EXPECT_EQ(buffer[i], i < c.length ? answer.data[4 + i] : 0) << int{c.command} << " byte " << i;
    }
  }
}

TEST_F(SdoClientTest, DownloadChangesTheDrivesObject) {
  ASSERT_TRUE(client.download(0x1017, 0, 250, 2, 0, master_bus));
  exchange(0);
  ASSERT_EQ(client.status(), SdoClientStatus::done);
  EXPECT_EQ(drive.objects().comm.producer_heartbeat_ms, 250);
}

TEST_F(SdoClientTest, AbortFromTheServerEndsTheTransferWithItsCode) {
  ASSERT_TRUE(client.download(0x6041, 0, 0, 2, 0, master_bus));
  exchange(0);
  ASSERT_EQ(client.status(), SdoClientStatus::aborted);
  EXPECT_EQ(client.result().abort, SdoAbort::read_only);
  EXPECT_EQ(client.result().abort_raw, 0x0601'0002U);
}

TEST_F(SdoClientTest, TimeoutFiresExactlyAtTheDeadlineAndAbortsOnTheBus) {
  ASSERT_TRUE(client.upload(0x1000, 0, 1'000, master_bus));
  CanFrame f{};
  while (drive_bus.receive(f) == ReceiveStatus::received) {
  }  // the server never sees it
  client.poll(50'999, master_bus);
  EXPECT_TRUE(client.busy());
  client.poll(51'000, master_bus);
  ASSERT_EQ(client.status(), SdoClientStatus::timed_out);
  ASSERT_EQ(drive_bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(test::bytes_of(f), (std::vector<std::uint8_t>{0x80, 0x00, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05}));
}

TEST_F(SdoClientTest, ResponsesForAnotherObjectOrNodeAreIgnored) {
  ASSERT_TRUE(client.upload(0x1000, 0, 0, master_bus));
  EXPECT_FALSE(client.on_frame(encode_sdo_upload_response(node, 0x1001, 0, 1, 1), 0, master_bus));
  EXPECT_FALSE(client.on_frame(encode_sdo_upload_response(node + 1, 0x1000, 0, 1, 4), 0, master_bus));
  EXPECT_FALSE(client.on_frame(encode_sdo_download_response(node, 0x1000, 0), 0, master_bus))
      << "a download confirmation does not answer an upload";
  EXPECT_TRUE(client.busy());
  EXPECT_TRUE(client.on_frame(encode_sdo_upload_response(node, 0x1000, 0, 0x1234, 2), 0, master_bus));
  EXPECT_EQ(client.result().value, 0x1234U);
}

TEST_F(SdoClientTest, IntegerUploadOfALongerObjectAbortsLengthTooHigh) {
  // upload() reads an integer of up to four bytes: a segmented answer announcing 20 does not fit.
  ASSERT_TRUE(client.upload(0x1008, 0, 0, master_bus));
  CanFrame segmented = encode_sdo_upload_response(node, 0x1008, 0, 20, 4);
  segmented.data[0] = 0x41;  // initiate upload, segmented, size 20 indicated
  EXPECT_TRUE(client.on_frame(segmented, 0, master_bus));
  EXPECT_EQ(client.status(), SdoClientStatus::aborted);
  EXPECT_EQ(client.result().abort, SdoAbort::length_too_high);
  CanFrame f{};
  ASSERT_EQ(drive_bus.receive(f), ReceiveStatus::received);  // the upload request
  ASSERT_EQ(drive_bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(test::bytes_of(f), (std::vector<std::uint8_t>{0x80, 0x08, 0x10, 0x00, 0x12, 0x00, 0x07, 0x06}));
}

TEST_F(SdoClientTest, IntegerUploadTakesASegmentedAnswerOfUpToFourBytes) {
  // CiA 301 lets a server answer any object segmented; the client must not care.
  ASSERT_TRUE(client.upload(0x1017, 0, 0, master_bus));
  CanFrame initiate = encode_sdo_upload_segmented_response(node, 0x1017, 0, 2);
  EXPECT_TRUE(client.on_frame(initiate, 0, master_bus));
  EXPECT_TRUE(client.busy());
  const std::uint8_t bytes[] = {0xE8, 0x03};
  EXPECT_TRUE(client.on_frame(encode_sdo_upload_segment(node, false, bytes, true), 0, master_bus));
  ASSERT_EQ(client.status(), SdoClientStatus::done);
  EXPECT_EQ(client.result().value, 1000U);
  EXPECT_EQ(client.result().size, 2);
  EXPECT_EQ(client.result().length, 2U);
}

TEST_F(SdoClientTest, ReadsTheDrivesStringsBySegmentedUpload) {
  // Each exchange() moves one request and its answer: the client runs one frame at a time.
  const auto read = [&](std::uint16_t index) {
    std::array<std::uint8_t, 64> buffer{};
    EXPECT_TRUE(client.upload_bytes(index, 0, buffer, 0, master_bus));
    for (int i = 0; i < 20 && client.busy(); ++i) {
      exchange(0);
    }
    EXPECT_EQ(client.status(), SdoClientStatus::done);
    return std::string(buffer.begin(), buffer.begin() + client.result().length);
  };
  EXPECT_EQ(read(0x1008), "Settle simulated CiA 402 drive");
  EXPECT_EQ(read(0x1009), "simulated");
  EXPECT_EQ(read(0x100A), "Settle 0.1.0");
  EXPECT_EQ(read(0x1008), drive_device_name);
}

TEST_F(SdoClientTest, TheDriveDropsASegmentedUploadWhoseClientWentSilent) {
  FrameBuffer<4> out;
  ASSERT_EQ(drive.on_frame(encode_sdo_upload_request(node, 0x1008, 0), 1'000, out), DriveEvent::handled);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].data[0], 0x41) << "segmented, size indicated";
  out.clear();
  drive.poll(1'000 + sdo_server_default_timeout_us - 1, out);
  for (const CanFrame& g : out.frames()) {
    EXPECT_NE(g.id, 0x580U + node) << "no SDO frame before the deadline";
  }
  out.clear();
  drive.poll(1'000 + sdo_server_default_timeout_us, out);
  bool aborted = false;
  for (const CanFrame& g : out.frames()) {
    if (g.id == 0x580U + node) {
      EXPECT_EQ(test::bytes_of(g), (std::vector<std::uint8_t>{0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05}));
      aborted = true;
    }
  }
  EXPECT_TRUE(aborted);
}

// CiA 301 table 22, written out here: each has its meaning; other codes are "unknown".
TEST(SdoAbortMeaning, EveryStandardCodeHasOne) {
  const std::uint32_t standard[] = {
      0x05030000, 0x05040000, 0x05040001, 0x05040002, 0x05040003, 0x05040004, 0x05040005, 0x06010000,
      0x06010001, 0x06010002, 0x06020000, 0x06040041, 0x06040042, 0x06040043, 0x06040047, 0x06060000,
      0x06070010, 0x06070012, 0x06070013, 0x06090011, 0x06090030, 0x06090031, 0x06090032, 0x06090036,
      0x060A0023, 0x08000000, 0x08000020, 0x08000021, 0x08000022, 0x08000023, 0x08000024};
  std::set<std::string> meanings;
  for (const std::uint32_t code : standard) {
    EXPECT_STRNE(abort_meaning(code), "unknown abort code") << std::hex << code;
    EXPECT_TRUE(is_known_abort(code)) << std::hex << code;
    EXPECT_TRUE(meanings.insert(abort_meaning(code)).second) << "the same meaning twice: " << abort_meaning(code);
  }
  EXPECT_STREQ(abort_meaning(0x0602'0000), "object does not exist in the object dictionary");
  for (const std::uint32_t code : {0u, 0x12345678u, 0x05040006u, 0x0609'0037u, 0xFFFF'FFFFu}) {
    EXPECT_STREQ(abort_meaning(code), "unknown abort code") << std::hex << code;
    EXPECT_FALSE(is_known_abort(code)) << std::hex << code;
  }
  static_assert(is_known_abort(0x0504'0000) && !is_known_abort(0x0504'0006), "usable in constant expressions");
}

}  // namespace
}  // namespace settle::hal::canopen
