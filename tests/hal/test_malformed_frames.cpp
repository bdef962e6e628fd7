// SPDX-License-Identifier: Apache-2.0
// Frames that are not what a decoder expects (wrong length, unknown command specifier, wrong
// node, RTR, extended or FD format) are rejected, and rejecting them changes nothing: the
// drive's whole dictionary and state are compared before and after.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/emcy.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/canopen/sync.hpp"

namespace settle::hal::canopen {
namespace {

constexpr NodeId node = 6;

std::vector<std::uint32_t> snapshot(DriveNode& drive) {
  std::vector<std::uint32_t> values;
  for (const OdEntry& e : drive.dictionary().entries()) {
    values.push_back(e.var.raw());
  }
  values.push_back(static_cast<std::uint32_t>(drive.state()));
  values.push_back(static_cast<std::uint32_t>(drive.nmt_state()));
  return values;
}

// Variants of a good frame that must all be refused.
std::vector<CanFrame> corruptions_of(const CanFrame& good) {
  std::vector<CanFrame> bad;
  for (std::uint8_t len = 0; len <= 8; ++len) {
    if (len != good.len) {
      CanFrame f = good;
      f.len = len;
      bad.push_back(f);
    }
  }
  CanFrame rtr = good;
  rtr.flags = can_flag::rtr;
  bad.push_back(rtr);
  CanFrame ext = good;
  ext.flags = can_flag::extended;
  bad.push_back(ext);
  CanFrame fd = good;
  fd.flags = can_flag::fd;
  bad.push_back(fd);
  return bad;
}

TEST(MalformedFrames, DecodersRefuseWrongLengthAndFormat) {
  for (const CanFrame& f : corruptions_of(encode_nmt(NmtCommand::start, node))) {
    EXPECT_FALSE(decode_nmt(f));
  }
  for (const CanFrame& f : corruptions_of(encode_heartbeat(node, NmtState::operational))) {
    EXPECT_FALSE(decode_heartbeat(f));
  }
  for (const CanFrame& f : corruptions_of(encode_emcy(node, {0x1000, 1, {}}))) {
    EXPECT_FALSE(decode_emcy(f));
  }
  for (const CanFrame& f : corruptions_of(encode_sdo_upload_request(node, 0x1000, 0))) {
    EXPECT_FALSE(decode_sdo_request(f, node));
  }
  for (const CanFrame& f : corruptions_of(encode_sdo_upload_response(node, 0x1000, 0, 1, 4))) {
    EXPECT_FALSE(decode_sdo_response(f, node));
  }
  for (const CanFrame& f : corruptions_of(encode_rpdo1(node, {}))) {
    EXPECT_FALSE(decode_rpdo1(f, node));
  }
  for (const CanFrame& f : corruptions_of(encode_tpdo1(node, {}))) {
    EXPECT_FALSE(decode_tpdo1(f, node));
  }
  for (const CanFrame& f : corruptions_of(encode_tpdo2(node, {}))) {
    EXPECT_FALSE(decode_tpdo2(f, node));
  }
  for (const CanFrame& f : corruptions_of(encode_sync(5))) {
    if (f.len != 0) {  // a SYNC without counter is legal
      EXPECT_FALSE(decode_sync(f));
    }
  }
}

TEST(MalformedFrames, UnknownNmtCommandAndOutOfRangeNodeAreRefused) {
  CanFrame f = encode_nmt(NmtCommand::start, node);
  for (const int cs : {0x00, 0x03, 0x7F, 0x83, 0xFF}) {
    f.data[0] = static_cast<std::uint8_t>(cs);
    EXPECT_FALSE(decode_nmt(f)) << cs;
  }
  f = encode_nmt(NmtCommand::start, 128);
  EXPECT_FALSE(decode_nmt(f));
}

TEST(MalformedFrames, SdoForAnotherNodeOrOnTheResponseIdIsNotAnswered) {
  EXPECT_FALSE(decode_sdo_request(encode_sdo_upload_request(node + 1, 0x1000, 0), node));
  EXPECT_FALSE(decode_sdo_request(encode_sdo_upload_response(node, 0x1000, 0, 0, 4), node));
  EXPECT_FALSE(decode_sdo_request(encode_sdo_upload_request(node, 0x1000, 0), 0)) << "node 0 has no SDO";
}

class DriveRejects : public ::testing::Test {
 protected:
  DriveRejects() {
    FrameBuffer<4> boot;
    drive.start(0, boot);
    FrameBuffer<4> out;
    (void)drive.on_frame(encode_nmt(NmtCommand::start, node), 0, out);
  }

  // The frame must leave every object and both state machines as they were, and produce
  // nothing on the bus.
  void expect_no_effect(const CanFrame& f, const char* what) {
    const auto before = snapshot(drive);
    FrameBuffer<8> out;
    const DriveEvent e = drive.on_frame(f, 1000, out);
    EXPECT_TRUE(e == DriveEvent::none || e == DriveEvent::handled) << what;
    // A latched RPDO is only applied at SYNC; a bad one must be refused there.
    (void)drive.on_frame(encode_sync(), 2000, out);
    EXPECT_EQ(snapshot(drive), before) << what;
    for (std::size_t i = 0; i < out.size(); ++i) {
      EXPECT_NE(out[i].id, cob_id(cob::sdo_tx, node)) << what << ": no SDO answer";
    }
  }

  DriveNode drive{DriveNodeConfig{node}};
};

TEST_F(DriveRejects, WrongLengthSdoIsIgnored) {
  for (const CanFrame& f : corruptions_of(encode_sdo_download_request(node, 0x6060, 0, 7, 1))) {
    expect_no_effect(f, "corrupted SDO download");
  }
}

TEST_F(DriveRejects, SdoForAnotherNodeIsIgnored) {
  expect_no_effect(encode_sdo_download_request(node + 1, 0x6060, 0, 7, 1), "SDO to another node");
}

TEST_F(DriveRejects, ShortRpdoIsNotAppliedLongerIsAppliedFromItsMappedBytes) {
  for (const int len : {0, 1, 5, 7, 8}) {
    CanFrame f = encode_rpdo1(node, Rpdo1{0x0006, 999});
    f.len = static_cast<std::uint8_t>(len);
    FrameBuffer<8> out;
    (void)drive.on_frame(f, 1000, out);
    (void)drive.on_frame(encode_sync(), 2000, out);
    // Shorter: nothing changes but the error objects. Longer: the six mapped bytes are taken
    // (controlword "shutdown", target 999), the rest ignored. Either way EMCY 0x8210/0x8220.
    EXPECT_EQ(drive.objects().app.target_position, len < 6 ? 0 : 999) << len;
    EXPECT_EQ(drive.state(), len < 6 ? Cia402State::switch_on_disabled : Cia402State::ready_to_switch_on) << len;
    ASSERT_FALSE(out.empty()) << len;
    const auto emcy = decode_emcy(out[0]);
    ASSERT_TRUE(emcy);
    EXPECT_EQ(emcy->message.error_code, len < 6 ? emcy_code::pdo_length : emcy_code::pdo_length_exceeded);
  }
}

TEST_F(DriveRejects, RpdoOfAnotherNodeIsIgnored) {
  expect_no_effect(encode_rpdo1(node + 1, Rpdo1{0x0006, 999}), "RPDO of another node");
}

TEST_F(DriveRejects, NmtForAnotherNodeAndMalformedNmtAreIgnored) {
  expect_no_effect(encode_nmt(NmtCommand::stop, node + 1), "NMT stop for another node");
  CanFrame f = encode_nmt(NmtCommand::stop, node);
  f.len = 3;
  expect_no_effect(f, "three-byte NMT");
  f = encode_nmt(NmtCommand::stop, node);
  f.data[0] = 0x03;
  expect_no_effect(f, "unknown NMT command");
}

TEST_F(DriveRejects, ExtendedRtrAndFdFramesAreIgnoredEvenOnCanopenIds) {
  for (const std::uint8_t flags : {can_flag::extended, can_flag::rtr, can_flag::fd}) {
    CanFrame f = encode_sdo_download_request(node, 0x6060, 0, 7, 1);
    f.flags = flags;
    expect_no_effect(f, "non-CANopen frame format");
  }
}

}  // namespace
}  // namespace settle::hal::canopen
