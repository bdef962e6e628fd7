// SPDX-License-Identifier: Apache-2.0
// drive_config_from_eds: the objects streaming needs, checked in a drive's description with a
// specific error for each way they can be wrong; dynamic mapping when the description's mapping
// is writable, the drive's static mapping when it is not and carries what is needed; and the
// bundled EDS configured against Settle's drive.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/eds_drive_config.hpp"
#include "settle/hal/eds_reader.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::eds {
namespace {

using canopen::PdoSetup;
using canopen::PdoSlot;

// A description written object by object.
struct Obj {
  std::uint16_t index;
  int sub;  // -1: a VAR; otherwise a sub-index of a RECORD/ARRAY whose sub 0 is written for it
  std::uint16_t type;
  const char* access;
  bool mappable;
  std::string value;
};

class EdsText {
 public:
  EdsText& add(const Obj& o) {
    objects_.push_back(o);
    return *this;
  }
  // A PDO: communication (COB-ID, transmission type) and mapping objects.
  EdsText& pdo(bool receive, unsigned n, bool writable, const std::vector<std::uint32_t>& entries) {
    const auto comm = static_cast<std::uint16_t>((receive ? 0x1400 : 0x1800) + n - 1);
    const auto map = static_cast<std::uint16_t>((receive ? 0x1600 : 0x1A00) + n - 1);
    const unsigned cob = (receive ? 0x200U : 0x180U) + 0x100U * (n - 1U);
    add({comm, 1, data_type::u32, "rw", false, "$NODEID+" + std::to_string(cob)});
    add({comm, 2, data_type::u8, "rw", false, "1"});
    add({map, 0, data_type::u8, writable ? "rw" : "const", false, std::to_string(entries.size())});
    for (std::size_t i = 0; i < 8; ++i) {
      add({map, static_cast<int>(i + 1), data_type::u32, writable ? "rw" : "const", false,
           std::to_string(i < entries.size() ? entries[i] : 0)});
    }
    (receive ? rx_ : tx_) = std::max(receive ? rx_ : tx_, n);
    return *this;
  }
  EdsText& without(std::uint16_t index) {
    std::erase_if(objects_, [index](const Obj& o) { return o.index == index; });
    return *this;
  }
  EdsText& replace(const Obj& o) {
    for (Obj& x : objects_) {
      if (x.index == o.index && x.sub == o.sub) x = o;
    }
    return *this;
  }
  [[nodiscard]] std::string text() const {
    std::string t = "[FileInfo]\nFileName=test.eds\n[DeviceInfo]\nVendorName=Test\nVendorNumber=0x000000AB\n"
                    "ProductName=Test drive\nProductNumber=0x1234\nRevisionNumber=0x00010000\n";
    t += "NrOfRXPDO=" + std::to_string(rx_) + "\nNrOfTXPDO=" + std::to_string(tx_) + "\nGranularity=8\n";
    std::vector<std::uint16_t> indices;
    for (const Obj& o : objects_) {
      if (std::find(indices.begin(), indices.end(), o.index) == indices.end()) indices.push_back(o.index);
    }
    t += "[OptionalObjects]\nSupportedObjects=" + std::to_string(indices.size()) + "\n";
    for (std::size_t i = 0; i < indices.size(); ++i) t += std::to_string(i + 1) + "=" + hex(indices[i]) + "\n";
    for (const std::uint16_t index : indices) {
      std::vector<const Obj*> subs;
      for (const Obj& o : objects_) {
        if (o.index == index) subs.push_back(&o);
      }
      const std::string name = hex(index).substr(2);
      if (subs.size() == 1 && subs[0]->sub < 0) {
        t += "[" + name + "]\nParameterName=o" + name + "\nObjectType=0x7\n" + body(*subs[0]);
        continue;
      }
      int highest = 0;
      for (const Obj* o : subs) highest = std::max(highest, o->sub);
      t += "[" + name + "]\nParameterName=o" + name + "\nObjectType=0x9\nSubNumber=" + std::to_string(highest + 1) + "\n";
      bool have_sub0 = false;
      for (const Obj* o : subs) have_sub0 = have_sub0 || o->sub == 0;
      if (!have_sub0) {
        t += "[" + name + "sub0]\nParameterName=count\nObjectType=0x7\nDataType=0x0005\nAccessType=const\nDefaultValue=" +
             std::to_string(highest) + "\nPDOMapping=0\n";
      }
      for (const Obj* o : subs) {
        t += "[" + name + "sub" + std::to_string(o->sub) + "]\nParameterName=s\nObjectType=0x7\n" + body(*o);
      }
    }
    return t;
  }

 private:
  static std::string hex(std::uint16_t v) {
    char b[8];
    std::snprintf(b, sizeof b, "0x%04X", static_cast<unsigned>(v));
    return b;
  }
  static std::string body(const Obj& o) {
    char type[8];
    std::snprintf(type, sizeof type, "0x%04X", static_cast<unsigned>(o.type));
    return std::string{"DataType="} + type + "\nAccessType=" + o.access + "\nDefaultValue=" + o.value +
           "\nPDOMapping=" + (o.mappable ? "1" : "0") + "\n";
  }
  std::vector<Obj> objects_;
  unsigned rx_{0};
  unsigned tx_{0};
};

// What a CiA 402 drive describes, without PDOs.
EdsText drive_objects() {
  EdsText e;
  e.add({0x1000, -1, data_type::u32, "ro", false, "0x00020192"})
      .add({0x6040, -1, data_type::u16, "rw", true, "0"})
      .add({0x6041, -1, data_type::u16, "ro", true, "0"})
      .add({0x6060, -1, data_type::i8, "rw", false, "0"})
      .add({0x6061, -1, data_type::i8, "ro", false, "0"})
      .add({0x6064, -1, data_type::i32, "ro", true, "0"})
      .add({0x606C, -1, data_type::i32, "ro", true, "0"})
      .add({0x607A, -1, data_type::i32, "rw", true, "0"})
      .add({0x60C2, 1, data_type::u8, "rw", false, "1"})
      .add({0x60C2, 2, data_type::i8, "rw", false, "-3"})
      .add({0x60F4, -1, data_type::i32, "ro", true, "0"});
  return e;
}

Description parsed(const EdsText& e) {
  LoadResult r = parse(e.text());
  EXPECT_TRUE(r.description.has_value()) << r.error << "\n" << e.text();
  return r.description ? *r.description : Description{};
}

canopen::RemoteDriveConfig base() {
  canopen::RemoteDriveConfig c{};
  c.node = 3;
  return c;
}

constexpr std::uint32_t cw = 0x6040'0010, target = 0x607A'0020, sw = 0x6041'0010, pos = 0x6064'0020,
                        vel = 0x606C'0020, fe = 0x60F4'0020;

TEST(EdsDriveConfig, AWritableMappingIsMappedDynamicallyWithTheFeedbackAskedFor) {
  EdsText e = drive_objects();
  e.pdo(true, 1, true, {cw}).pdo(true, 2, true, {cw, target});
  e.pdo(false, 1, true, {sw}).pdo(false, 2, true, {}).pdo(false, 3, true, {});
  const DriveConfigResult r = drive_config_from_eds(parsed(e), base(), FeedbackRequest{true, true, 0, 0});
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_TRUE(r.mapping_writable);
  EXPECT_EQ(r.config.pdo_setup, PdoSetup::dynamic);
  EXPECT_EQ(r.config.node, 3U);
  EXPECT_EQ(r.config.expected_vendor_id, 0xABU);
  EXPECT_EQ(r.config.expected_product_code, 0x1234U);
  EXPECT_EQ(r.config.layout.controlword, (PdoSlot{1, 0, 2}));
  EXPECT_EQ(r.config.layout.target_position, (PdoSlot{1, 2, 4}));
  EXPECT_EQ(r.config.layout.velocity_actual, (PdoSlot{2, 0, 4}));
  EXPECT_EQ(r.config.layout.following_error, (PdoSlot{2, 4, 4}));
  EXPECT_FALSE(r.config.layout.load_position.mapped());
  EXPECT_EQ(canopen::check_layout(r.config.layout, true), canopen::LayoutError::none);
}

TEST(EdsDriveConfig, ThePeriodGoesTo60C2Or1006WhicheverTheDriveHasAndOneIsNeeded) {
  EdsText e = drive_objects();
  e.pdo(true, 1, true, {}).pdo(false, 1, true, {}).pdo(false, 2, true, {});
  e.add({0x1006, -1, data_type::u32, "rw", false, "0"});
  const auto writes = [](const DriveConfigResult& r, std::uint16_t index) {
    std::array<canopen::StartupStep, canopen::remote_drive_max_steps> steps{};
    const std::size_t n = canopen::plan_start_up(r.config, steps).value_or(0);
    return std::count_if(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(n), [&](const auto& s) {
      return s.index() == index && s.action() == canopen::StartupAction::write;
    });
  };
  const DriveConfigResult both = drive_config_from_eds(parsed(e), base(), {});
  ASSERT_TRUE(both.ok()) << both.error;
  EXPECT_EQ(writes(both, 0x60C2), 2);
  EXPECT_EQ(writes(both, 0x1006), 1);
  EdsText no_ip = e;
  const DriveConfigResult cycle_only = drive_config_from_eds(parsed(no_ip.without(0x60C2)), base(), {});
  ASSERT_TRUE(cycle_only.ok()) << cycle_only.error;
  EXPECT_EQ(writes(cycle_only, 0x60C2), 0);
  EXPECT_EQ(writes(cycle_only, 0x1006), 1);
  const DriveConfigResult neither = drive_config_from_eds(parsed(no_ip.without(0x1006)), base(), {});
  EXPECT_NE(neither.error.find("neither 0x60C2 (interpolation time period) nor 0x1006"), std::string::npos)
      << neither.error;
}

// The objects the master uses when present are written only to a drive that has them; the
// capability list says which it found, how each is used, and what it does without the others.
TEST(EdsDriveConfig, OptionalObjectsAreWrittenOnlyWhenPresentAndListedWithTheirUse) {
  canopen::RemoteDriveConfig b = base();
  b.heartbeat_period_ms = 100;
  b.master_node = 0x7F;
  b.following_error_window = 1000;
  b.communication_loss_periods = 3;
  // heartbeat period, master node, following error window, communication loss periods
  const auto kept = [](const canopen::RemoteDriveConfig& c) {
    return std::array<unsigned, 4>{c.heartbeat_period_ms, c.master_node, c.following_error_window,
                                   c.communication_loss_periods};
  };
  EdsText e = drive_objects();
  e.pdo(true, 1, true, {}).pdo(false, 1, true, {}).pdo(false, 2, true, {});
  const DriveConfigResult without = drive_config_from_eds(parsed(e), b, {});
  ASSERT_TRUE(without.ok()) << without.error;
  EXPECT_EQ(kept(without.config), (std::array<unsigned, 4>{0, 0, 0, 0}));
  e.add({0x1017, -1, data_type::u16, "rw", false, "0"})
      .add({0x1016, 1, data_type::u32, "rw", false, "0"})
      .add({0x6065, -1, data_type::u32, "rw", false, "0"})
      .add({0x6066, -1, data_type::u16, "rw", false, "0"})
      .add({0x2001, -1, data_type::u8, "rw", false, "3"});
  const DriveConfigResult with = drive_config_from_eds(parsed(e), b, {});
  ASSERT_TRUE(with.ok()) << with.error;
  // 0x2001 is Settle's communication loss periods on Settle's drive only (no [SettleDrive] here).
  EXPECT_EQ(kept(with.config), (std::array<unsigned, 4>{100, 0x7F, 1000, 0}));

  const auto use_of = [](const std::vector<Capability>& caps, std::uint16_t index, std::uint8_t sub) {
    for (const Capability& c : caps) {
      if (c.index == index && c.sub == sub) return c;
    }
    ADD_FAILURE() << "not listed: " << index;
    return Capability{};
  };
  const std::vector<Capability> none = capabilities(parsed(drive_objects().pdo(true, 1, true, {}).pdo(false, 1, true, {}).pdo(false, 2, true, {})), without, {});
  EXPECT_FALSE(use_of(none, 0x1017, 0).found);
  EXPECT_EQ(use_of(none, 0x1017, 0).use, "");
  EXPECT_FALSE(use_of(none, 0x1017, 0).without.empty());
  EXPECT_EQ(use_of(none, 0x6040, 0).use, "RPDO1");
  EXPECT_TRUE(use_of(none, 0x6040, 0).needed);
  EXPECT_EQ(use_of(none, 0x6064, 0).use, "TPDO1");
  EXPECT_EQ(use_of(none, 0x6060, 0).use, "written");
  EXPECT_EQ(use_of(none, 0x6061, 0).use, "checked");
  const std::vector<Capability> all = capabilities(parsed(e), with, {});
  EXPECT_TRUE(use_of(all, 0x1017, 0).found);
  EXPECT_EQ(use_of(all, 0x1017, 0).use, "written");
  EXPECT_EQ(use_of(all, 0x6065, 0).use, "written");
  EXPECT_EQ(use_of(all, 0x2001, 0).use, "");
  EXPECT_EQ(use_of(all, 0x607F, 0).use, "read");
}

TEST(EdsDriveConfig, EachRequiredObjectIsCheckedForPresenceTypeAccessAndMappability) {
  const auto error_with = [](EdsText e, FeedbackRequest f = {}) {
    e.pdo(true, 1, true, {}).pdo(false, 1, true, {}).pdo(false, 2, true, {});
    return drive_config_from_eds(parsed(e), base(), f).error;
  };
  EXPECT_EQ(error_with(drive_objects().without(0x6061)), "the drive's EDS has no 0x6061 (modes of operation display)");
  EXPECT_EQ(error_with(drive_objects().replace({0x607A, -1, data_type::u32, "rw", true, "0"})),
            "the drive's EDS gives 0x607A (target position) the data type 0x0007, not INTEGER32");
  EXPECT_EQ(error_with(drive_objects().replace({0x6040, -1, data_type::u16, "ro", true, "0"})),
            "the drive's EDS makes 0x6040 (controlword) ro: the master must write it");
  EXPECT_EQ(error_with(drive_objects().replace({0x6064, -1, data_type::i32, "ro", false, "0"})),
            "the drive's EDS does not let 0x6064 (position actual value) be mapped to a PDO");
  EXPECT_EQ(error_with(drive_objects().replace({0x60C2, 2, data_type::i8, "ro", false, "-3"})),
            "the drive's EDS makes 0x60C2:2 (interpolation time index) ro: the master must write it");
  EXPECT_EQ(error_with(drive_objects().without(0x60F4), FeedbackRequest{false, true, 0, 0}),
            "the drive's EDS has no 0x60F4 (following error actual value)");
  EXPECT_EQ(error_with(drive_objects(), FeedbackRequest{false, false, 0x2100, 1}),
            "the drive's EDS has no 0x2100:1 (load-side position)");
  EXPECT_TRUE(error_with(drive_objects(), FeedbackRequest{true, true, 0, 0}).empty());
}

TEST(EdsDriveConfig, AStaticMappingThatCarriesWhatIsNeededIsReadAtStartUp) {
  EdsText e = drive_objects();
  e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, pos}).pdo(false, 2, false, {vel, fe});
  const DriveConfigResult r = drive_config_from_eds(parsed(e), base(), FeedbackRequest{true, true, 0, 0});
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_FALSE(r.mapping_writable);
  EXPECT_EQ(r.config.pdo_setup, PdoSetup::read_static);
  EXPECT_EQ(r.config.layout.velocity_actual, (PdoSlot{2, 0, 4}));
  EXPECT_EQ(r.config.layout.following_error, (PdoSlot{2, 4, 4}));
}

TEST(EdsDriveConfig, AStaticMappingWithoutWhatIsNeededIsRefusedSaying) {
  {
    EdsText e = drive_objects();  // RPDO1 = controlword, RPDO2 = target position
    e.pdo(true, 1, false, {cw}).pdo(true, 2, false, {target}).pdo(false, 1, false, {sw, pos});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error,
              "the drive's PDO mapping is static (not writable) and no RPDO carries both 0x6040 (controlword) and "
              "0x607A (target position)");
  }
  {
    EdsText e = drive_objects();
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, pos});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), FeedbackRequest{false, true, 0, 0}).error,
              "the drive's PDO mapping is static (not writable) and no TPDO carries 0x60F4 (following error actual "
              "value)");
  }
  {
    EdsText e = drive_objects();
    e.pdo(true, 1, false, {cw, target, 0x6060'0008}).pdo(false, 1, false, {sw, pos});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error,
              "the drive's PDO mapping is static (not writable) and its RPDO1 also maps 0x6060, which the master "
              "cannot fill");
  }
}

// A PDO whose COB-ID says it does not exist (bit 31) is neither sent nor received: what it maps is
// not placed (a disabled RPDO1 of controlword + target leaves them to RPDO2, a disabled TPDO2 does
// not carry the velocity), as start-up finds on the drive.
TEST(EdsDriveConfig, ADisabledPdoOfAStaticMappingCarriesNothing) {
  EdsText e = drive_objects();
  e.pdo(true, 1, false, {cw, target}).pdo(true, 2, false, {cw, target});
  e.pdo(false, 1, false, {sw, pos}).pdo(false, 2, false, {vel});
  e.replace({0x1400, 1, data_type::u32, "rw", false, "$NODEID+0x80000200"});
  e.replace({0x1801, 1, data_type::u32, "rw", false, "$NODEID+0x80000280"});
  const DriveConfigResult r = drive_config_from_eds(parsed(e), base(), {});
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.config.layout.controlword, (PdoSlot{2, 0, 2}));
  EXPECT_EQ(r.config.layout.target_position, (PdoSlot{2, 2, 4}));
  EXPECT_FALSE(r.config.layout.velocity_actual.mapped());
  EXPECT_EQ(drive_config_from_eds(parsed(e), base(), FeedbackRequest{true, false, 0, 0}).error,
            "the drive's PDO mapping is static (not writable) and no TPDO carries 0x606C (velocity actual value)");
}

// A static drive described with a COB-ID other than the predefined one would be streamed to (or
// listened for) in silence: the master uses the predefined connection set and does not re-assign a
// static drive's, so it refuses, naming the PDO, the object and both identifiers. Bit 30 (no RTR)
// is no difference; a dynamic drive gets its COB-IDs written at start-up and is not concerned.
TEST(EdsDriveConfig, AStaticPdoOnAnotherCobIdThanThePredefinedIsRefusedNamingIt) {
  const std::string prefix = "the drive's PDO mapping is static (not writable) and its ";
  {
    EdsText e = drive_objects();
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, pos});
    e.replace({0x1800, 1, data_type::u32, "rw", false, "$NODEID+0x1A0"});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error,
              prefix + "TPDO1's COB-ID (0x1800:1) is 0x1A3, not the predefined 0x183 the master listens on "
                       "(CiA 301's predefined connection set for node 3)");
  }
  {
    EdsText e = drive_objects();
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, pos});
    e.replace({0x1400, 1, data_type::u32, "rw", false, "0x205"});  // node 5's, not node 3's
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error,
              prefix + "RPDO1's COB-ID (0x1400:1) is 0x205, not the predefined 0x203 the master sends on "
                       "(CiA 301's predefined connection set for node 3)");
  }
  {
    EdsText e = drive_objects();  // the feedback's second TPDO counts as much as the first
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, vel}).pdo(false, 2, false, {pos});
    e.replace({0x1801, 1, data_type::u32, "rw", false, "$NODEID+0x380"});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error,
              prefix + "TPDO2's COB-ID (0x1801:1) is 0x383, not the predefined 0x283 the master listens on "
                       "(CiA 301's predefined connection set for node 3)");
  }
  {
    EdsText e = drive_objects();  // bit 30 (no RTR allowed) set: the same identifier
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, pos});
    e.replace({0x1800, 1, data_type::u32, "rw", false, "$NODEID+0x40000180"});
    const DriveConfigResult r = drive_config_from_eds(parsed(e), base(), {});
    EXPECT_TRUE(r.ok()) << r.error;
  }
  {
    EdsText e = drive_objects();  // a PDO carrying nothing the master reads may have any COB-ID
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, pos}).pdo(false, 3, false, {0x1001'0008});
    e.replace({0x1802, 1, data_type::u32, "rw", false, "$NODEID+0x4A0"});
    const DriveConfigResult r = drive_config_from_eds(parsed(e), base(), {});
    EXPECT_TRUE(r.ok()) << r.error;
  }
  {
    EdsText e = drive_objects();  // dynamic: start-up writes the predefined COB-IDs
    e.pdo(true, 1, true, {cw, target}).pdo(false, 1, true, {sw, pos}).pdo(false, 2, true, {});
    e.replace({0x1800, 1, data_type::u32, "rw", false, "$NODEID+0x1A0"});
    const DriveConfigResult r = drive_config_from_eds(parsed(e), base(), {});
    EXPECT_TRUE(r.ok()) << r.error;
  }
}

// A real drive's static mapping that splits the feedback (TPDO1 = statusword + velocity actual,
// TPDO2 = position actual, both on every SYNC) streams: the master reads one period from both.
TEST(EdsDriveConfig, AStaticMappingMaySplitTheFeedbackAcrossSyncTpdos) {
  EdsText e = drive_objects();
  e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, vel}).pdo(false, 2, false, {pos});
  const DriveConfigResult r = drive_config_from_eds(parsed(e), base(), FeedbackRequest{true, false, 0, 0});
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.config.pdo_setup, PdoSetup::read_static);
  EXPECT_EQ(r.config.layout.statusword, (PdoSlot{1, 0, 2}));
  EXPECT_EQ(r.config.layout.velocity_actual, (PdoSlot{1, 2, 4}));
  EXPECT_EQ(r.config.layout.position_actual, (PdoSlot{2, 0, 4}));
  const std::vector<Capability> caps = capabilities(parsed(e), r, FeedbackRequest{true, false, 0, 0});
  for (const Capability& c : caps) {
    if (c.index == 0x6041) {
      EXPECT_EQ(c.use, "TPDO1");
    }
    if (c.index == 0x6064) {
      EXPECT_EQ(c.use, "TPDO2");
    }
  }
}

// What a split cannot do: carry no position (or no statusword) at all, or send the TPDOs of one
// period on different SYNCs, or not on SYNCs.
TEST(EdsDriveConfig, ASplitFeedbackIsRefusedWhenAPeriodCannotBeRead) {
  const std::string prefix = "the drive's PDO mapping is static (not writable) and ";
  {
    EdsText e = drive_objects();
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, vel}).pdo(false, 2, false, {fe});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error,
              prefix + "no TPDO carries 0x6064 (position actual value)");
  }
  {
    EdsText e = drive_objects();
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {vel}).pdo(false, 2, false, {pos});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error, prefix + "no TPDO carries 0x6041 (statusword)");
  }
  const std::string split = prefix + "the statusword (TPDO1) and the position actual (TPDO2) come in different TPDOs, but ";
  {
    EdsText e = drive_objects();
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, vel}).pdo(false, 2, false, {pos});
    e.replace({0x1801, 2, data_type::u8, "rw", false, "2"});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error,
              split + "TPDO2 (transmission type 2) and TPDO1 (transmission type 1) are not sent on the same SYNCs");
  }
  {
    EdsText e = drive_objects();
    e.pdo(true, 1, false, {cw, target}).pdo(false, 1, false, {sw, vel}).pdo(false, 2, false, {pos});
    e.replace({0x1800, 2, data_type::u8, "rw", false, "254"});
    EXPECT_EQ(drive_config_from_eds(parsed(e), base(), {}).error,
              split + "TPDO1 (transmission type 254) is not sent on SYNCs (synchronous cyclic: 1..240)");
  }
}

// Start-up of `remote` against `drive`, frame for frame, until it is no longer configuring.
void start_up(canopen::DriveNode& drive, canopen::RemoteDrive& remote) {
  FrameBuffer<16> to_drive;
  FrameBuffer<16> to_master;
  std::uint64_t now = 0;
  drive.start(now, to_master);
  to_master.clear();
  remote.start(now, to_drive);
  for (int i = 0; i < 200 && remote.state() == canopen::RemoteDriveState::configuring; ++i) {
    const std::vector<CanFrame> requests(to_drive.frames().begin(), to_drive.frames().end());
    to_drive.clear();
    for (const CanFrame& f : requests) (void)drive.on_frame(f, now, to_master);
    const std::vector<CanFrame> answers(to_master.frames().begin(), to_master.frames().end());
    to_master.clear();
    for (const CanFrame& f : answers) (void)remote.on_frame(f, now, to_drive);
    now += 1000;
    remote.poll(now, to_drive);
  }
  ASSERT_EQ(remote.state(), canopen::RemoteDriveState::enabling)
      << canopen::to_string(remote.failure().error) << " at 0x" << std::hex << remote.failure().index;
}

// The bundled description of Settle's drive: static mapping, read at start-up, and the layout it
// gives is the default one (so the master keeps its inline codecs). Then against the drive itself.
TEST(EdsDriveConfig, TheBundledEdsConfiguresSettlesDrive) {
  const LoadResult loaded = load(SETTLE_DRIVE_EDS_PATH);
  ASSERT_TRUE(loaded.description) << loaded.error;
  const DriveConfigResult r = drive_config_from_eds(*loaded.description, base(),
                                                    FeedbackRequest{true, false, canopen::obj::load_position_actual, 0});
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.config.pdo_setup, PdoSetup::read_static);
  EXPECT_TRUE(canopen::is_default_layout(r.config.layout));

  canopen::DriveNode drive{canopen::DriveNodeConfig{3}};
  canopen::RemoteDrive remote{r.config};
  start_up(drive, remote);
  EXPECT_TRUE(canopen::is_default_layout(remote.config().layout)) << "derived from the drive's own mapping";
}


// Issue 35: CiA 301 asks 0x1006 only of the SYNC producer. The bundled description keeps it and
// the master writes it; a description without it (a drive that aborts 0x06020000 on it) is
// configured without the write, and start-up against such a drive succeeds.
TEST(EdsDriveConfig, The1006WriteIsMadeOnlyWhenTheDescriptionHasIt) {
  const LoadResult loaded = load(SETTLE_DRIVE_EDS_PATH);
  ASSERT_TRUE(loaded.description) << loaded.error;
  const FeedbackRequest feedback{true, false, canopen::obj::load_position_actual, 0};
  const DriveConfigResult with = drive_config_from_eds(*loaded.description, base(), feedback);
  ASSERT_TRUE(with.ok()) << with.error;
  EXPECT_TRUE(with.config.write_sync_period);

  // The same file without [1006] and its line in the object list.
  std::string text;
  {
    std::FILE* f = std::fopen(SETTLE_DRIVE_EDS_PATH, "rb");
    ASSERT_NE(f, nullptr);
    for (int c = std::fgetc(f); c != EOF; c = std::fgetc(f)) text.push_back(static_cast<char>(c));
    std::fclose(f);
  }
  const auto section = text.find("[1006]");
  ASSERT_NE(section, std::string::npos);
  text.erase(section, text.find("\n\n", section) + 2 - section);
  const auto listed = text.find("=0x1006\n");
  ASSERT_NE(listed, std::string::npos);
  text.replace(listed, 8, "=0x1005\n");  // listed twice is harmless to the reader; keeps the count
  const LoadResult lacking = parse(text);
  ASSERT_TRUE(lacking.description) << lacking.error;
  ASSERT_FALSE(lacking.description->has(canopen::obj::communication_cycle_period));
  const DriveConfigResult without = drive_config_from_eds(*lacking.description, base(), feedback);
  ASSERT_TRUE(without.ok()) << without.error;
  EXPECT_FALSE(without.config.write_sync_period);

  std::array<canopen::StartupStep, canopen::remote_drive_max_steps> steps{};
  const auto planned = canopen::plan_start_up(without.config, steps);
  ASSERT_TRUE(planned.has_value());
  for (std::size_t i = 0; i < *planned; ++i) {
    EXPECT_NE(steps[i].index(), canopen::obj::communication_cycle_period) << "step " << i;
  }
  canopen::DriveNodeConfig dc{3};
  dc.has_communication_cycle_period = false;
  dc.sync_period_us = 0;
  canopen::DriveNode drive{dc};
  canopen::RemoteDrive remote{without.config};
  start_up(drive, remote);
  // And the old way, writing 0x1006 to that drive, is what fails (abort 0x06020000).
  canopen::DriveNode drive2{dc};
  canopen::RemoteDriveConfig forced = without.config;
  forced.write_sync_period = true;
  canopen::RemoteDrive remote2{forced};
  FrameBuffer<16> to_drive;
  FrameBuffer<16> to_master;
  std::uint64_t now = 0;
  drive2.start(now, to_master);
  to_master.clear();
  remote2.start(now, to_drive);
  for (int i = 0; i < 200 && remote2.state() == canopen::RemoteDriveState::configuring; ++i) {
    const std::vector<CanFrame> requests(to_drive.frames().begin(), to_drive.frames().end());
    to_drive.clear();
    for (const CanFrame& f : requests) (void)drive2.on_frame(f, now, to_master);
    const std::vector<CanFrame> answers(to_master.frames().begin(), to_master.frames().end());
    to_master.clear();
    for (const CanFrame& f : answers) (void)remote2.on_frame(f, now, to_drive);
    now += 1000;
    remote2.poll(now, to_drive);
  }
  EXPECT_EQ(remote2.state(), canopen::RemoteDriveState::failed);
  EXPECT_EQ(remote2.failure().index, canopen::obj::communication_cycle_period);
}

}  // namespace
}  // namespace settle::hal::eds
