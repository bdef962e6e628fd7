// SPDX-License-Identifier: Apache-2.0
// The simulated drive configured from an EDS (testbed::simulated_drive_from_eds): the bundled
// settle_drive.eds is exactly the default drive; the other bundled drives load and answer SDO with
// their identity and mapping; an EDS the simulated drive cannot be is refused naming the object.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/hal/eds_drive_config.hpp"
#include "settle/hal/frame_sink.hpp"
#include "settle/testbed/drive_from_eds.hpp"
#include "settle/testbed/simulated_drive.hpp"

namespace settle::testbed {
namespace {

namespace co = hal::canopen;

std::string eds_path(const std::string& name) { return std::string{SETTLE_EDS_DIR} + "/" + name; }

std::string file_text(const std::string& path) {
  std::ifstream in{path};
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A drive built from the file's configuration; the result holds the strings the drive serves.
struct Loaded {
  DriveFromEds eds;
  std::optional<co::DriveNode> drive;
};
std::unique_ptr<Loaded> loaded(const std::string& path, co::NodeId node) {
  auto l = std::make_unique<Loaded>();
  l->eds = load_drive_config(path, node);
  EXPECT_TRUE(l->eds.config.has_value()) << l->eds.error;
  l->drive.emplace(l->eds.config.value_or(co::DriveNodeConfig{}));
  return l;
}

std::string text_of(co::DriveNode& drive, std::uint16_t index) {
  const co::OdEntry* e = drive.dictionary().find(index, 0);
  if (e == nullptr || e->var.bytes() == nullptr) return "<none>";
  const auto v = e->var.bytes()->view();
  return {v.begin(), v.end()};
}

void expect_same_pdos(const co::PdoMapping& a, const co::PdoMapping& b, const char* what, std::size_t i) {
  EXPECT_EQ(a.cob_id, b.cob_id) << what << i;
  EXPECT_EQ(a.transmission_type, b.transmission_type) << what << i;
  ASSERT_EQ(a.count, b.count) << what << i;
  for (std::size_t k = 0; k < a.count; ++k) {
    EXPECT_EQ(a.entries[k].raw(), b.entries[k].raw()) << what << i << " entry " << k;
  }
}

std::uint32_t read(co::DriveNode& drive, std::uint16_t index, std::uint8_t sub) {
  std::uint32_t raw = 0;
  std::uint8_t size = 0;
  EXPECT_EQ(drive.dictionary().read(index, sub, raw, size), co::SdoAbort::none) << std::hex << index;
  return raw;
}

// The identity and device name the drive answers with.
void expect_identity(co::DriveNode& drive, std::uint32_t vendor, std::uint32_t product, const std::string& name) {
  EXPECT_EQ(read(drive, 0x1018, 1), vendor);
  EXPECT_EQ(read(drive, 0x1018, 2), product);
  EXPECT_EQ(text_of(drive, 0x1008), name);
}

TEST(DriveFromEds, TheBundledEdsIsTheDefaultDrive) {
  for (const co::NodeId node : {co::NodeId{1}, co::NodeId{42}, co::NodeId{127}}) {
    const auto l = loaded(SETTLE_DRIVE_EDS_PATH, node);
    const co::DriveNodeConfig& c = *l->eds.config;
    co::DriveNodeConfig d{};
    d.node = node;
    EXPECT_EQ(c.node, d.node);
    EXPECT_EQ(c.heartbeat_period_ms, d.heartbeat_period_ms);
    EXPECT_EQ(c.sync_period_us, d.sync_period_us);
    EXPECT_EQ(c.sync_counter_overflow, d.sync_counter_overflow);
    EXPECT_EQ(c.communication_loss_periods, d.communication_loss_periods);
    EXPECT_EQ(c.quick_stop_option, d.quick_stop_option);
    EXPECT_EQ(c.abort_connection_option, d.abort_connection_option);
    EXPECT_EQ(c.following_error_window, d.following_error_window);
    EXPECT_EQ(c.following_error_timeout_ms, d.following_error_timeout_ms);
    EXPECT_EQ(c.max_profile_velocity, d.max_profile_velocity);
    EXPECT_EQ(c.position_limit_min, d.position_limit_min);
    EXPECT_EQ(c.position_limit_max, d.position_limit_max);
    EXPECT_EQ(c.vendor_id, d.vendor_id);
    EXPECT_EQ(c.product_code, d.product_code);
    EXPECT_EQ(c.revision, d.revision);
    EXPECT_EQ(c.serial, d.serial);
    EXPECT_EQ(c.device_type, d.device_type);
    EXPECT_STREQ(c.device_name, d.device_name);
    EXPECT_STREQ(c.hardware_version, d.hardware_version);
    EXPECT_STREQ(c.software_version, d.software_version);
    EXPECT_EQ(c.has_interpolation_period, d.has_interpolation_period);
    EXPECT_EQ(c.has_following_error_actual, d.has_following_error_actual);
    EXPECT_EQ(c.has_velocity_actual, d.has_velocity_actual);
    EXPECT_EQ(c.pdo_mapping_writable, d.pdo_mapping_writable);
    EXPECT_EQ(c.rpdo_count, d.rpdo_count);
    EXPECT_EQ(c.tpdo_count, d.tpdo_count);
    for (std::size_t i = 0; i < d.rpdo_count; ++i) expect_same_pdos(c.rpdos[i], d.rpdos[i], "RPDO index ", i);
    for (std::size_t i = 0; i < d.tpdo_count; ++i) expect_same_pdos(c.tpdos[i], d.tpdos[i], "TPDO index ", i);
  }
}

TEST(DriveFromEds, SplitRpdoDriveHasControlwordAndTargetInTwoWritablePdos) {
  const auto l = loaded(eds_path("split_rpdo_drive.eds"), 5);
  co::DriveNode& drive = *l->drive;
  expect_identity(drive, 0x5E01, 0xA001, "Split-RPDO servo (simulated)");
  EXPECT_EQ(text_of(drive, 0x100A), "Settle 0.1.0");
  EXPECT_EQ(read(drive, 0x1600, 0), 1U);
  EXPECT_EQ(read(drive, 0x1600, 1), 0x6040'0010U);
  EXPECT_EQ(read(drive, 0x1601, 1), 0x607A'0020U);
  EXPECT_EQ(read(drive, 0x1401, 1), 0x305U);
  EXPECT_EQ(read(drive, 0x1402, 1), 0x8000'0405U);
  EXPECT_TRUE(drive.rpdo_active(1));
  EXPECT_EQ(drive.dictionary().write(0x1600, 0, 0, 1), co::SdoAbort::invalid_value) << "writable, by the procedure";
  EXPECT_EQ(drive.dictionary().write(0x1400, 1, 0x8000'0205U, 4), co::SdoAbort::none);
  EXPECT_EQ(drive.dictionary().write(0x1600, 0, 0, 1), co::SdoAbort::none);
}

TEST(DriveFromEds, VelocityFeedbackDriveLeavesTheLoadPositionUnmapped) {
  const auto l = loaded(eds_path("velocity_feedback_drive.eds"), 5);
  co::DriveNode& drive = *l->drive;
  expect_identity(drive, 0x5E02, 0xB002, "Velocity-feedback servo (simulated)");
  EXPECT_EQ(read(drive, 0x1A01, 0), 2U);
  EXPECT_EQ(read(drive, 0x1A01, 1), 0x606C'0020U);
  EXPECT_EQ(read(drive, 0x1A01, 2), 0x60F4'0020U);
  std::uint32_t raw = 0;
  std::uint8_t size = 0;
  EXPECT_EQ(drive.dictionary().read(0x2000, 0, raw, size), co::SdoAbort::none) << "the load position exists";
  for (std::uint16_t m = 0x1A00; m < 0x1A04; ++m) {
    for (std::uint8_t s = 1; s <= 8; ++s) EXPECT_NE(read(drive, m, s) >> 16U, 0x2000U) << "not mapped by default";
  }
}

TEST(DriveFromEds, StaticMappingDriveIsReadOnlyAndSuitable) {
  const auto l = loaded(eds_path("static_mapping_drive.eds"), 5);
  co::DriveNode& drive = *l->drive;
  expect_identity(drive, 0x5E03, 0xC003, "Static-mapping servo (simulated)");
  EXPECT_EQ(read(drive, 0x1A01, 1), 0x2000'0020U);
  EXPECT_EQ(drive.dictionary().write(0x1600, 0, 0, 1), co::SdoAbort::read_only);
  EXPECT_EQ(drive.dictionary().write(0x1400, 1, 0x8000'0205U, 4), co::SdoAbort::read_only);
}

TEST(DriveFromEds, TheTestDriveWithout60C2HasNone) {
  const auto l = loaded(std::string{SETTLE_TEST_DATA_DIR} + "/no_interpolation_period_drive.eds", 5);
  co::DriveNode& drive = *l->drive;
  std::uint32_t raw = 0;
  std::uint8_t size = 0;
  EXPECT_EQ(drive.dictionary().read(0x60C2, 1, raw, size), co::SdoAbort::no_object);
  expect_identity(drive, 0x5E04, 0xD004, "Drive without 0x60C2 (simulated)");
}

// Issue 35: a drive without the load position 0x2000 (its TPDO2 the velocity alone), and one
// without the communication cycle period 0x1006 (CiA 301 asks it only of the SYNC producer): each
// simulated without the object, which it then does not serve.
TEST(DriveFromEds, TheTestDrivesWithoutALoadPositionOrA1006HaveNone) {
  std::uint32_t raw = 0;
  std::uint8_t size = 0;
  const auto no_load = loaded(std::string{SETTLE_TEST_DATA_DIR} + "/no_load_position_drive.eds", 1);
  ASSERT_TRUE(no_load->eds.config);
  EXPECT_FALSE(no_load->eds.config->has_load_position);
  EXPECT_TRUE(no_load->eds.config->has_communication_cycle_period);
  EXPECT_EQ(no_load->drive->dictionary().read(0x2000, 0, raw, size), co::SdoAbort::no_object);
  EXPECT_EQ(read(*no_load->drive, 0x1A01, 0), 1U);
  EXPECT_EQ(read(*no_load->drive, 0x1A01, 1), 0x606C'0020U);
  const auto no_cycle = loaded(std::string{SETTLE_TEST_DATA_DIR} + "/no_cycle_period_drive.eds", 1);
  ASSERT_TRUE(no_cycle->eds.config);
  EXPECT_FALSE(no_cycle->eds.config->has_communication_cycle_period);
  EXPECT_EQ(no_cycle->eds.config->sync_period_us, 0U);
  EXPECT_TRUE(no_cycle->eds.config->has_load_position);
  EXPECT_EQ(no_cycle->drive->dictionary().read(0x1006, 0, raw, size), co::SdoAbort::no_object);
}

// The master configured from `description` (velocity actual asked for when `velocity`) against
// `drive`, both started, the drive enabled, then `periods` SYNCs: the TPDOs (id, length) the drive
// sent on those SYNCs, the periods the master took of them, and its feedback after.
struct Streamed {
  std::vector<std::pair<std::uint32_t, std::uint8_t>> tpdos;
  std::uint64_t periods_taken{0};
  co::RemoteFeedback feedback{};
};
Streamed stream_against(co::DriveNode& drive, const hal::eds::Description& description, bool velocity,
                        int periods) {
  Streamed s;
  co::RemoteDriveConfig base{};
  base.node = 1;
  const hal::eds::DriveConfigResult cfg =
      hal::eds::drive_config_from_eds(description, base, hal::eds::FeedbackRequest{velocity, false, 0, 0});
  EXPECT_TRUE(cfg.ok()) << cfg.error;
  if (!cfg.ok()) return s;
  co::RemoteDrive master{cfg.config};
  hal::FrameBuffer<32> to_drive;
  hal::FrameBuffer<32> to_master;
  std::uint64_t now = 0;
  std::int32_t axis = 1234;
  const auto exchange = [&](bool sync) {
    hal::CanFrame rpdo{};
    if (master.rpdo(axis, rpdo)) (void)to_drive.put(rpdo);
    if (sync) (void)to_drive.put(co::encode_sync());
    const std::vector<hal::CanFrame> requests(to_drive.frames().begin(), to_drive.frames().end());
    to_drive.clear();
    for (const hal::CanFrame& f : requests) {
      if (drive.on_frame(f, now, to_master) == co::DriveEvent::sync) {
        if (drive.following()) axis = drive.setpoint();
        const std::size_t before = to_master.size();
        drive.publish(co::DriveFeedback{axis, 0, 0}, now, to_master);
        for (std::size_t i = before; i < to_master.size(); ++i) s.tpdos.emplace_back(to_master[i].id, to_master[i].len);
      }
    }
    drive.poll(now, to_master);
    const std::vector<hal::CanFrame> answers(to_master.frames().begin(), to_master.frames().end());
    to_master.clear();
    for (const hal::CanFrame& f : answers) (void)master.on_frame(f, now, to_drive);
    now += 1000;
    master.poll(now, to_drive);
  };
  drive.start(now, to_master);
  to_master.clear();
  master.start(now, to_drive);
  for (int i = 0; i < 500 && master.state() == co::RemoteDriveState::configuring; ++i) exchange(false);
  EXPECT_EQ(master.state(), co::RemoteDriveState::enabling) << co::to_string(master.failure().error);
  for (int i = 0; i < 50 && !master.ready(); ++i) exchange(true);
  EXPECT_TRUE(master.ready());
  const std::uint64_t taken_to_ready = master.feedback().tpdo1_received;
  s.tpdos.clear();
  for (int i = 0; i < periods; ++i) exchange(true);
  s.periods_taken = master.feedback().tpdo1_received - taken_to_ready;
  s.feedback = master.feedback();
  return s;
}

// The corpus drive whose static mapping splits the feedback (TPDO1 = statusword + velocity
// actual, TPDO2 = position actual): simulated from its file, it sends both TPDOs on every SYNC as
// the file says, and the master configured from the same file reads each period from the two.
TEST(DriveFromEds, ASplitFeedbackDriveSendsBothTpdosOnEverySync) {
  const std::string path = std::string{SETTLE_TEST_DATA_DIR} + "/../corpus/13_static_split_feedback.eds";
  const auto l = loaded(path, 1);
  const hal::eds::LoadResult eds = hal::eds::load(path);
  ASSERT_TRUE(eds.description) << eds.error;
  const Streamed s = stream_against(*l->drive, *eds.description, true, 10);
  ASSERT_EQ(s.tpdos.size(), 20U) << "two TPDOs per SYNC";
  for (std::size_t i = 0; i < s.tpdos.size(); i += 2) {
    EXPECT_EQ(s.tpdos[i], (std::pair<std::uint32_t, std::uint8_t>{0x181, 6})) << "statusword + velocity actual";
    EXPECT_EQ(s.tpdos[i + 1], (std::pair<std::uint32_t, std::uint8_t>{0x281, 4})) << "position actual";
  }
  EXPECT_EQ(s.periods_taken, 10U) << "every period taken";
  EXPECT_EQ(s.feedback.tpdos_dropped, 0U);
  EXPECT_EQ(s.feedback.position_actual, 1234);
  EXPECT_TRUE(co::is_operation_enabled(s.feedback.statusword));
}

DriveFromEds from_text(const std::string& text) {
  const hal::eds::LoadResult r = hal::eds::parse(text);
  EXPECT_TRUE(r.description.has_value()) << r.error;
  if (!r.description) return {};
  return simulated_drive_from_eds(*r.description, 1);
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(DriveFromEds, WhatTheSimulatedDriveCannotBeIsRefusedNamingTheObject) {
  const std::string base = file_text(SETTLE_DRIVE_EDS_PATH);
  ASSERT_FALSE(base.empty());
  // An object it does not implement.
  DriveFromEds r = from_text(replaced(base, "[ManufacturerObjects]\nSupportedObjects=2\n",
                                      "[ManufacturerObjects]\nSupportedObjects=3\n3=0x2100\n") +
                             "\n[2100]\nParameterName=Brake\nObjectType=0x7\nDataType=0x0005\nAccessType=rw\n"
                             "DefaultValue=0\nPDOMapping=0\n");
  EXPECT_FALSE(r.config);
  EXPECT_NE(r.error.find("0x2100:0 Brake: an object the simulated drive does not implement"), std::string::npos)
      << r.error;
  // A default it cannot take.
  r = from_text(replaced(base, "ParameterName=Modes of operation\nObjectType=0x7\nDataType=0x0002\nAccessType=rw\nDefaultValue=8",
                         "ParameterName=Modes of operation\nObjectType=0x7\nDataType=0x0002\nAccessType=rw\nDefaultValue=7"));
  EXPECT_FALSE(r.config);
  EXPECT_NE(r.error.find("0x6060:0"), std::string::npos) << r.error;
  // A default mapping that cannot be bound: the statusword received.
  r = from_text(replaced(base, "DefaultValue=0x60400010", "DefaultValue=0x60410010"));
  EXPECT_FALSE(r.config);
  EXPECT_NE(r.error.find("cannot be bound (SDO abort 0x06040041): RPDO1 maps 0x6041:0, which is read-only (an "
                         "RPDO writes it)"),
            std::string::npos)
      << r.error;
  // The strings are the EDS's.
  r = from_text(replaced(base, "DefaultValue=Settle simulated CiA 402 drive", "DefaultValue=Other drive"));
  ASSERT_TRUE(r.config) << r.error;
  EXPECT_STREQ(r.config->device_name, "Other drive");
  EXPECT_EQ(r.texts->device_name, "Other drive");
  // An object the drive always has, missing from the EDS (0x6502 taken off the object list).
  std::string without = replaced(replaced(base, "SupportedObjects=35\n", "SupportedObjects=34\n"), "35=0x6502\n", "");
  const auto section = without.find("[6502]");
  ASSERT_NE(section, std::string::npos);
  without.erase(section, without.find("\n\n", section) + 2 - section);
  r = from_text(without);
  EXPECT_FALSE(r.config);
  EXPECT_NE(r.error.find("0x6502:0: the simulated drive always has it, the EDS does not"), std::string::npos)
      << r.error;
  // A missing file.
  r = load_drive_config("/nonexistent/drive.eds", 1);
  EXPECT_FALSE(r.config);
  EXPECT_NE(r.error.find("/nonexistent/drive.eds"), std::string::npos) << r.error;
}

// `text` without object `index` (hex, upper case): its sections and its line in an object list.
std::string without_object(std::string text, const std::string& index) {
  for (auto at = text.find("\n[" + index); at != std::string::npos; at = text.find("\n[" + index)) {
    text.erase(at + 1, text.find("\n\n", at + 1) + 1 - at);
  }
  const auto listed = text.find("=0x" + index + "\n");
  EXPECT_NE(listed, std::string::npos) << index;
  if (listed != std::string::npos) {
    const auto line = text.rfind('\n', listed) + 1;
    text.erase(line, listed + index.size() + 4 - line);
  }
  return text;
}

// A drive whose whole feedback is in TPDO1 (statusword + position actual; no 0x606C, no load
// position: corpus 04 without its 0x606C), whatever its TPDO2 is: mapping nothing (sub 0 = 0, the
// entry it no longer maps still described), absent, or disabled (COB-ID bit 31). The simulated
// drive is each of them and sends TPDO1 alone on every SYNC (a mapping that maps nothing is
// disabled: no empty TPDO2), and the master configured from the same text takes every period.
// What it cannot be is still refused, naming it: no TPDO at all, a disabled TPDO2 mapping an
// object the drive does not have, mapping entries past its capacity.
TEST(DriveFromEds, ADriveWithItsWholeFeedbackInTpdo1SendsItAlone) {
  const std::string no_1006 = file_text(std::string{SETTLE_TEST_DATA_DIR} + "/../corpus/04_no_1006.eds");
  ASSERT_FALSE(no_1006.empty());
  const std::string one_tpdo = without_object(no_1006, "606C");
  const std::string tpdo2_count =
      "[1A01sub0]\nParameterName=Number of mapped objects\nObjectType=0x7\nDataType=0x0005\nAccessType=ro\n"
      "DefaultValue=";
  const std::string tpdo2_cob = "DefaultValue=$NODEID+0x280";
  const std::string maps_nothing = replaced(one_tpdo, tpdo2_count + "1", tpdo2_count + "0");
  const std::string absent = without_object(without_object(one_tpdo, "1801"), "1A01");
  const std::string disabled = replaced(no_1006, tpdo2_cob, "DefaultValue=$NODEID+0x80000280");
  for (const auto& [what, text, tpdos] : {std::tuple{"maps nothing", maps_nothing, 2U},
                                          std::tuple{"absent", absent, 1U}, std::tuple{"disabled", disabled, 2U}}) {
    SCOPED_TRACE(what);
    const hal::eds::LoadResult eds = hal::eds::parse(text);
    ASSERT_TRUE(eds.description) << eds.error;
    const DriveFromEds r = simulated_drive_from_eds(*eds.description, 1);
    ASSERT_TRUE(r.config) << r.error;
    EXPECT_EQ(r.config->tpdo_count, tpdos);
    co::DriveNode drive{*r.config};
    if (std::string{what} == "maps nothing") {
      EXPECT_EQ(read(drive, 0x1A01, 0), 0U);
      EXPECT_EQ(read(drive, 0x1A01, 1), 0x606C0020U) << "the entry it no longer maps, as described";
    }
    const Streamed s = stream_against(drive, *eds.description, false, 10);
    EXPECT_EQ(s.tpdos, (std::vector<std::pair<std::uint32_t, std::uint8_t>>(10, {0x181, 6}))) << "TPDO1 alone";
    EXPECT_EQ(s.periods_taken, 10U);
    EXPECT_EQ(s.feedback.periods_complete, s.feedback.tpdo1_received) << "each period complete with TPDO1";
    EXPECT_EQ(s.feedback.position_actual, 1234);
  }
  const auto refused = [](const std::string& text) {
    const DriveFromEds r = from_text(text);
    EXPECT_FALSE(r.config);
    return r.error;
  };
  const std::string no_tpdo = without_object(without_object(absent, "1800"), "1A00");
  EXPECT_EQ(refused(no_tpdo), "the simulated drive needs RPDO1 and TPDO1 (the EDS describes 1 RPDOs and 0 TPDOs)");
  EXPECT_NE(refused(replaced(one_tpdo, tpdo2_cob, "DefaultValue=$NODEID+0x80000280"))
                .find("cannot be bound (SDO abort 0x06020000): TPDO2 maps 0x606C:0, which the simulated drive does "
                      "not have"),
            std::string::npos);
  EXPECT_EQ(refused(maps_nothing + "\n[1A01sub9]\nParameterName=Entry 9\nObjectType=0x7\nDataType=0x0007\n"
                                   "AccessType=ro\nDefaultValue=0\nPDOMapping=0\n"),
            "TPDO2: mapping entries past sub-index 8 (the simulated drive has 8)");
}

// Another vendor's load encoder where its description puts it (tests/testbed/corpus's
// 12_load_at_2100.eds: 0x2100:1, marked nowhere): without load_at the drive reports no load
// position; with it the drive serves its load position at 0x2100:1, mappable, its dictionary still
// in index order (every entry found where it is); an object that cannot be a load position, and
// Settle's own drive (which keeps its 0x2000), are told apart.
TEST(DriveFromEds, AnotherVendorsLoadEncoderIsServedOnlyWhereTheUserNamesIt) {
  const hal::eds::LoadResult file =
      hal::eds::parse(file_text(std::string{SETTLE_TEST_DATA_DIR} + "/../corpus/12_load_at_2100.eds"));
  ASSERT_TRUE(file.description) << file.error;
  const DriveFromEds plain = simulated_drive_from_eds(*file.description, 1);
  ASSERT_TRUE(plain.config) << plain.error;
  EXPECT_FALSE(plain.config->has_load_position);
  EXPECT_EQ(co::DriveNode{*plain.config}.dictionary().find(0x2100, 1), nullptr);

  const DriveFromEds named = simulated_drive_from_eds(*file.description, 1, hal::eds::MappedObject{0x2100, 1, 32});
  ASSERT_TRUE(named.config) << named.error;
  EXPECT_TRUE(named.config->has_load_position);
  co::DriveNode drive{*named.config};
  const co::OdEntry* load = drive.dictionary().find(0x2100, 1);
  ASSERT_NE(load, nullptr);
  EXPECT_EQ(load->var.type(), co::OdType::i32);
  EXPECT_TRUE(load->pdo_mappable);
  EXPECT_EQ(drive.dictionary().find(0x2000, 0), nullptr);
  const auto entries = drive.dictionary().entries();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    if (i > 0) {
      EXPECT_LT((entries[i - 1].index << 8) | entries[i - 1].sub, (entries[i].index << 8) | entries[i].sub) << i;
    }
    EXPECT_EQ(drive.dictionary().find(entries[i].index, entries[i].sub), &entries[i]) << i;
  }

  for (const auto& [index, sub, why] : {std::tuple{0x2100, 2, "an UNSIGNED32"}, std::tuple{0x2100, 7, "not described"},
                                        std::tuple{0x6064, 0, "not a manufacturer object"}}) {
    const DriveFromEds bad = simulated_drive_from_eds(
        *file.description, 1, hal::eds::MappedObject{static_cast<std::uint16_t>(index), static_cast<std::uint8_t>(sub), 32});
    EXPECT_FALSE(bad.config) << why;
    EXPECT_NE(bad.error.find("the simulated drive serves its load position only in a manufacturer object"),
              std::string::npos)
        << why << ": " << bad.error;
  }

  const hal::eds::LoadResult own = hal::eds::parse(file_text(SETTLE_DRIVE_EDS_PATH));
  ASSERT_TRUE(own.description) << own.error;
  const DriveFromEds settle = simulated_drive_from_eds(*own.description, 1, hal::eds::MappedObject{0x2100, 1, 32});
  ASSERT_TRUE(settle.config) << settle.error;
  EXPECT_EQ(settle.config->load_position_index, co::obj::load_position_actual);
  EXPECT_NE(co::DriveNode{*settle.config}.dictionary().find(0x2000, 0), nullptr);
}

// The one builder of the simulated drive: the description's configuration at the spec's node, with
// only the settings the spec gives applied over it; without a description the default drive; a
// description it cannot be, or an axis that refuses its configuration, builds nothing and says why.
TEST(SimulatedDrive, TheBuilderAppliesTheSpecOverTheDescriptionAndSaysWhyItCannotBuild) {
  const hal::eds::LoadResult file = hal::eds::parse(file_text(SETTLE_DRIVE_EDS_PATH));
  ASSERT_TRUE(file.description) << file.error;
  const DriveFromEds plain = simulated_drive_from_eds(*file.description, 7);
  ASSERT_TRUE(plain.config) << plain.error;
  SimulatedDriveSpec spec{};
  spec.node = 7;
  spec.eds = &*file.description;
  SimulatedDriveError error;
  SimulatedDrive d = build_simulated_drive(spec, error);
  ASSERT_TRUE(d.node) << error.message();
  EXPECT_FALSE(error.any());
  const co::DriveNodeConfig& built = *d.source->config;
  EXPECT_EQ(built.node, 7);
  EXPECT_EQ(built.sync_period_us, plain.config->sync_period_us);
  EXPECT_EQ(built.heartbeat_period_ms, plain.config->heartbeat_period_ms);
  EXPECT_EQ(built.communication_loss_periods, plain.config->communication_loss_periods);
  EXPECT_STREQ(built.device_name, plain.config->device_name);
  EXPECT_EQ(d.node->node().state(), co::Cia402State::switch_on_disabled);

  spec.sync_period_us = plain.config->sync_period_us + 250;
  spec.heartbeat_period_ms = static_cast<std::uint16_t>(plain.config->heartbeat_period_ms + 10);
  spec.communication_loss_periods = static_cast<std::uint8_t>(plain.config->communication_loss_periods + 4);
  const DriveFromEds set = simulated_drive_config(spec);
  ASSERT_TRUE(set.config);
  EXPECT_EQ(set.config->sync_period_us, *spec.sync_period_us);
  EXPECT_EQ(set.config->heartbeat_period_ms, *spec.heartbeat_period_ms);
  EXPECT_EQ(set.config->communication_loss_periods, *spec.communication_loss_periods);

  SimulatedDriveSpec none{};
  none.node = 3;
  const DriveFromEds def = simulated_drive_config(none);
  ASSERT_TRUE(def.config);
  EXPECT_EQ(def.config->node, 3);
  EXPECT_EQ(def.config->max_profile_velocity, co::DriveNodeConfig{}.max_profile_velocity);
  EXPECT_TRUE(build_simulated_drive(none, error).node) << error.message();  // no plant given: the default one

  const hal::eds::LoadResult bad =
      hal::eds::parse(replaced(file_text(SETTLE_DRIVE_EDS_PATH), "DefaultValue=0x60400010", "DefaultValue=0x60410010"));
  ASSERT_TRUE(bad.description) << bad.error;
  spec.eds = &*bad.description;
  d = build_simulated_drive(spec, error);
  EXPECT_FALSE(d.node);
  EXPECT_NE(error.eds.find("RPDO1 maps 0x6041:0"), std::string::npos) << error.eds;
  EXPECT_EQ(error.message(), error.eds);

  none.axis.scale.period_us = 0;
  d = build_simulated_drive(none, error);
  EXPECT_FALSE(d.node);
  EXPECT_TRUE(error.eds.empty());
  EXPECT_EQ(error.axis, plant::SimStatus::non_positive_step);
  EXPECT_EQ(error.message(), "the simulated drive refused its configuration: " + std::string{to_string(error.axis)});
}

}  // namespace
}  // namespace settle::testbed
