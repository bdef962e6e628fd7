// The servo loop against a real CiA 402 drive node on the in-process bus: start-up before
// streaming, setpoints applied exactly once and in order, the move's end reached exactly, and
// the safety rules (queue bound, velocity refusal, step guard, tx busy without bursts).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "ideal_drive.hpp"
#include "settle/firmware/servo_loop.hpp"
#include "settle/hal/mailbox_bus.hpp"
#include "settle/hal/testing/fault_injecting_bus.hpp"

using namespace settle;

namespace {

constexpr std::uint32_t kPeriod = 1000;

core::MoveRequest scurve(double d, double t) {
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.distance = d;
  r.time = t;
  r.omega = 22.04871;
  return r;
}

firmware::AxisConfig axis(std::uint8_t node) {
  firmware::AxisConfig a{};
  a.drive.node = hal::canopen::NodeId{node};
  a.drive.heartbeat_timeout_ms = 500;
  a.counts_per_unit = 1e6;
  a.vmax = 2.0;
  return a;
}

struct Rig {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  test::IdealDrive drive{hub, hal::canopen::DriveNodeConfig{}};
  firmware::ServoLoop<double, 1, 4> loop{master, kPeriod};
  std::uint64_t now = 0;
  std::vector<std::int32_t> sent;

  explicit Rig(const firmware::AxisConfig& a = axis(1)) {
    EXPECT_EQ(loop.add_axis(a), firmware::LoopStatus::ok);
    drive.start(now);
    loop.start(now);
  }
  void tick() {
    now += kPeriod;
    hub.set_time_us(now);
    loop.tick(now);
    if (loop.record(0).sent && loop.ready(0)) sent.push_back(loop.record(0).target);
    drive.process(now);
  }
  bool run_until_ready(int max_ticks = 2000) {
    for (int i = 0; i < max_ticks && !loop.ready(0); ++i) tick();
    return loop.ready(0);
  }
};

TEST(ServoLoop, EnablesTheDriveBeforeStreaming) {
  Rig r;
  EXPECT_FALSE(r.loop.ready(0));
  ASSERT_TRUE(r.run_until_ready()) << hal::canopen::to_string(r.loop.drive(0).state());
  EXPECT_EQ(r.drive.node().state(), hal::canopen::Cia402State::operation_enabled);
  EXPECT_EQ(r.drive.node().mode(), hal::canopen::OperationMode::cyclic_synchronous_position);
  EXPECT_EQ(r.drive.node().interpolation_period_us(), kPeriod);
  EXPECT_EQ(r.drive.position(), 0);  // enabling never moved the axis
}

TEST(ServoLoop, StreamsAMoveExactlyOnceInOrderAndEndsOnTarget) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  // Within one rig tick the drive applies what the loop sent, so both logs align here.
  r.sent.clear();
  r.drive.applied.clear();
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), firmware::LoopStatus::ok);
  ASSERT_EQ(r.loop.submit(0, scurve(-0.05, 0.3)), firmware::LoopStatus::ok);
  for (int i = 0; i < 1000; ++i) r.tick();
  EXPECT_TRUE(r.loop.idle());
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 2u);
  EXPECT_EQ(r.drive.position(), 50'000);  // 0.1 m - 0.05 m at 1 µm per count, exactly
  // every setpoint the loop sent while operating was applied once, in order
  ASSERT_EQ(r.drive.applied.size(), r.sent.size());
  for (std::size_t i = 0; i < r.sent.size(); ++i) ASSERT_EQ(r.drive.applied[i], r.sent[i]) << i;
  // and they follow the profile
  core::Move<double> m{};
  ASSERT_EQ(core::plan(scurve(0.1, 0.5), m), core::Status::ok);
  for (std::size_t k = 0; k < 500; ++k) {
    ASSERT_EQ(r.sent[k], static_cast<std::int32_t>(std::nearbyint(m.at(static_cast<double>(k) * 1e-3).p * 1e6))) << k;
  }
  EXPECT_EQ(r.loop.axis_stats(0).max_following_error, 0U);
}

TEST(ServoLoop, FeedbackLogKeepsEachPeriodInArrivalOrderAndCountsWhatItHadToDrop) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  while (!r.loop.feedback_log(0).empty()) r.loop.feedback_log(0).drop_front();
  r.drive.applied.clear();
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), firmware::LoopStatus::ok);
  // Drained every tick: one sample per period. A tick receives what the drive published after
  // the previous tick's SYNC, so sample k + 1 is the drive's answer to the k-th applied setpoint.
  std::vector<std::int32_t> logged;
  for (int i = 0; i < 101; ++i) {
    r.tick();
    for (firmware::FeedbackSample fs{}; r.loop.feedback_log(0).pop(fs);) logged.push_back(fs.position_actual);
  }
  ASSERT_EQ(logged.size(), 101U);
  ASSERT_GE(r.drive.applied.size(), 100U);
  for (std::size_t k = 0; k < 100; ++k) EXPECT_EQ(logged[k + 1], r.drive.applied[k]) << "period " << k;
  EXPECT_EQ(r.loop.axis_stats(0).feedback_overflows, 0U);
  // Not drained: the log holds its capacity, the oldest samples stay, the rest are counted.
  const std::size_t extra = 5;
  for (std::size_t i = 0; i < firmware::kFeedbackLogCapacity + extra; ++i) r.tick();
  EXPECT_EQ(r.loop.feedback_log(0).size(), firmware::kFeedbackLogCapacity);
  EXPECT_EQ(r.loop.axis_stats(0).feedback_overflows, extra);
  firmware::FeedbackSample first{};
  ASSERT_TRUE(r.loop.feedback_log(0).pop(first));
  EXPECT_EQ(first.position_actual, r.drive.applied[100]) << "the oldest undrained sample comes first";
}

TEST(ServoLoop, RefusesWhatItCannotStreamAndChangesNothing) {
  Rig r;
  core::Status st{};
  auto bad = scurve(0.1, -1.0);
  EXPECT_EQ(r.loop.submit(0, bad, &st), firmware::LoopStatus::plan_failed);
  EXPECT_EQ(st, core::Status::non_positive_time);
  EXPECT_EQ(r.loop.submit(0, scurve(1.0, 0.6)), firmware::LoopStatus::exceeds_axis_velocity);  // peak > 2 m/s
  EXPECT_EQ(r.loop.submit(3, scurve(0.1, 1)), firmware::LoopStatus::no_such_axis);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(r.loop.submit(0, scurve(0.01, 0.5)), firmware::LoopStatus::ok);
  EXPECT_EQ(r.loop.submit(0, scurve(0.01, 0.5)), firmware::LoopStatus::queue_full);
  EXPECT_EQ(r.master.counters().sent, r.master.counters().sent);  // nothing streamed by a refusal
}

TEST(ServoLoop, TxBusyIsCountedAndNeverBursts) {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> port{hub};
  hal::testing::FaultInjectingBus faulty{port};
  test::IdealDrive drive{hub, hal::canopen::DriveNodeConfig{}};
  firmware::ServoLoop<double, 1, 4> loop{faulty, kPeriod};
  ASSERT_EQ(loop.add_axis(axis(1)), firmware::LoopStatus::ok);
  std::uint64_t now = 0;
  drive.start(now);
  loop.start(now);
  auto tick = [&] {
    now += kPeriod;
    hub.set_time_us(now);
    faulty.set_time_us(now);
    const auto before = port.counters().sent;
    loop.tick(now);
    EXPECT_LE(port.counters().sent - before, 2u + 4u);  // RPDO + SYNC (+ start-up SDO/NMT)
    drive.process(now);
  };
  for (int i = 0; i < 2000 && !loop.ready(0); ++i) tick();
  ASSERT_TRUE(loop.ready(0));
  ASSERT_EQ(loop.submit(0, scurve(0.1, 0.5)), firmware::LoopStatus::ok);
  for (int i = 0; i < 100; ++i) tick();
  faulty.fail_sends(5, hal::SendStatus::busy);
  for (int i = 0; i < 700; ++i) tick();
  EXPECT_GE(loop.axis_stats(0).rpdo_busy + loop.stats().sync_busy, 5u);
  EXPECT_EQ(loop.axis_stats(0).step_guard_trips, 0u);
  EXPECT_EQ(loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(drive.position(), 100'000);
}

TEST(ServoLoop, StreamsSeed001sVelocityStepWithinTheGuard) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  core::MoveRequest req{};
  req.profile = core::ProfileKind::ramp_versine;  // starts and ends with a velocity step
  req.distance = 0.1;
  req.time = 0.167;
  req.omega = 28.28;
  req.zeta = 0.159;
  core::Move<double> m{};
  ASSERT_EQ(core::plan(req, m), core::Status::ok);
  ASSERT_TRUE(m.peaks().velocity_step);
  ASSERT_LT(m.peaks().v, 2.0);
  ASSERT_EQ(r.loop.submit(0, m), firmware::LoopStatus::ok);
  for (int i = 0; i < 400; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).step_guard_trips, 0u);
  EXPECT_EQ(r.drive.position(), 100'000);
}

// The loop on a CAN controller's buffers, held by the controller's own type (direct driver calls,
// as drive firmware builds it) or as a hal::CanBus: the same frames, tick for tick.
template <typename LoopBus>
std::vector<hal::CanFrame> run_on_controller() {
  hal::LoopbackHub hub;
  hal::LoopbackBus<64> wire{hub};  // the controller's wire side
  hal::MailboxBus<3, 8> controller;
  test::IdealDrive drive{hub, hal::canopen::DriveNodeConfig{}};
  firmware::ServoLoop<double, 1, 4, firmware::FloatEvaluation<double>, LoopBus> loop{controller, kPeriod};
  EXPECT_EQ(loop.add_axis(axis(1)), firmware::LoopStatus::ok);
  std::vector<hal::CanFrame> sent;
  std::uint64_t now = 0;
  const auto pump = [&] {
    hal::CanFrame f{};
    while (controller.take_sent(f)) {
      sent.push_back(f);
      (void)wire.send(f);
    }
  };
  drive.start(now);
  loop.start(now);
  pump();
  bool submitted = false;
  for (int i = 0; i < 1200; ++i) {
    now += kPeriod;
    hub.set_time_us(now);
    drive.process(now);
    hal::CanFrame f{};
    while (wire.receive(f, 0) == hal::ReceiveStatus::received) (void)controller.put_received(f);
    if (!submitted && loop.ready(0)) submitted = loop.submit(0, scurve(0.05, 0.3)) == firmware::LoopStatus::ok;
    loop.tick(now);
    pump();
  }
  EXPECT_TRUE(submitted);
  EXPECT_EQ(loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(drive.position(), 50'000);
  EXPECT_EQ(controller.counters().rx_overflow_drops, 0u);
  return sent;
}

TEST(ServoLoop, OnTheControllersOwnTypeItSendsWhatItSendsThroughCanBus) {
  const auto direct = run_on_controller<hal::MailboxBus<3, 8>>();
  const auto virtual_calls = run_on_controller<hal::CanBus>();
  ASSERT_EQ(direct.size(), virtual_calls.size());
  ASSERT_GT(direct.size(), 2000u);
  for (std::size_t i = 0; i < direct.size(); ++i) ASSERT_EQ(direct[i], virtual_calls[i]) << "frame " << i;
}

TEST(ServoLoop, AMoveAcrossTheCountWrapStreamsItsTrueStepsAndEndsOnTarget) {
  // Positions are int32 counts that wrap modulo 2^32, as the drive's counter does: an axis that
  // powers on 3 000 counts below INT32_MAX and moves +0.01 m (10 000 counts) passes the wrap. The
  // step guard and the following error see the true 1-period steps, not a 2^32 jump.
  Rig r;
  constexpr std::int32_t kStart = INT32_MAX - 3000;
  r.drive.set_position(kStart);
  ASSERT_TRUE(r.run_until_ready());
  for (int i = 0; i < 5; ++i) r.tick();
  ASSERT_EQ(r.drive.position(), kStart) << "enabling never moved the axis";
  r.sent.clear();
  r.drive.applied.clear();
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), firmware::LoopStatus::ok);
  for (int i = 0; i < 300; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).step_guard_trips, 0u);
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  const auto expected = static_cast<std::int32_t>(static_cast<std::uint32_t>(kStart) + 10'000U);
  EXPECT_LT(expected, 0) << "the target is past the wrap";
  EXPECT_EQ(r.drive.position(), expected);
  EXPECT_EQ(r.loop.axis_stats(0).max_following_error, 0U);
  bool crossed = false;
  for (std::size_t k = 1; k < r.sent.size(); ++k) crossed = crossed || (r.sent[k - 1] > 0 && r.sent[k] < 0);
  EXPECT_TRUE(crossed);
}

TEST(ServoLoop, FollowingErrorIsMeasuredTheShortWayRoundTheWrap) {
  // The drive lags by a constant 5 counts while the stream passes the wrap: the error stays 5,
  // and a 10-count limit never trips (a 64-bit difference would see 2^32 - 5 at the crossing).
  firmware::AxisConfig a = axis(1);
  a.following_error_counts = 10;
  Rig r{a};
  constexpr std::int32_t kStart = INT32_MAX - 3000;
  r.drive.set_position(kStart);
  r.drive.set_lag(5);
  ASSERT_TRUE(r.run_until_ready());
  for (int i = 0; i < 5; ++i) r.tick();
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), firmware::LoopStatus::ok);
  for (int i = 0; i < 300; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(r.loop.axis_stats(0).following_error_trips, 0u);
  EXPECT_EQ(r.loop.axis_stats(0).max_following_error, 5U);
}

TEST(ServoLoop, StepGuardHoldsWhenAMovesPeaksAreWrong) {
  // Defence in depth: submit trusts the move's reported peak velocity; the guard does not. A move
  // whose peaks claim 0.1 m/s but which really moves at ~3 m/s (the axis allows 2) must be abandoned at its first
  // over-large step, and the axis must hold where it was.
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  core::Move<double> fast{};
  ASSERT_EQ(core::plan(scurve(0.5, 0.3), fast), core::Status::ok);
  ASSERT_GT(fast.peaks().v, 2.5);
  core::Peaks<double> lie = fast.peaks();
  lie.v = 0.1;
  const core::Move<double> liar{fast.profile(), fast.shaper(), lie};
  ASSERT_EQ(r.loop.submit(0, liar), firmware::LoopStatus::ok);
  for (int i = 0; i < 400; ++i) {
    r.tick();
    if (r.sent.size() >= 2) {
      const auto step = std::abs(r.sent[r.sent.size() - 1] - r.sent[r.sent.size() - 2]);
      ASSERT_LE(step, static_cast<int>(2.0 * 1e6 * 1e-3) + 2) << i;  // vmax (2 m/s) * period + margin
    }
  }
  EXPECT_EQ(r.loop.axis_stats(0).step_guard_trips, 1u);
  EXPECT_EQ(r.loop.axis_stats(0).moves_aborted, 1u);
  EXPECT_LT(r.drive.position(), 500'000);
  EXPECT_TRUE(r.loop.idle());
}

TEST(ServoLoop, RestartedDriveIsEnabledAgainBeforeStreaming) {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  std::optional<test::IdealDrive> drive;
  drive.emplace(hub, hal::canopen::DriveNodeConfig{});
  firmware::ServoLoop<double, 1, 4> loop{master, kPeriod};
  ASSERT_EQ(loop.add_axis(axis(1)), firmware::LoopStatus::ok);
  std::uint64_t now = 0;
  drive->start(now);
  loop.start(now);
  std::uint64_t streamed_while_not_ready = 0;
  auto tick = [&] {
    now += kPeriod;
    hub.set_time_us(now);
    loop.tick(now);
    if (!loop.ready(0) && loop.record(0).moving) ++streamed_while_not_ready;
    drive->process(now);
  };
  for (int i = 0; i < 2000 && !loop.ready(0); ++i) tick();
  ASSERT_TRUE(loop.ready(0));
  ASSERT_EQ(loop.submit(0, scurve(0.1, 0.5)), firmware::LoopStatus::ok);
  ASSERT_EQ(loop.submit(0, scurve(0.1, 0.5)), firmware::LoopStatus::ok);  // queued behind it
  for (int i = 0; i < 200; ++i) tick();
  const auto restarts_before = loop.axis_stats(0).restarts;
  // The drive power-cycles mid-move: a fresh node on the bus, which announces itself (boot-up).
  drive.emplace(hub, hal::canopen::DriveNodeConfig{});
  drive->start(now);
  tick();
  tick();
  EXPECT_FALSE(loop.ready(0));
  EXPECT_EQ(loop.axis_stats(0).restarts, restarts_before + 1);
  EXPECT_EQ(loop.axis_stats(0).moves_aborted, 1u);
  EXPECT_TRUE(loop.idle());  // the queued move was planned from a position that no longer holds
  for (int i = 0; i < 2000 && !loop.ready(0); ++i) tick();
  ASSERT_TRUE(loop.ready(0)) << hal::canopen::to_string(loop.drive(0).state());
  EXPECT_EQ(drive->node().state(), hal::canopen::Cia402State::operation_enabled);
  EXPECT_EQ(drive->node().mode(), hal::canopen::OperationMode::cyclic_synchronous_position);
  ASSERT_EQ(loop.submit(0, scurve(0.02, 0.3)), firmware::LoopStatus::ok);
  for (int i = 0; i < 400; ++i) tick();
  EXPECT_EQ(streamed_while_not_ready, 0u);
  EXPECT_EQ(loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(drive->position(), 20'000);  // the new drive started at 0 and the loop held there
}

TEST(ServoLoop, ThreeAxesOnOneBusEachFollowTheirOwnMove) {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  std::vector<std::unique_ptr<test::IdealDrive>> drives;
  firmware::ServoLoop<double, 3, 2> loop{master, kPeriod};
  for (std::uint8_t n = 1; n <= 3; ++n) {
    ASSERT_EQ(loop.add_axis(axis(n)), firmware::LoopStatus::ok);
    hal::canopen::DriveNodeConfig dc{};
    dc.node = n;
    drives.push_back(std::make_unique<test::IdealDrive>(hub, dc));
  }
  EXPECT_EQ(loop.add_axis(axis(4)), firmware::LoopStatus::too_many_axes);
  std::uint64_t now = 0;
  for (auto& d : drives) d->start(now);
  loop.start(now);
  auto tick = [&] {
    now += kPeriod;
    hub.set_time_us(now);
    loop.tick(now);
    for (auto& d : drives) d->process(now);
  };
  for (int i = 0; i < 3000 && !loop.all_ready(); ++i) tick();
  ASSERT_TRUE(loop.all_ready());
  ASSERT_EQ(loop.submit(0, scurve(0.1, 0.4)), firmware::LoopStatus::ok);
  ASSERT_EQ(loop.submit(1, scurve(-0.03, 0.2)), firmware::LoopStatus::ok);
  ASSERT_EQ(loop.submit(2, scurve(0.25, 0.7)), firmware::LoopStatus::ok);
  for (int i = 0; i < 900; ++i) tick();
  EXPECT_TRUE(loop.idle());
  EXPECT_EQ(drives[0]->position(), 100'000);
  EXPECT_EQ(drives[1]->position(), -30'000);
  EXPECT_EQ(drives[2]->position(), 250'000);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(loop.axis_stats(i).moves_completed, 1u);
    EXPECT_EQ(loop.axis_stats(i).max_following_error, 0U);
  }
}

}  // namespace
