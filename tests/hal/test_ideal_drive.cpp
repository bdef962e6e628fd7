// SPDX-License-Identifier: Apache-2.0
// hal::testing's ideal drive (the far end of the bus for the firmware tests, the benchmarks and
// the Cortex-M images), driven by hal's own master (RemoteDrive + SyncProducer) over loopback:
// what it applies and records, what it reports, and its velocity arithmetic at the extremes of
// the position counter, where the images' former copy computed `(sp - position) * rate` in int32.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/mailbox_bus.hpp"
#include "settle/hal/testing/ideal_drive.hpp"

namespace settle::hal::testing {
namespace {

constexpr std::int32_t kMin = std::numeric_limits<std::int32_t>::min();
constexpr std::int32_t kMax = std::numeric_limits<std::int32_t>::max();

TEST(IdealVelocity, IsTheStepTimesTheRate) {
  EXPECT_EQ(ideal_velocity(0, 10, 1000), 10'000);
  EXPECT_EQ(ideal_velocity(10, 0, 1000), -10'000);
  EXPECT_EQ(ideal_velocity(-5, 5, 250), 2'500);
  EXPECT_EQ(ideal_velocity(7, 7, 1000), 0);
  EXPECT_EQ(ideal_velocity(0, 10, 0), 0);
}

// A step across the counter's wrap is the short way round (as DriveNode's step limit sees it):
// INT32_MAX -> INT32_MIN is one count forward. `to - from` in int32 overflows here.
TEST(IdealVelocity, ACrossingOfTheWrapIsTheShortWayRound) {
  EXPECT_EQ(ideal_velocity(kMax, kMin, 1000), 1'000);
  EXPECT_EQ(ideal_velocity(kMin, kMax, 1000), -1'000);
  EXPECT_EQ(ideal_velocity(kMax - 5, kMin + 5, 1000), 11'000);
}

// Positions far apart (±2e9): the step the short way round is 294 967 296 counts, which at 1 kHz
// is beyond int32: the velocity saturates at 0x606C's limits instead of overflowing. The images'
// former formula, (sp - position) * 1000 in int32, overflowed twice here (4e9 does not fit, nor
// does the product): undefined behaviour, and on a wrapping machine a velocity of the wrong size.
TEST(IdealVelocity, PositionsFarApartSaturateInsteadOfOverflowing) {
  constexpr std::int32_t far = 2'000'000'000;
  static_assert(std::int64_t{far} - std::int64_t{-far} > kMax, "the old int32 subtraction overflows");
  EXPECT_EQ(ideal_velocity(-far, far, 1000), kMin);  // 4e9 forward = 294 967 296 back
  EXPECT_EQ(ideal_velocity(far, -far, 1000), kMax);
  EXPECT_EQ(ideal_velocity(0, far, 1000), kMax);
  EXPECT_EQ(ideal_velocity(0, -far, 1000), kMin);
  EXPECT_EQ(ideal_velocity(0, far, 1), far);  // one period a second: the step itself
  // What the old formula gave on a wrapping machine for the first case: neither the step nor a
  // bound of 0x606C.
  const auto wrapped = static_cast<std::int32_t>((static_cast<std::uint32_t>(far) - static_cast<std::uint32_t>(-far)) * 1000U);
  EXPECT_NE(wrapped, ideal_velocity(-far, far, 1000));
}

// The master side: hal's RemoteDrive and a SYNC producer on their own loopback port.
struct Master {
  explicit Master(LoopbackHub& h, canopen::NodeId node) : hub{h}, remote{config(node)} {}
  static canopen::RemoteDriveConfig config(canopen::NodeId node) {
    canopen::RemoteDriveConfig c{};
    c.node = node;
    return c;
  }
  // One period: RPDO (target), SYNC, the drive answers, the master reads.
  template <typename Drive>
  void tick(Drive& drive, std::int32_t target) {
    now += 1000;
    hub.set_time_us(now);
    remote.poll(now, port);
    if (CanFrame rpdo{}; remote.rpdo(target, rpdo)) (void)port.send(rpdo);
    (void)port.send(sync.next());
    drive.process(now);
    CanFrame f{};
    while (port.receive(f) == ReceiveStatus::received) remote.on_frame(f, now, port);
  }
  template <typename Drive>
  bool enable(Drive& drive, std::int32_t hold) {
    drive.start(now);
    remote.start(now, port);
    for (int i = 0; i < 500 && !remote.ready(); ++i) tick(drive, hold);
    return remote.ready();
  }
  LoopbackHub& hub;
  LoopbackBus<64> port{hub};
  canopen::RemoteDrive remote;
  canopen::SyncProducer sync{1000};
  std::uint64_t now{0};
};

TEST(IdealDrive, AppliesRecordsAndReportsEachSetpointOnePeriodLater) {
  LoopbackHub hub;
  Master m{hub, 3};
  IdealDrive<LoopbackBus<64>> drive{hub, canopen::DriveNodeConfig{.node = 3}};
  std::array<std::int32_t, 4> record{};
  drive.record_applied(record);
  ASSERT_TRUE(m.enable(drive, 0));
  drive.clear_applied();
  for (const std::int32_t sp : {5, 12, 20, 20, 14}) m.tick(drive, sp);
  // Every setpoint applied at its SYNC, in order; the buffer keeps the first four.
  EXPECT_EQ(drive.applied_count(), 5u);
  EXPECT_TRUE(drive.applied_truncated());
  EXPECT_EQ(std::vector<std::int32_t>(drive.applied().begin(), drive.applied().end()),
            (std::vector<std::int32_t>{5, 12, 20, 20}));
  EXPECT_EQ(drive.position(), 14);
  EXPECT_EQ(drive.velocity(), -6'000);
  EXPECT_EQ(m.remote.feedback().position_actual, 14);
  EXPECT_EQ(m.remote.feedback().velocity_actual, -6'000);
  EXPECT_EQ(drive.node().counters().steps_refused, 0u);
  drive.clear_applied();
  EXPECT_TRUE(drive.applied().empty());
  EXPECT_FALSE(drive.applied_truncated());
}

// Powered on away from zero, it holds there until enabled (it does not jump to setpoint()'s 0),
// records nothing until it follows, and a lag is reported as a constant following error.
TEST(IdealDrive, HoldsWhereItStandsUntilFollowingAndReportsItsLag) {
  LoopbackHub hub;
  Master m{hub, 1};
  IdealDrive<> drive{hub, canopen::DriveNodeConfig{}};
  std::array<std::int32_t, 16> record{};
  drive.record_applied(record);
  drive.set_position(-70'000);
  drive.start(m.now);
  m.remote.start(m.now, m.port);
  std::uint64_t syncs_before_ready = 0;
  for (int i = 0; i < 500 && !m.remote.ready(); ++i) {
    m.tick(drive, -70'000);
    EXPECT_EQ(drive.position(), -70'000) << i;
    syncs_before_ready = drive.node().counters().syncs;
  }
  ASSERT_TRUE(m.remote.ready());
  EXPECT_GT(syncs_before_ready, 0u);
  drive.set_lag(5);
  drive.clear_applied();
  m.tick(drive, -69'990);
  EXPECT_EQ(drive.position(), -69'990);
  EXPECT_EQ(m.remote.feedback().position_actual, -69'995);
  EXPECT_EQ(drive.applied_count(), 1u);
}

// Across the counter's wrap, and an axis found 4e9 counts (the long way) from its setpoint: no
// overflow (this test runs in the sanitizer presets), and the velocity is saturated.
TEST(IdealDrive, CrossesTheWrapAndSurvivesAnAxisFarFromItsSetpoint) {
  LoopbackHub hub;
  Master m{hub, 1};
  IdealDrive<> drive{hub, canopen::DriveNodeConfig{}};
  drive.set_position(kMax - 3);
  ASSERT_TRUE(m.enable(drive, kMax - 3));
  m.tick(drive, kMin + 2);  // 6 counts forward, across the wrap
  EXPECT_EQ(drive.position(), kMin + 2);
  EXPECT_EQ(m.remote.feedback().velocity_actual, 6'000);
  EXPECT_EQ(drive.node().counters().steps_refused, 0u);

  // The axis is moved by hand to +2e9 while its setpoint stays at -2e9 (one SYNC: the following
  // error takes longer than one period to fault).
  constexpr std::int32_t far = 2'000'000'000;
  drive.set_position(-far);
  m.tick(drive, kMin + 2);  // the drive's setpoint is still kMin + 2: the axis goes there
  drive.set_position(far);
  m.tick(drive, kMin + 2);
  EXPECT_EQ(drive.position(), kMin + 2);
  EXPECT_EQ(drive.velocity(), ideal_velocity(far, kMin + 2, 1000));
  EXPECT_EQ(drive.velocity(), kMax);  // (kMin + 2 - 2e9) wraps to +147 483 650 counts
}

// On a CAN controller's buffers (the Cortex-M example's wiring): the owner plays the wire side.
TEST(IdealDrive, RunsOnAMailboxPort) {
  IdealDrive<MailboxBus<4, 8>> drive{canopen::DriveNodeConfig{.node = 9}};
  drive.start(0);
  CanFrame f{};
  ASSERT_TRUE(drive.port().take_sent(f));  // boot-up
  EXPECT_EQ(f.id, 0x700U + 9U);
  EXPECT_EQ(drive.position(), 0);
}

}  // namespace
}  // namespace settle::hal::testing
