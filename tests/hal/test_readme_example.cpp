// SPDX-License-Identifier: Apache-2.0
// hal/README.md's examples of the two ends of the bus (DriveNode, RemoteDrive) are the code this
// test compiles (extracted from the README at build time) and runs: the master's tick and the
// drive's period on the loopback bus bring the drive up, enable it and stream a move to it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>

#include "settle/hal/can_bus.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/hal/loopback_bus.hpp"

namespace readme {
using namespace settle::hal;
using namespace settle::hal::canopen;
#include "readme_examples.inc"
}  // namespace readme

namespace {

using namespace settle::hal;
using namespace settle::hal::canopen;

// An ideal axis: at its setpoint at the end of every period.
struct Axis {
  std::int32_t p{0};
  std::int32_t v{0};
  void move_to(std::int32_t sp) {
    v = (sp - p) * 1000;  // counts per 1 ms period -> counts/s
    p = sp;
  }
  void decelerate() { v = 0; }
  [[nodiscard]] bool at_rest() const { return v == 0; }
  [[nodiscard]] std::int32_t position() const { return p; }
  [[nodiscard]] std::int32_t velocity() const { return v; }
  [[nodiscard]] std::int32_t load_position() const { return p; }
};

TEST(HalReadme, TheMasterAndDriveExamplesStreamAMove) {
  LoopbackHub hub;
  LoopbackBus<64> master_bus{hub};
  LoopbackBus<64> drive_bus{hub};
  DriveNode drive{DriveNodeConfig{.node = 2}};
  RemoteDrive remote{RemoteDriveConfig{.node = 2, .heartbeat_timeout_ms = 300}};
  SyncProducer sync{1000};
  Axis axis;
  std::uint64_t now = 0;
  drive.start(now, drive_bus);
  remote.start(now, master_bus);
  int ready_at = -1;
  std::int32_t target = 0;
  for (int tick = 0; tick < 2000; ++tick) {
    now += 1000;
    hub.set_time_us(now);
    if (remote.ready()) {
      if (ready_at < 0) ready_at = tick;
      target = std::min(target + 10, 5000);  // a ramp to 5000 counts, 10 counts per period
    }
    readme::master_tick(remote, sync, master_bus, target, now);
    readme::drive_period(drive, axis, drive_bus, now);
  }
  ASSERT_GE(ready_at, 0) << "never enabled: " << static_cast<int>(remote.state());
  EXPECT_LT(ready_at, 100);
  EXPECT_TRUE(remote.ready());
  EXPECT_TRUE(drive.following());
  EXPECT_EQ(axis.position(), 5000);
  EXPECT_EQ(remote.feedback().position_actual, 5000);
  EXPECT_EQ(remote.feedback().load_position, 5000);
  EXPECT_EQ(drive.counters().steps_refused, 0U);
}

}  // namespace
