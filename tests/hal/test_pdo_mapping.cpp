// SPDX-License-Identifier: Apache-2.0
// The drive's PDOs over SDO (DriveNode): dynamic mapping by the CiA 301 procedure (disable via
// COB-ID bit 31, mapping sub 0 = 0, entries, sub 0 = n, enable), each wrong order refused with
// its abort code, the mapped PDOs then carrying the right bytes; the static mapping read-only;
// the drive's optional objects and identity as its configuration says.
#include <gtest/gtest.h>

#include <initializer_list>
#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/drive_node.hpp"

namespace settle::hal::canopen {
namespace {

constexpr NodeId node = 3;

DriveNodeConfig writable_config() {
  DriveNodeConfig c{};
  c.node = node;
  c.pdo_mapping_writable = true;
  c.rpdo_count = 4;
  c.tpdo_count = 4;
  return c;
}

class DrivePdos : public ::testing::Test {
 protected:
  void make(const DriveNodeConfig& config) { drive.emplace(config); }

  // An expedited SDO download of `size` bytes: none, or the drive's abort code.
  SdoAbort write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size = 4) {
    out.clear();
    EXPECT_EQ(drive->on_frame(encode_sdo_download_request(node, index, sub, value, size), now, out),
              DriveEvent::handled);
    EXPECT_EQ(out.size(), 1U);
    const auto answer = out.empty() ? std::nullopt : decode_sdo_response(out[0], node);
    if (!answer) {
      ADD_FAILURE() << "no SDO answer";
      return SdoAbort::general_error;
    }
    return answer->kind == SdoKind::abort ? static_cast<SdoAbort>(answer->abort_code) : SdoAbort::none;
  }
  std::uint32_t read(std::uint16_t index, std::uint8_t sub) {
    std::uint32_t raw = 0;
    std::uint8_t size = 0;
    EXPECT_EQ(drive->dictionary().read(index, sub, raw, size), SdoAbort::none)
        << std::hex << index << ":" << int{sub};
    return raw;
  }
  SdoAbort upload_abort(std::uint16_t index, std::uint8_t sub) {
    out.clear();
    (void)drive->on_frame(encode_sdo_upload_request(node, index, sub), now, out);
    const auto answer = out.empty() ? std::nullopt : decode_sdo_response(out[0], node);
    return answer && answer->kind == SdoKind::abort ? static_cast<SdoAbort>(answer->abort_code) : SdoAbort::none;
  }
  // The CiA 301 sequence for one PDO: disable, clear, entries, count, enable.
  void map(std::uint16_t comm, std::uint32_t cob, const std::vector<std::uint32_t>& entries) {
    const auto mapping = static_cast<std::uint16_t>(comm + 0x200);
    ASSERT_EQ(write(comm, 1, cob | pdo_cob_invalid), SdoAbort::none);
    ASSERT_EQ(write(mapping, 0, 0, 1), SdoAbort::none);
    for (std::size_t i = 0; i < entries.size(); ++i) {
      ASSERT_EQ(write(mapping, static_cast<std::uint8_t>(i + 1), entries[i]), SdoAbort::none);
    }
    ASSERT_EQ(write(mapping, 0, static_cast<std::uint32_t>(entries.size()), 1), SdoAbort::none);
    ASSERT_EQ(write(comm, 1, cob), SdoAbort::none);
  }
  void operational() {
    out.clear();
    ASSERT_EQ(drive->on_frame(encode_nmt(NmtCommand::start, node), now, out), DriveEvent::handled);
  }
  // A SYNC, then the period's feedback; returns the frames the drive sent.
  std::vector<CanFrame> sync_and_publish(const DriveFeedback& feedback) {
    now += 1000;
    out.clear();
    EXPECT_EQ(drive->on_frame(sync_producer.next(), now, out), DriveEvent::sync);
    drive->publish(feedback, now, out);
    std::vector<CanFrame> sent;
    for (std::size_t i = 0; i < out.size(); ++i) {
      sent.push_back(out[i]);
    }
    return sent;
  }
  void receive(const CanFrame& f) {
    out.clear();
    EXPECT_EQ(drive->on_frame(f, now, out), DriveEvent::handled) << std::hex << f.id;
  }

  std::optional<DriveNode> drive{std::in_place, writable_config()};
  FrameBuffer<16> out;
  SyncProducer sync_producer{1000};
  std::uint64_t now{0};
};

TEST_F(DrivePdos, TheDefaultDriveHasTodaysStaticPdosReadOnly) {
  DriveNodeConfig c{};
  c.node = node;
  make(c);
  EXPECT_EQ(write(0x1600, 0, 0, 1), SdoAbort::read_only);
  EXPECT_EQ(write(0x1400, 1, 0x8000'0203U), SdoAbort::read_only);
  EXPECT_EQ(write(0x1A01, 1, 0x6064'0020U), SdoAbort::read_only);
  EXPECT_EQ(write(0x1800, 2, 2, 1), SdoAbort::read_only);
  EXPECT_EQ(upload_abort(0x1401, 1), SdoAbort::no_object) << "RPDO2 does not exist";
  EXPECT_EQ(upload_abort(0x1A02, 0), SdoAbort::no_object) << "TPDO3 does not exist";
  EXPECT_EQ(upload_abort(0x1600, 3), SdoAbort::no_sub_index) << "a static mapping lists its entries only";
  EXPECT_EQ(read(0x1600, 0), 2U);
  EXPECT_EQ(read(0x1600, 1), 0x6040'0010U);
  EXPECT_EQ(read(0x1600, 2), 0x607A'0020U);
  EXPECT_EQ(read(0x1A01, 2), 0x606C'0020U);
  EXPECT_EQ(drive->default_mapping_error(), SdoAbort::none);
  EXPECT_TRUE(drive->rpdo_active(0));
  EXPECT_TRUE(drive->tpdo_active(1));
  EXPECT_FALSE(drive->tpdo_active(2));
}

TEST_F(DrivePdos, AWritableDriveListsEveryPdoAndEveryMappingSubIndex) {
  ASSERT_TRUE(drive->dictionary().is_well_formed());
  // 46 fixed rows, and per PDO communication sub 0..2 and mapping sub 0..8.
  EXPECT_EQ(drive->dictionary().entries().size(), 46U + 8U * 12U) << "the table's capacity is exact";
  EXPECT_EQ(read(0x1403, 1), 0x8000'0503U) << "RPDO4: predefined id, not valid";
  EXPECT_EQ(read(0x1803, 1), 0x8000'0483U);
  EXPECT_EQ(read(0x1603, 8), 0U);
  EXPECT_EQ(read(0x1A00, 0), 2U);
  EXPECT_FALSE(drive->rpdo_active(1));
  EXPECT_TRUE(drive->rpdo_active(0));
}

TEST_F(DrivePdos, TheProcedureInOrderIsAcceptedAndSplitRpdosDriveTheAxis) {
  // RPDO1: controlword only; RPDO2: the target.
  map(0x1400, 0x203, {0x6040'0010U});
  map(0x1401, 0x303, {0x607A'0020U});
  EXPECT_EQ(read(0x1600, 0), 1U);
  EXPECT_EQ(read(0x1601, 1), 0x607A'0020U);
  EXPECT_TRUE(drive->rpdo_active(1));
  operational();
  receive(test::frame(0x203, {0x06, 0x00}));
  receive(test::frame(0x303, {0x10, 0x27, 0x00, 0x00}));
  (void)sync_and_publish({});
  EXPECT_EQ(drive->objects().app.controlword, 0x0006);
  EXPECT_EQ(drive->objects().app.target_position, 10000);
  EXPECT_EQ(drive->state(), Cia402State::ready_to_switch_on);
  EXPECT_EQ(drive->counters().rpdos_applied, 2U);
}

TEST_F(DrivePdos, RpdoLossIsAMissingTargetWhicheverPdoCarriesIt) {
  map(0x1400, 0x203, {0x6040'0010U});
  map(0x1401, 0x303, {0x607A'0020U});
  operational();
  for (const std::uint8_t cw : std::initializer_list<std::uint8_t>{0x06, 0x07, 0x0F}) {
    receive(test::frame(0x203, {cw, 0x00}));
    receive(test::frame(0x303, {0, 0, 0, 0}));
    (void)sync_and_publish({});
  }
  ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
  // The controlword keeps coming, the target does not: RPDO loss after 0x2001 (3) periods.
  for (int i = 0; i < 4; ++i) {
    receive(test::frame(0x203, {0x0F, 0x00}));
    (void)sync_and_publish({});
  }
  EXPECT_EQ(drive->counters().rpdos_missing, 4U);
  EXPECT_EQ(drive->objects().app.error_code, emcy_code::rpdo_timeout);
  EXPECT_NE(drive->state(), Cia402State::operation_enabled);
}

TEST_F(DrivePdos, NoPdoIsRemappedOrMovedUnderAnEnabledDriveWhileOperational) {
  operational();
  for (const std::uint16_t cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
    receive(encode_rpdo1(node, Rpdo1{cw, 0}));
    (void)sync_and_publish({});
  }
  ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
  // The TPDO1 re-map (position actual replaced by the target), every step refused, and
  // the other communication and mapping objects of both directions too.
  EXPECT_EQ(write(0x1800, 1, 0x183U | pdo_cob_invalid), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(write(0x1A00, 0, 0, 1), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(write(0x1A00, 2, 0x607A'0020U), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(write(0x1800, 2, 2, 1), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(write(0x1400, 1, 0x203U | pdo_cob_invalid), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(write(0x1400, 2, 5, 1), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(write(0x1600, 0, 0, 1), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(write(0x1401, 1, 0x303U, 4), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(write(0x1601, 1, 0x607A'0020U), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(read(0x1A00, 2), 0x6064'0020U);
  EXPECT_TRUE(drive->tpdo_active(0));
  EXPECT_TRUE(drive->rpdo_active(0));
  // The TPDO still carries the position actual.
  const auto sent = sync_and_publish({1234, 0, 0});
  ASSERT_FALSE(sent.empty());
  EXPECT_EQ(sent[0].id, 0x183U);
  EXPECT_EQ(decode_tpdo1(sent[0], node)->position_actual, 1234);

  // Disabled (operational): the procedure is allowed again.
  receive(encode_rpdo1(node, Rpdo1{controlword::switch_on, 0}));
  (void)sync_and_publish({});
  ASSERT_EQ(drive->state(), Cia402State::switched_on);
  EXPECT_EQ(write(0x1800, 2, 2, 1), SdoAbort::none);
}

TEST_F(DrivePdos, EachWrongStepIsRefusedWithItsAbortCode) {
  // RPDO1 is valid: its mapping cannot change, nor its id.
  EXPECT_EQ(write(0x1600, 0, 0, 1), SdoAbort::invalid_value);
  EXPECT_EQ(write(0x1600, 1, 0x6040'0010U), SdoAbort::invalid_value);
  EXPECT_EQ(write(0x1400, 1, 0x204), SdoAbort::invalid_value);
  EXPECT_EQ(write(0x1400, 1, 0x2000'0203U), SdoAbort::invalid_value) << "29-bit ids are not supported";
  EXPECT_EQ(write(0x1400, 1, 0x8000'0803U), SdoAbort::invalid_value) << "bits 11..28";
  EXPECT_EQ(write(0x1400, 1, 0x8000'0000U), SdoAbort::invalid_value) << "id 0";
  // Disabled, but sub 0 not yet 0: the entries stay locked.
  ASSERT_EQ(write(0x1400, 1, 0x8000'0203U), SdoAbort::none);
  EXPECT_EQ(write(0x1600, 1, 0x6040'0010U), SdoAbort::invalid_value);
  ASSERT_EQ(write(0x1600, 0, 0, 1), SdoAbort::none);
  EXPECT_EQ(write(0x1400, 1, 0x203), SdoAbort::invalid_value) << "no mapping: cannot enable";
  // Each entry is checked when sub 0 names it.
  ASSERT_EQ(write(0x1600, 1, 0x5555'0020U), SdoAbort::none);
  EXPECT_EQ(write(0x1600, 0, 1, 1), SdoAbort::no_object);
  ASSERT_EQ(write(0x1600, 1, 0x1000'0020U), SdoAbort::none);
  EXPECT_EQ(write(0x1600, 0, 1, 1), SdoAbort::not_mappable) << "device type is not mappable";
  ASSERT_EQ(write(0x1600, 1, 0x60C2'0508U), SdoAbort::none);
  EXPECT_EQ(write(0x1600, 0, 1, 1), SdoAbort::no_sub_index);
  ASSERT_EQ(write(0x1600, 1, 0x607A'0010U), SdoAbort::none);
  EXPECT_EQ(write(0x1600, 0, 1, 1), SdoAbort::length_mismatch) << "0x607A is 32 bits";
  ASSERT_EQ(write(0x1600, 1, 0x6041'0010U), SdoAbort::none);
  EXPECT_EQ(write(0x1600, 0, 1, 1), SdoAbort::not_mappable) << "an RPDO cannot write the statusword";
  ASSERT_EQ(write(0x1600, 1, 0x607A'0020U), SdoAbort::none);
  ASSERT_EQ(write(0x1600, 2, 0x6064'0020U), SdoAbort::none);
  ASSERT_EQ(write(0x1600, 3, 0x6040'0010U), SdoAbort::none);
  EXPECT_EQ(write(0x1600, 0, 3, 1), SdoAbort::pdo_too_long) << "80 bits";
  EXPECT_EQ(write(0x1600, 0, 9, 1), SdoAbort::value_too_high);
  EXPECT_EQ(read(0x1600, 0), 0U) << "a refused count is not stored";
  EXPECT_EQ(write(0x1400, 1, 0x203), SdoAbort::invalid_value);
  EXPECT_FALSE(drive->rpdo_active(0));
  // Transmission types: synchronous 1..240 only.
  EXPECT_EQ(write(0x1400, 2, 0, 1), SdoAbort::invalid_value);
  EXPECT_EQ(write(0x1800, 2, 241, 1), SdoAbort::invalid_value);
  EXPECT_EQ(write(0x1800, 2, 0xFF, 1), SdoAbort::invalid_value);
  EXPECT_EQ(write(0x1800, 2, 240, 1), SdoAbort::none);
}

TEST_F(DrivePdos, MappedTpdosCarryTheirObjectsEveryNthSync) {
  map(0x1802, 0x383, {0x606C'0020U, 0x60F4'0020U});
  ASSERT_EQ(write(0x1802, 2, 2, 1), SdoAbort::none);
  // TPDO2 off: a disabled PDO is not sent.
  ASSERT_EQ(write(0x1801, 1, 0x8000'0283U), SdoAbort::none);
  operational();
  std::vector<std::vector<CanFrame>> periods;
  for (int i = 0; i < 4; ++i) {
    periods.push_back(sync_and_publish(DriveFeedback{-3, 0x01020304, 7}));
  }
  const auto ids = [](const std::vector<CanFrame>& frames) {
    std::vector<std::uint32_t> v;
    for (const CanFrame& f : frames) {
      v.push_back(f.id);
    }
    return v;
  };
  EXPECT_EQ(ids(periods[0]), (std::vector<std::uint32_t>{0x183}));
  EXPECT_EQ(ids(periods[1]), (std::vector<std::uint32_t>{0x183, 0x383}));
  EXPECT_EQ(ids(periods[2]), (std::vector<std::uint32_t>{0x183}));
  EXPECT_EQ(ids(periods[3]), (std::vector<std::uint32_t>{0x183, 0x383}));
  // Velocity, then following error (setpoint held at the position actual, -3: zero).
  EXPECT_EQ(test::bytes_of(periods[1][1]), (std::vector<std::uint8_t>{0x04, 0x03, 0x02, 0x01, 0, 0, 0, 0}));
}

TEST_F(DrivePdos, ADisabledRpdoIsNotApplied) {
  operational();
  ASSERT_EQ(write(0x1400, 1, 0x8000'0203U), SdoAbort::none);
  out.clear();
  EXPECT_EQ(drive->on_frame(test::frame(0x203, {0x06, 0, 0x10, 0, 0, 0}), now, out), DriveEvent::none);
  (void)sync_and_publish({});
  EXPECT_EQ(drive->objects().app.controlword, 0);
  EXPECT_EQ(drive->counters().rpdos_applied, 0U);
}

TEST_F(DrivePdos, ResetCommunicationRestoresTheDefaultMapping) {
  map(0x1400, 0x203, {0x6040'0010U});
  out.clear();
  (void)drive->on_frame(encode_nmt(NmtCommand::reset_communication, node), now, out);
  EXPECT_EQ(read(0x1600, 0), 2U);
  EXPECT_EQ(read(0x1600, 2), 0x607A'0020U);
  EXPECT_TRUE(drive->rpdo_active(0));
}

TEST_F(DrivePdos, ADefaultMappingThatCannotBindIsReportedAndTheLengthRulesFollowTheMapping) {
  DriveNodeConfig c = writable_config();
  c.rpdos[0].entries[0] = PdoMappingEntry{0x6041, 0, 16};
  make(c);
  EXPECT_EQ(drive->default_mapping_error(), SdoAbort::not_mappable);
  EXPECT_FALSE(drive->rpdo_active(0));

  make(writable_config());
  map(0x1401, 0x303, {0x607A'0020U});
  operational();
  out.clear();
  (void)drive->on_frame(test::frame(0x303, {1, 2, 3}), now, out);
  ASSERT_EQ(out.size(), 1U) << "a short RPDO2: EMCY 0x8210";
  EXPECT_EQ(decode_emcy(out[0])->message.error_code, emcy_code::pdo_length);
}

TEST_F(DrivePdos, OptionalObjectsAndIdentityFollowTheConfiguration) {
  DriveNodeConfig c{};
  c.node = node;
  c.has_interpolation_period = false;
  c.has_following_error_actual = false;
  c.device_type = 0x0004'0192U;
  c.vendor_id = 0x1234;
  c.product_code = 0x42;
  c.sync_period_us = 2000;
  make(c);
  EXPECT_EQ(upload_abort(0x60C2, 1), SdoAbort::no_object);
  EXPECT_EQ(upload_abort(0x60F4, 0), SdoAbort::no_object);
  EXPECT_EQ(read(0x1000, 0), 0x0004'0192U);
  EXPECT_EQ(read(0x1018, 1), 0x1234U);
  EXPECT_EQ(read(0x1018, 2), 0x42U);
  EXPECT_EQ(drive->interpolation_period_us(), 2000U) << "without 0x60C2 the drive interpolates over 0x1006";
  EXPECT_TRUE(drive->dictionary().is_well_formed());
}

}  // namespace
}  // namespace settle::hal::canopen
