// SPDX-License-Identifier: Apache-2.0
// The servo loop against a real CiA 402 drive node on the in-process bus: start-up before
// streaming, setpoints applied exactly once and in order, the move's end reached exactly, and
// the safety rules (queue bound, velocity refusal, step guard, tx busy and send errors without
// skips or bursts, the feedback watchdog, a drive someone else stops, a second SYNC producer,
// bus-off and its recovery).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "settle/runtime/servo_loop.hpp"
#include "settle/hal/mailbox_bus.hpp"
#include "settle/hal/testing/fault_injecting_bus.hpp"
#include "settle/hal/testing/ideal_drive.hpp"

using namespace settle;

namespace {

constexpr std::uint32_t kPeriod = 1000;

core::MoveRequest scurve(double d, double t) {
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.distance = d;
  r.time = t;
  r.set_mode(22.04871);
  return r;
}

runtime::AxisConfig axis(std::uint8_t node) {
  runtime::AxisConfig a{};
  a.drive.node = hal::canopen::NodeId{node};
  a.drive.heartbeat_timeout_ms = 500;
  a.scale = {1e6, kPeriod};
  a.vmax = 2.0;
  return a;
}

// A frame on the wire and the rig tick in which it was seen.
struct Seen {
  std::uint64_t tick;
  hal::CanFrame frame;
};

template <typename Loop = runtime::ServoLoop<double, 1, 4>>
struct BasicRig {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  hal::testing::FaultInjectingBus faulty{master};  // the loop's bus: passes everything unless told
  hal::LoopbackBus<256> wire{hub};                 // hears every frame anyone sends (a candump)
  hal::LoopbackBus<256> third{hub};                // another node: NMT master, SYNC producer, ...
  hal::canopen::DriveNodeConfig drive_config{};
  hal::testing::IdealDrive<> drive{hub, drive_config};
  std::vector<std::int32_t> applied_log = std::vector<std::int32_t>(1 << 18);  // what drive.applied() holds
  Loop loop{faulty, kPeriod};
  std::uint64_t now = 0;
  std::uint64_t ticks = 0;
  std::vector<std::int32_t> sent;
  std::vector<Seen> frames;
  std::vector<runtime::LoopEvent> events;
  bool drive_alive = true;  // false: the drive's process hangs (it takes and sends nothing)
  std::function<void()> before_drive;  // runs between the loop's tick and the drive's

  explicit BasicRig(const runtime::AxisConfig& a = axis(1), const hal::canopen::DriveNodeConfig& dc = {})
      : drive_config{dc} {
    EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::ok);
    drive.record_applied(applied_log);
    drive.start(now);
    loop.start(now);
  }
  void tick() {
    ++ticks;
    now += kPeriod;
    hub.set_time_us(now);
    faulty.set_time_us(now);
    loop.tick(now);
    if (loop.record(0).sent && loop.ready(0)) sent.push_back(loop.record(0).target);
    if (before_drive) before_drive();
    if (drive_alive) drive.process(now);
    hal::CanFrame f{};
    while (wire.receive(f, 0) == hal::ReceiveStatus::received) frames.push_back({ticks, f});
    for (runtime::LoopEvent e{}; loop.events().pop(e);) events.push_back(e);
  }
  bool run_until_ready(int max_ticks = 2000) {
    for (int i = 0; i < max_ticks && !loop.ready(0); ++i) tick();
    return loop.ready(0);
  }
  // Frames with this identifier seen on the wire from rig tick `from` on.
  [[nodiscard]] std::size_t count(std::uint32_t id, std::uint64_t from = 0) const {
    return static_cast<std::size_t>(std::count_if(frames.begin(), frames.end(), [&](const Seen& s) {
      return s.tick >= from && s.frame.id == id;
    }));
  }
  [[nodiscard]] std::vector<runtime::LoopEventKind> kinds(std::size_t from = 0) const {
    std::vector<runtime::LoopEventKind> k;
    for (std::size_t i = from; i < events.size(); ++i) k.push_back(events[i].kind);
    return k;
  }
};

using Rig = BasicRig<>;

// What the loop must stream for a move starting at 0, derived from the plan, not from the loop: the
// profile sampled every period, rounded to counts, to its end (the move's distance) inclusive.
std::vector<std::int32_t> expected_setpoints(const core::MoveRequest& req) {
  core::Move<double> m{};
  EXPECT_EQ(core::plan(req, m), core::Status::ok);
  const auto n = static_cast<std::size_t>(std::ceil(m.duration() * 1e3 - 1e-9));
  std::vector<std::int32_t> e;
  for (std::size_t k = 0; k <= n; ++k) {
    e.push_back(static_cast<std::int32_t>(std::nearbyint(m.at(static_cast<double>(k) * 1e-3).p * 1e6)));
  }
  return e;
}

// `applied` is exactly `expected`, then the final setpoint held: every setpoint applied once, in
// order, none skipped and none doubled.
void expect_applied_exactly(const std::vector<std::int32_t>& applied, const std::vector<std::int32_t>& expected) {
  ASSERT_GE(applied.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) ASSERT_EQ(applied[k], expected[k]) << "setpoint " << k;
  for (std::size_t k = expected.size(); k < applied.size(); ++k) ASSERT_EQ(applied[k], expected.back()) << k;
}

using Kind = runtime::LoopEventKind;
using Fault = runtime::AxisFault;

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
  r.drive.clear_applied();
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  ASSERT_EQ(r.loop.submit(0, scurve(-0.05, 0.3)), runtime::LoopStatus::ok);
  for (int i = 0; i < 1000; ++i) r.tick();
  EXPECT_TRUE(r.loop.idle());
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 2u);
  EXPECT_EQ(r.drive.position(), 50'000);  // 0.1 m - 0.05 m at 1 µm per count, exactly
  // every setpoint the loop sent while operating was applied once, in order
  ASSERT_EQ(r.drive.applied().size(), r.sent.size());
  for (std::size_t i = 0; i < r.sent.size(); ++i) ASSERT_EQ(r.drive.applied()[i], r.sent[i]) << i;
  // and they follow the profile
  core::Move<double> m{};
  ASSERT_EQ(core::plan(scurve(0.1, 0.5), m), core::Status::ok);
  for (std::size_t k = 0; k < 500; ++k) {
    ASSERT_EQ(r.sent[k], static_cast<std::int32_t>(std::nearbyint(m.at(static_cast<double>(k) * 1e-3).p * 1e6))) << k;
  }
  EXPECT_EQ(r.loop.axis_stats(0).max_following_error, 0U);
}

// The drive's software position limits (0x607D, read at start-up) bound every move's path, from
// where the moves queued before it end: a move that would leave them is refused, nothing queued.
TEST(ServoLoop, AMoveWhosePathLeavesTheDrivesSoftwareLimitsIsRefused) {
  hal::canopen::DriveNodeConfig dc{};
  dc.position_limit_min = -20'000;
  dc.position_limit_max = 100'000;
  Rig r{axis(1), dc};
  EXPECT_FALSE(r.loop.drive(0).limits().has_position_limits()) << "before start-up nothing is known";
  ASSERT_TRUE(r.run_until_ready());
  EXPECT_EQ(r.loop.drive(0).limits().position_min, -20'000);
  EXPECT_EQ(r.loop.drive(0).limits().position_max, 100'000);
  EXPECT_EQ(r.loop.submit(0, scurve(0.2, 0.5)), runtime::LoopStatus::position_limit);
  EXPECT_EQ(r.loop.submit(0, scurve(-0.03, 0.5)), runtime::LoopStatus::position_limit);
  EXPECT_TRUE(r.loop.idle()) << "nothing queued";
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok) << "to the limit itself";
  EXPECT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::position_limit) << "from where the first ends";
  ASSERT_EQ(r.loop.submit(0, scurve(-0.05, 0.3)), runtime::LoopStatus::ok);
  EXPECT_EQ(std::string{runtime::to_string(runtime::LoopStatus::position_limit)}, "position_limit");
  for (int i = 0; i < 1000; ++i) r.tick();
  EXPECT_TRUE(r.loop.idle());
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 2u);
  EXPECT_EQ(r.drive.position(), 50'000);
  EXPECT_EQ(r.drive.node().counters().steps_refused, 0u);
  // From 50 000 again: 0.06 m more leaves them, 0.05 m does not.
  EXPECT_EQ(r.loop.submit(0, scurve(0.06, 0.3)), runtime::LoopStatus::position_limit);
  EXPECT_EQ(r.loop.submit(0, scurve(0.05, 0.3)), runtime::LoopStatus::ok);
}

// The float loop (a Cortex-M4F's) checks the path on the Move<float> it streams, as the setpoints
// it sends (rounded to counts): the same refusals as the double loop, and a move to the limit
// itself is taken although 0.1F m is 100 000.0015 counts before rounding.
TEST(ServoLoop, TheFloatLoopChecksTheDrivesSoftwareLimitsOnTheMoveItStreams) {
  hal::canopen::DriveNodeConfig dc{};
  dc.position_limit_min = -20'000;
  dc.position_limit_max = 100'000;
  BasicRig<runtime::ServoLoop<float, 1, 4>> r{axis(1), dc};
  ASSERT_TRUE(r.run_until_ready());
  EXPECT_EQ(r.loop.submit(0, scurve(0.2, 0.5)), runtime::LoopStatus::position_limit);
  EXPECT_EQ(r.loop.submit(0, scurve(-0.03, 0.5)), runtime::LoopStatus::position_limit);
  EXPECT_TRUE(r.loop.idle()) << "nothing queued";
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok) << "to the limit itself";
  EXPECT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::position_limit) << "from where the first ends";
  for (int i = 0; i < 1000; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(r.drive.position(), 100'000);
  EXPECT_EQ(r.drive.node().counters().steps_refused, 0u);
}

// The drive's max profile velocity (0x607F, counts/s) against the move's true peak velocity.
TEST(ServoLoop, AMoveFasterThanTheDrivesMaxProfileVelocityIsRefused) {
  hal::canopen::DriveNodeConfig dc{};
  dc.max_profile_velocity = 100'000;  // 0.1 m/s at 1 µm per count
  Rig r{axis(1), dc};
  ASSERT_TRUE(r.run_until_ready());
  EXPECT_EQ(r.loop.drive(0).limits().max_profile_velocity, 100'000U);
  core::Move<double> fast{};
  ASSERT_EQ(core::plan(scurve(0.1, 0.5), fast), core::Status::ok);
  ASSERT_GT(fast.peaks().v, 0.1);
  EXPECT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::exceeds_drive_velocity);
  EXPECT_TRUE(r.loop.idle());
  EXPECT_EQ(std::string{runtime::to_string(runtime::LoopStatus::exceeds_drive_velocity)}, "exceeds_drive_velocity");
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.5)), runtime::LoopStatus::ok);
  for (int i = 0; i < 700; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(r.drive.position(), 10'000);
}

TEST(ServoLoop, FeedbackLogKeepsEachPeriodInArrivalOrderAndCountsWhatItHadToDrop) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  while (!r.loop.feedback_log(0).empty()) r.loop.feedback_log(0).drop_front();
  r.drive.clear_applied();
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::ok);
  // Drained every tick: one sample per period. A tick receives what the drive published after
  // the previous tick's SYNC, so sample k + 1 is the drive's answer to the k-th applied setpoint.
  std::vector<std::int32_t> logged;
  for (int i = 0; i < 101; ++i) {
    r.tick();
    for (runtime::FeedbackSample fs{}; r.loop.feedback_log(0).pop(fs);) logged.push_back(fs.position_actual);
  }
  ASSERT_EQ(logged.size(), 101U);
  ASSERT_GE(r.drive.applied().size(), 100U);
  for (std::size_t k = 0; k < 100; ++k) EXPECT_EQ(logged[k + 1], r.drive.applied()[k]) << "period " << k;
  EXPECT_EQ(r.loop.axis_stats(0).feedback_overflows, 0U);
  // Not drained: the log holds its capacity, the oldest samples stay, the rest are counted.
  const std::size_t extra = 5;
  for (std::size_t i = 0; i < runtime::kFeedbackLogCapacity + extra; ++i) r.tick();
  EXPECT_EQ(r.loop.feedback_log(0).size(), runtime::kFeedbackLogCapacity);
  EXPECT_EQ(r.loop.axis_stats(0).feedback_overflows, extra);
  runtime::FeedbackSample first{};
  ASSERT_TRUE(r.loop.feedback_log(0).pop(first));
  EXPECT_EQ(first.position_actual, r.drive.applied()[100]) << "the oldest undrained sample comes first";
}

// A drive whose static mapping is `dc`'s, read by the master (read_static). start(): ready, the
// feedback log and the drive's applied targets emptied, a 0.2 s move submitted; run(n): n ticks,
// the position actual of every sample the loop logs appended to `logged`.
struct StaticMappingRun {
  static runtime::AxisConfig static_axis() {
    runtime::AxisConfig a = axis(1);
    a.drive.pdo_setup = hal::canopen::PdoSetup::read_static;
    return a;
  }
  explicit StaticMappingRun(const hal::canopen::DriveNodeConfig& dc) : r{static_axis(), dc} {}
  [[nodiscard]] bool start() {
    if (!r.run_until_ready()) return false;
    while (!r.loop.feedback_log(0).empty()) r.loop.feedback_log(0).drop_front();
    r.drive.clear_applied();
    return r.loop.submit(0, scurve(0.01, 0.2)) == runtime::LoopStatus::ok;
  }
  void run(int ticks) {
    for (int i = 0; i < ticks; ++i) {
      r.tick();
      for (runtime::FeedbackSample fs{}; r.loop.feedback_log(0).pop(fs);) logged.push_back(fs.position_actual);
    }
  }
  Rig r;
  std::vector<std::int32_t> logged;
};

// A drive whose static mapping splits the feedback (TPDO1 = statusword + velocity actual, TPDO2 =
// position actual): one sample per period, taken once both of the period's TPDOs arrived. A period
// whose TPDO2 is lost gives no sample and no answer (as a default drive's lost TPDO1), and the
// next period is logged whole, its own position with its own statusword.
TEST(ServoLoop, AFeedbackSplitAcrossTpdosIsLoggedAWholePeriodAtATime) {
  hal::canopen::DriveNodeConfig dc{};
  dc.tpdos[0].count = 2;
  dc.tpdos[0].entries[0] = hal::canopen::PdoMappingEntry{0x6041, 0, 16};
  dc.tpdos[0].entries[1] = hal::canopen::PdoMappingEntry{0x606C, 0, 32};
  dc.tpdos[1].count = 1;
  dc.tpdos[1].entries[0] = hal::canopen::PdoMappingEntry{0x6064, 0, 32};
  StaticMappingRun m{dc};
  ASSERT_TRUE(m.start());
  Rig& r = m.r;
  const hal::canopen::RemoteDrive& d = r.loop.drive(0);
  ASSERT_TRUE(hal::canopen::feedback_split(d.config().layout));
  m.run(50);
  ASSERT_EQ(m.logged.size(), 50U);
  r.faulty.set_target(hal::CanFilter{0x281, 0x7FF});
  r.faulty.drop_receives(1);  // the next TPDO2 (the answer to applied[49]) is lost
  const std::uint64_t answered = d.feedback().tpdo1_received;
  m.run(1);
  EXPECT_EQ(m.logged.size(), 50U) << "no sample for the period whose TPDO2 was lost";
  EXPECT_EQ(d.feedback().tpdo1_received, answered) << "nor an answer";
  m.run(49);
  ASSERT_EQ(m.logged.size(), 99U);
  EXPECT_EQ(d.feedback().tpdos_dropped, 1U) << "that period's TPDO1";
  ASSERT_GE(r.drive.applied().size(), 99U);
  for (std::size_t k = 1; k < 50; ++k) EXPECT_EQ(m.logged[k], r.drive.applied()[k - 1]) << "sample " << k;
  for (std::size_t k = 50; k < 99; ++k) EXPECT_EQ(m.logged[k], r.drive.applied()[k]) << "sample " << k;
  EXPECT_EQ(r.loop.axis_stats(0).feedback_timeouts, 0U);
}

// A drive whose static mapping has one feedback TPDO (statusword + position actual, as a drive
// without 0x606C and no load position maps it): that TPDO is the whole period, and every period
// gives one sample, the position the drive applied the period before. A TPDO that carries nothing
// the master reads (TPDO3: the error register, sent every second SYNC) changes nothing.
TEST(ServoLoop, AFeedbackInOneTpdoIsLoggedEveryPeriod) {
  for (const bool tpdo3 : {false, true}) {
    SCOPED_TRACE(tpdo3 ? "and a TPDO3 of the error register" : "TPDO1 alone");
    hal::canopen::DriveNodeConfig dc{};
    dc.tpdos[0].count = 2;
    dc.tpdos[0].entries[0] = hal::canopen::PdoMappingEntry{0x6041, 0, 16};
    dc.tpdos[0].entries[1] = hal::canopen::PdoMappingEntry{0x6064, 0, 32};
    dc.tpdos[1].count = 0;
    if (tpdo3) {
      dc.tpdo_count = 3;
      dc.tpdos[2] = hal::canopen::PdoMapping{0, 2, 1, {hal::canopen::PdoMappingEntry{0x1001, 0, 8}}};
    }
    StaticMappingRun m{dc};
    ASSERT_TRUE(m.start());
    ASSERT_FALSE(hal::canopen::feedback_split(m.r.loop.drive(0).config().layout));
    m.run(50);
    ASSERT_EQ(m.logged.size(), 50U);
    ASSERT_GE(m.r.drive.applied().size(), 49U);
    for (std::size_t k = 1; k < 50; ++k) EXPECT_EQ(m.logged[k], m.r.drive.applied()[k - 1]) << "sample " << k;
    EXPECT_EQ(m.r.loop.axis_stats(0).feedback_timeouts, 0U);
  }
}

TEST(ServoLoop, RefusesWhatItCannotStreamAndChangesNothing) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  const auto sent_before = r.faulty.counters().sent;
  core::Status st{};
  auto bad = scurve(0.1, -1.0);
  EXPECT_EQ(r.loop.submit(0, bad, &st), runtime::LoopStatus::plan_failed);
  EXPECT_EQ(st, core::Status::non_positive_time);
  EXPECT_EQ(r.loop.submit(0, scurve(1.0, 0.6)), runtime::LoopStatus::exceeds_axis_velocity);  // peak > 2 m/s
  EXPECT_EQ(r.loop.submit(3, scurve(0.1, 1)), runtime::LoopStatus::no_such_axis);
  EXPECT_TRUE(r.loop.idle()) << "a refused move is not queued";
  for (int i = 0; i < 4; ++i) EXPECT_EQ(r.loop.submit(0, scurve(0.01, 0.5)), runtime::LoopStatus::ok);
  EXPECT_EQ(r.loop.submit(0, scurve(0.01, 0.5)), runtime::LoopStatus::queue_full);
  EXPECT_EQ(r.faulty.counters().sent, sent_before) << "submitting sends nothing; only tick() does";
  // Exactly the four accepted moves run: the refused ones left no trace in the queue.
  for (int i = 0; i < 2500; ++i) r.tick();
  EXPECT_TRUE(r.loop.idle());
  EXPECT_EQ(r.loop.axis_stats(0).moves_started, 4u);
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 4u);
  EXPECT_EQ(r.drive.position(), 40'000);
}

// Item 11: the RPDO and the SYNC that applies it are one unit. Faults are injected on the SYNC
// only, on the RPDO only, and on any frame at random; in every case the drive applies every
// setpoint of the move exactly once, in order (compared with the sequence derived from the plan),
// and each tick whose unit did not go out is counted as held.
struct UnitRun {
  std::vector<std::int32_t> applied;
  std::uint64_t units_held{0};
  std::uint64_t failed_sends{0};  // what the double refused, counted by the double
  std::uint64_t completed{0};
  std::int32_t position{0};
};

UnitRun run_with_send_faults(std::optional<std::uint32_t> only_id, hal::SendStatus status, bool random) {
  Rig r;
  EXPECT_TRUE(r.run_until_ready());
  r.drive.clear_applied();
  EXPECT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  const auto held_before = r.loop.stats().units_held;
  if (only_id) r.faulty.set_target(hal::CanFilter{*only_id, 0x7FF, hal::FrameFormat::standard});
  if (random) {
    hal::testing::FaultRates rates{};
    (status == hal::SendStatus::busy ? rates.tx_busy_ppm : rates.tx_error_ppm) = 40'000;
    r.faulty.set_random(12345, rates);
  }
  for (int i = 0; i < 700; ++i) {
    // runs of one, two and three failed sends: the drive tolerates three periods without SYNC
    if (!random && (i == 100 || i == 200 || i == 300)) r.faulty.fail_sends(static_cast<std::uint32_t>(i / 100), status);
    if (random && i == 450) r.faulty.set_random(1, {});
    r.tick();
  }
  UnitRun u;
  u.applied.assign(r.drive.applied().begin(), r.drive.applied().end());
  u.units_held = r.loop.stats().units_held - held_before;
  u.failed_sends = r.faulty.stats().tx_busy + r.faulty.stats().tx_errors;
  u.completed = r.loop.axis_stats(0).moves_completed;
  u.position = r.drive.position();
  EXPECT_EQ(r.loop.fault(0), runtime::AxisFault::none);
  return u;
}

void expect_every_setpoint_once(const UnitRun& u, std::uint64_t failed_sends) {
  EXPECT_EQ(u.failed_sends, failed_sends);
  EXPECT_EQ(u.units_held, failed_sends) << "each refused frame holds the moves' clock for exactly one tick";
  EXPECT_EQ(u.completed, 1u);
  EXPECT_EQ(u.position, 100'000);
  expect_applied_exactly(u.applied, expected_setpoints(scurve(0.1, 0.5)));
}

TEST(ServoLoop, ABusySyncHoldsTheMovesClockAndNoSetpointIsSkipped) {
  expect_every_setpoint_once(run_with_send_faults(0x080, hal::SendStatus::busy, false), 6);
}

TEST(ServoLoop, ABusyRpdoHoldsTheMovesClockAndNoSetpointIsAppliedTwice) {
  expect_every_setpoint_once(run_with_send_faults(0x201, hal::SendStatus::busy, false), 6);
}

TEST(ServoLoop, SendErrorsOnEitherFrameAreHeldAndResentLikeBusy) {
  expect_every_setpoint_once(run_with_send_faults(0x080, hal::SendStatus::error, false), 6);
  expect_every_setpoint_once(run_with_send_faults(0x201, hal::SendStatus::error, false), 6);
}

TEST(ServoLoop, RandomBusyAndErrorsOnEveryFrameNeverSkipOrDoubleASetpoint) {
  for (const auto status : {hal::SendStatus::busy, hal::SendStatus::error}) {
    const UnitRun u = run_with_send_faults(std::nullopt, status, true);
    ASSERT_GT(u.failed_sends, 10u) << "the seed must actually inject";
    expect_every_setpoint_once(u, u.failed_sends);
  }
}

TEST(ServoLoop, SendsThatKeepFailingHaltTheAxisAndVoidTheMove) {
  // More than the loop tolerates (LoopConfig::send_failure_periods): the axis halts with
  // send_failed, the move is void, nothing more is streamed to it; the drive was never given a jump.
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  for (int i = 0; i < 100; ++i) r.tick();
  const std::size_t before = r.events.size();
  const auto held_before = r.loop.stats().units_held;
  const auto first_held_tick = r.loop.stats().ticks + 1;
  r.faulty.fail_sends(1'000'000, hal::SendStatus::error);
  for (int i = 0; i < 50; ++i) r.tick();
  EXPECT_EQ(r.loop.stats().units_held - held_before, 50u) << "no tick's unit went out";
  EXPECT_TRUE(r.loop.halted(0));
  EXPECT_EQ(r.loop.fault(0), Fault::send_failed);
  ASSERT_EQ(r.kinds(before), (std::vector<Kind>{Kind::axis_stopped, Kind::move_voided}));
  EXPECT_EQ(r.events[before].fault, Fault::send_failed);
  EXPECT_EQ(r.events[before].tick, first_held_tick + runtime::kDefaultSendFailurePeriods - 1)
      << "halted in the tick that was the limit's";
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
  EXPECT_EQ(r.loop.axis_stats(0).moves_aborted, 1u);
  // After the halt the loop tries only its SYNC: one refused send per tick, no RPDO.
  const auto errors = r.faulty.stats().tx_errors;
  const auto rpdo_errors = r.loop.axis_stats(0).rpdo_errors;
  r.tick();
  EXPECT_EQ(r.faulty.stats().tx_errors, errors + 1);
  EXPECT_EQ(r.loop.axis_stats(0).rpdo_errors, rpdo_errors);
  for (std::size_t k = 1; k < r.drive.applied().size(); ++k) {
    ASSERT_LE(std::abs(r.drive.applied()[k] - r.drive.applied()[k - 1]), 2002) << k;
  }
  EXPECT_LT(r.drive.position(), 100'000);
}

TEST(ServoLoop, StreamsSeed001sVelocityStepWithinTheGuard) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  core::MoveRequest req{};
  req.profile = core::ProfileKind::ramp_versine;  // starts and ends with a velocity step
  req.distance = 0.1;
  req.time = 0.167;
  req.set_mode(28.28, 0.159);
  core::Move<double> m{};
  ASSERT_EQ(core::plan(req, m), core::Status::ok);
  ASSERT_TRUE(m.peaks().velocity_step);
  ASSERT_LT(m.peaks().v, 2.0);
  ASSERT_EQ(r.loop.submit(0, m), runtime::LoopStatus::ok);
  for (int i = 0; i < 400; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).step_guard_trips, 0u);
  EXPECT_EQ(r.drive.position(), 100'000);
}

// The loop on a CAN controller's buffers, held by the controller's own type (direct driver calls,
// and received records read in place, as drive firmware builds it) or as a hal::CanBus: the same
// frames, tick for tick, and the same counts.
struct ControllerRun {
  std::vector<hal::CanFrame> sent;
  std::uint64_t frames_received{0};  // the loop's
  std::uint64_t received{0};         // the controller's
  std::uint64_t feedback_count{0};
};
template <typename LoopBus>
ControllerRun run_on_controller() {
  hal::LoopbackHub hub;
  hal::LoopbackBus<64> wire{hub};  // the controller's wire side
  hal::MailboxBus<3, 8> controller;
  hal::testing::IdealDrive<> drive{hub, hal::canopen::DriveNodeConfig{}};
  runtime::ServoLoop<double, 1, 4, runtime::FloatEvaluation<double>, LoopBus> loop{controller, kPeriod};
  EXPECT_EQ(loop.add_axis(axis(1)), runtime::LoopStatus::ok);
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
    if (!submitted && loop.ready(0)) submitted = loop.submit(0, scurve(0.05, 0.3)) == runtime::LoopStatus::ok;
    loop.tick(now);
    pump();
  }
  EXPECT_TRUE(submitted);
  EXPECT_EQ(loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(drive.position(), 50'000);
  EXPECT_EQ(controller.counters().rx_overflow_drops, 0u);
  EXPECT_EQ(controller.pending_rx(), 0u) << "every received frame taken";
  return {sent, loop.stats().frames_received, controller.counters().received, loop.record(0).feedback_count};
}

TEST(ServoLoop, OnTheControllersOwnTypeItSendsWhatItSendsThroughCanBus) {
  static_assert(runtime::ServoLoop<double, 1, 4, runtime::FloatEvaluation<double>, hal::MailboxBus<3, 8>>::kReceivesInPlace);
  static_assert(!runtime::ServoLoop<double, 1, 4, runtime::FloatEvaluation<double>, hal::CanBus>::kReceivesInPlace);
  const auto direct = run_on_controller<hal::MailboxBus<3, 8>>();
  const auto virtual_calls = run_on_controller<hal::CanBus>();
  ASSERT_EQ(direct.sent.size(), virtual_calls.sent.size());
  ASSERT_GT(direct.sent.size(), 2000u);
  for (std::size_t i = 0; i < direct.sent.size(); ++i) {
    ASSERT_EQ(direct.sent[i], virtual_calls.sent[i]) << "frame " << i;
  }
  // Read in place, frames are dropped and counted once per tick: the same totals.
  EXPECT_GT(direct.frames_received, 2000u);
  EXPECT_EQ(direct.frames_received, virtual_calls.frames_received);
  EXPECT_EQ(direct.received, virtual_calls.received);
  EXPECT_EQ(direct.received, direct.frames_received);
  EXPECT_GT(direct.feedback_count, 1000u);
  EXPECT_EQ(direct.feedback_count, virtual_calls.feedback_count);
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
  r.drive.clear_applied();
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::ok);
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
  runtime::AxisConfig a = axis(1);
  a.following_error_counts = 10;
  Rig r{a};
  constexpr std::int32_t kStart = INT32_MAX - 3000;
  r.drive.set_position(kStart);
  r.drive.set_lag(5);
  ASSERT_TRUE(r.run_until_ready());
  for (int i = 0; i < 5; ++i) r.tick();
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::ok);
  for (int i = 0; i < 300; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).following_error_trips, 0u);
  EXPECT_EQ(r.loop.axis_stats(0).max_following_error, 5U);
  // 5 counts short is not at the target: the move is not reported completed while the drive
  // says so, and is once the drive catches up.
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
  EXPECT_FALSE(r.loop.idle());
  r.drive.set_lag(0);
  r.tick();
  r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  EXPECT_TRUE(r.loop.idle());
}

// Item 10: completed means the feedback showed the final setpoint within one count, not that the
// last setpoint was sent.
TEST(ServoLoop, AMoveIsCompletedOnlyWhenTheFeedbackShowsItsTargetWithinOneCount) {
  for (const std::uint32_t lag : {1U, 2U}) {
    runtime::AxisConfig a = axis(1);
    a.in_position_timeout_periods = 50;
    Rig r{a};
    r.drive.set_lag(lag);
    ASSERT_TRUE(r.run_until_ready());
    ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::ok);
    ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::ok);
    std::uint64_t end_tick = 0;
    for (int i = 0; i < 300; ++i) {
      r.tick();
      if (end_tick == 0 && r.loop.record(0).move_end) end_tick = r.ticks;
    }
    ASSERT_NE(end_tick, 0u);
    if (lag == 1) {
      EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u) << "lag 1";
      EXPECT_EQ(r.loop.axis_stats(0).moves_started, 2u) << "the next move followed once the first was done";
    } else {
      // Never within one count: void after the in-position timeout, and the queued move behind it
      // never starts (it was planned from a position the axis never reached).
      EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u) << "lag 2";
      EXPECT_EQ(r.loop.axis_stats(0).moves_started, 1u);
      EXPECT_EQ(r.loop.axis_stats(0).not_in_position, 1u);
      EXPECT_EQ(r.loop.fault(0), Fault::not_in_position);
      EXPECT_TRUE(r.loop.idle());
      const auto voided = std::find_if(r.events.begin(), r.events.end(), [](const runtime::LoopEvent& e) {
        return e.kind == Kind::move_voided;
      });
      ASSERT_NE(voided, r.events.end());
      EXPECT_EQ(voided->fault, Fault::not_in_position);
      EXPECT_EQ(voided->tick, r.loop.stats().ticks - r.ticks + end_tick + 51) << "50 periods after the final setpoint";
    }
  }
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
  ASSERT_EQ(r.loop.submit(0, liar), runtime::LoopStatus::ok);
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
  std::optional<hal::testing::IdealDrive<>> drive;
  std::vector<std::int32_t> record(1 << 16);
  drive.emplace(hub, hal::canopen::DriveNodeConfig{});
  runtime::ServoLoop<double, 1, 4> loop{master, kPeriod};
  ASSERT_EQ(loop.add_axis(axis(1)), runtime::LoopStatus::ok);
  std::uint64_t now = 0;
  drive->start(now);
  loop.start(now);
  auto tick = [&] {
    now += kPeriod;
    hub.set_time_us(now);
    loop.tick(now);
    drive->process(now);
  };
  for (int i = 0; i < 2000 && !loop.ready(0); ++i) tick();
  ASSERT_TRUE(loop.ready(0));
  ASSERT_EQ(loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  ASSERT_EQ(loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);  // queued behind it
  for (int i = 0; i < 200; ++i) tick();
  const auto restarts_before = loop.axis_stats(0).restarts;
  // The drive power-cycles mid-move: a fresh node on the bus, which announces itself (boot-up).
  drive.emplace(hub, hal::canopen::DriveNodeConfig{});
  drive->record_applied(record);
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
  // Nothing of the voided moves reached the new drive: it held where it booted, every period.
  for (int i = 0; i < 20; ++i) tick();
  ASSERT_GE(drive->applied().size(), 20u);
  for (const auto sp : drive->applied()) ASSERT_EQ(sp, 0);
  ASSERT_EQ(loop.submit(0, scurve(0.02, 0.3)), runtime::LoopStatus::ok);
  for (int i = 0; i < 400; ++i) tick();
  EXPECT_EQ(loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(drive->position(), 20'000);  // the new drive started at 0 and the loop held there
}

// The axis's scale is the one value its setpoints are computed with: a period that is not the
// loop's, or a scale that is not positive and finite, is refused before the axis exists.
TEST(ServoLoop, AnAxisScaleMustBeValidAndAtTheLoopsPeriod) {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  runtime::ServoLoop<double, 2, 2> loop{master, kPeriod};
  runtime::AxisConfig a = axis(1);
  a.scale.period_us = kPeriod / 2;
  EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::bad_axis_config);
  a.scale = {0.0, kPeriod};
  EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::bad_axis_config);
  a.scale = {std::numeric_limits<double>::infinity(), kPeriod};
  EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::bad_axis_config);
  a.scale = {1e6, kPeriod};
  EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::ok);
}

TEST(ServoLoop, ThreeAxesOnOneBusEachFollowTheirOwnMove) {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  std::vector<std::unique_ptr<hal::testing::IdealDrive<>>> drives;
  runtime::ServoLoop<double, 3, 2> loop{master, kPeriod};
  for (std::uint8_t n = 1; n <= 3; ++n) {
    ASSERT_EQ(loop.add_axis(axis(n)), runtime::LoopStatus::ok);
    hal::canopen::DriveNodeConfig dc{};
    dc.node = n;
    drives.push_back(std::make_unique<hal::testing::IdealDrive<>>(hub, dc));
  }
  EXPECT_EQ(loop.add_axis(axis(4)), runtime::LoopStatus::too_many_axes);
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
  ASSERT_EQ(loop.submit(0, scurve(0.1, 0.4)), runtime::LoopStatus::ok);
  ASSERT_EQ(loop.submit(1, scurve(-0.03, 0.2)), runtime::LoopStatus::ok);
  ASSERT_EQ(loop.submit(2, scurve(0.25, 0.7)), runtime::LoopStatus::ok);
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


// NMT commands another master sends (CiA 301: command byte, node).
hal::CanFrame nmt(std::uint8_t command, std::uint8_t node) {
  hal::CanFrame f{};
  f.id = 0x000;
  f.len = 2;
  f.data[0] = command;
  f.data[1] = node;
  return f;
}
constexpr std::uint8_t kNmtStop = 0x02;
constexpr std::uint8_t kNmtPreOperational = 0x80;

// Item 10, the feedback watchdog: the drive stops answering mid-move (its process hangs: no TPDO,
// no heartbeat). The loop streams at most feedback_timeout_periods setpoints blind, then halts the
// axis with feedback_timeout; the move is void, never completed.
TEST(ServoLoop, ADriveThatStopsAnsweringHaltsTheAxisAfterTheWatchdogsPeriods) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  for (int i = 0; i < 150; ++i) r.tick();  // about 9 % of the move
  const std::size_t before = r.events.size();
  const std::uint64_t hung_at = r.ticks;
  r.drive_alive = false;
  for (int i = 0; i < 100; ++i) r.tick();
  EXPECT_TRUE(r.loop.halted(0));
  EXPECT_FALSE(r.loop.ready(0));
  EXPECT_EQ(r.loop.fault(0), Fault::feedback_timeout);
  EXPECT_EQ(r.loop.axis_stats(0).feedback_timeouts, 1u);
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
  EXPECT_EQ(r.loop.axis_stats(0).moves_aborted, 1u);
  EXPECT_EQ(r.kinds(before), (std::vector<Kind>{Kind::axis_stopped, Kind::move_voided}));
  EXPECT_EQ(r.events[before].fault, Fault::feedback_timeout);
  EXPECT_TRUE(r.loop.idle());
  // On the wire: after the drive's last TPDO1, exactly the watchdog's periods of RPDOs, then none.
  EXPECT_EQ(r.count(0x181, hung_at + 1), 0u);
  EXPECT_EQ(r.count(0x201, hung_at + 1), runtime::kDefaultFeedbackTimeoutPeriods);
  EXPECT_EQ(r.events[before].tick, hung_at + 1 + runtime::kDefaultFeedbackTimeoutPeriods);
}

// A third party's NMT command, 150 ticks into a 0.5 s move.
void nmt_mid_move(Rig& r, std::uint8_t command, std::uint8_t node) {
  ASSERT_TRUE(r.run_until_ready());
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  for (int i = 0; i < 150; ++i) r.tick();
  ASSERT_EQ(r.third.send(nmt(command, node)), hal::SendStatus::sent);
}

// The defect as reported: a third party stops the drive mid-move (NMT stop: its TPDOs stop). The
// master sees the command on the bus (it sends no NMT command while streaming) and stops streaming
// in the tick that reads it, naming why: drive_not_operational, not a feedback timeout later. The
// same for a broadcast (node 0) and for pre-operational and the resets.
TEST(ServoLoop, AThirdPartysNmtStopMidMoveIsNeverReportedCompleted) {
  for (const std::uint8_t command : {kNmtStop, kNmtPreOperational, std::uint8_t{0x81}, std::uint8_t{0x82}}) {
    for (const std::uint8_t node : {std::uint8_t{1}, std::uint8_t{0}}) {
      SCOPED_TRACE(std::to_string(command) + " to node " + std::to_string(node));
      Rig r;
      ASSERT_NO_FATAL_FAILURE(nmt_mid_move(r, command, node));
      const std::uint64_t stopped_at = r.ticks + 1;
      for (int i = 0; i < 600; ++i) r.tick();
      EXPECT_EQ(r.loop.fault(0), Fault::drive_not_operational) << runtime::to_string(r.loop.fault(0));
      EXPECT_EQ(r.loop.axis_stats(0).feedback_timeouts, 0u);
      EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
      EXPECT_EQ(r.loop.axis_stats(0).moves_aborted, 1u);
      EXPECT_LT(r.drive.position(), 20'000);
      // After a reset the drive boots and is configured again (it holds where it is); after a stop
      // or pre-operational nothing more is streamed but the RPDO of the tick that read the command.
      if (command == kNmtStop || command == kNmtPreOperational) {
        EXPECT_FALSE(r.loop.ready(0));
        EXPECT_LE(r.count(0x201, stopped_at), 1u);
      }
    }
  }
}

// Only a command that takes this drive out of operational counts: a start, or a stop for another
// node, leaves the move running to completion.
TEST(ServoLoop, AnNmtCommandForAnotherNodeOrAStartLeavesTheMoveRunning) {
  for (const auto& [command, node] : {std::pair<std::uint8_t, std::uint8_t>{kNmtStop, 2},
                                      {kNmtPreOperational, 127}, {std::uint8_t{0x01}, 1}, {std::uint8_t{0x01}, 0}}) {
    SCOPED_TRACE(std::to_string(command) + " to node " + std::to_string(node));
    Rig r;
    ASSERT_NO_FATAL_FAILURE(nmt_mid_move(r, command, node));
    for (int i = 0; i < 600; ++i) r.tick();
    EXPECT_EQ(r.loop.fault(0), Fault::none) << runtime::to_string(r.loop.fault(0));
    EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  }
}

TEST(ServoLoop, TheWatchdogsPeriodsAreConfigurable) {
  runtime::AxisConfig a = axis(1);
  a.feedback_timeout_periods = 3;
  Rig r{a};
  ASSERT_TRUE(r.run_until_ready());
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  for (int i = 0; i < 50; ++i) r.tick();
  // The drive's feedback is lost on the way (the drive runs on): only the loop's watchdog sees it.
  r.faulty.set_target(hal::CanFilter{0x181, 0x7FF, hal::FrameFormat::standard});
  r.faulty.drop_receives(2);  // two periods lost: below the limit
  for (int i = 0; i < 20; ++i) r.tick();
  EXPECT_FALSE(r.loop.halted(0));
  r.faulty.drop_receives(3);
  for (int i = 0; i < 20; ++i) r.tick();
  EXPECT_TRUE(r.loop.halted(0));
  EXPECT_EQ(r.loop.fault(0), Fault::feedback_timeout);
}

// Item 10, heartbeat: the drive's own heartbeat says it left operational (someone else's NMT
// command). With the feedback watchdog off, the heartbeat alone voids the move and stops streaming.
TEST(ServoLoop, AHeartbeatSayingPreOperationalOrStoppedVoidsTheMove) {
  for (const std::uint8_t command : {kNmtStop, kNmtPreOperational}) {
    runtime::AxisConfig a = axis(1);
    a.feedback_timeout_periods = 0;
    Rig r{a};
    ASSERT_TRUE(r.run_until_ready());
    ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
    for (int i = 0; i < 150; ++i) r.tick();
    // The master does not see the command itself (lost on its way to the master only): the drive's
    // heartbeat is all that tells it.
    r.faulty.set_target(hal::CanFilter{0x000, 0x7FF, hal::FrameFormat::standard});
    r.faulty.drop_receives(1);
    ASSERT_EQ(r.third.send(nmt(command, 1)), hal::SendStatus::sent);
    const std::uint64_t nmt_at = r.ticks + 1;
    std::uint64_t stopped_at = 0;
    for (int i = 0; i < 400; ++i) {
      r.tick();
      if (stopped_at == 0 && r.loop.fault(0) != Fault::none) stopped_at = r.ticks;
    }
    ASSERT_NE(stopped_at, 0u) << int{command};
    EXPECT_EQ(r.loop.fault(0), Fault::drive_not_operational) << int{command};
    EXPECT_EQ(r.loop.drive(0).state(), hal::canopen::RemoteDriveState::not_operational);
    EXPECT_FALSE(r.loop.ready(0));
    EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
    EXPECT_EQ(r.loop.axis_stats(0).moves_aborted, 1u);
    EXPECT_TRUE(r.loop.idle());
    EXPECT_EQ(r.count(0x201, stopped_at + 1), 0u) << "nothing streamed after the heartbeat said so";
    // The heartbeat that said it arrived in the tick the loop stopped.
    std::uint64_t heartbeat_tick = 0;
    for (const Seen& f : r.frames) {
      if (f.frame.id == 0x701 && f.frame.data[0] != 0x05 && heartbeat_tick == 0 && f.tick >= nmt_at) heartbeat_tick = f.tick;
    }
    EXPECT_EQ(stopped_at, heartbeat_tick + 1);
  }
}

TEST(ServoLoop, AfterAHaltRestartRunsStartUpAgainAndANewMoveCompletes) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  for (int i = 0; i < 150; ++i) r.tick();
  ASSERT_EQ(r.third.send(nmt(kNmtStop, 1)), hal::SendStatus::sent);
  for (int i = 0; i < 50; ++i) r.tick();
  ASSERT_FALSE(r.loop.ready(0));
  ASSERT_EQ(r.loop.fault(0), Fault::drive_not_operational);
  const std::int32_t held = r.drive.position();
  const std::size_t before = r.events.size();
  const std::uint64_t restart_tick = r.ticks;
  r.loop.restart(0, r.now);
  ASSERT_TRUE(r.run_until_ready());
  EXPECT_GE(r.count(0x601, restart_tick), 5u) << "the SDO configuration ran again";
  EXPECT_EQ(r.kinds(before), (std::vector<Kind>{Kind::start_up_rerun, Kind::drive_ready}));
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::ok);
  for (int i = 0; i < 300; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(r.drive.position(), held + 10'000);
}

// Item 12: a SYNC the loop did not send. Every axis halts, the loop's own SYNC stops, and
// nothing more is streamed until the application restarts.
TEST(ServoLoop, ASecondSyncProducerStopsStreaming) {
  Rig r;
  ASSERT_TRUE(r.run_until_ready());
  ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
  for (int i = 0; i < 100; ++i) r.tick();
  const std::size_t before = r.events.size();
  hal::CanFrame sync{};
  sync.id = 0x080;
  ASSERT_EQ(r.third.send(sync), hal::SendStatus::sent);
  const std::uint64_t sent_at = r.ticks;
  for (int i = 0; i < 100; ++i) r.tick();
  EXPECT_EQ(r.loop.stats().foreign_syncs, 1u);
  EXPECT_TRUE(r.loop.halted(0));
  EXPECT_EQ(r.loop.fault(0), Fault::foreign_sync);
  EXPECT_EQ(r.kinds(before), (std::vector<Kind>{Kind::foreign_sync, Kind::axis_stopped, Kind::move_voided}));
  EXPECT_EQ(r.events[before].tick, sent_at + 1) << "in the tick that received it";
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
  // The foreign frame was the last SYNC on the wire, and no RPDO followed it.
  EXPECT_EQ(r.count(0x080, sent_at + 1), 1u);
  EXPECT_EQ(r.count(0x201, sent_at + 1), 0u);
  // The application decides to go on (the other producer is gone): start-up, then streaming.
  r.loop.restart(0, r.now);
  ASSERT_TRUE(r.run_until_ready());
  const std::int32_t held = r.drive.position();
  ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::ok);
  for (int i = 0; i < 300; ++i) r.tick();
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(r.drive.position(), held + 10'000);
}

// Item 13: the controller's error states, played by the fault-injecting bus (vcan has none).
// Error-passive: reported, streaming goes on. Bus-off: every axis stops, the move is void, the
// loop asks for a restart; when the bus is back the drives' start-up runs again before anything
// is streamed, and a new move completes.
TEST(ServoLoop, BusOffStopsStreamingAndRecoveryRunsStartUpAgain) {
  for (const bool restart_supported : {false, true}) {
    Rig r;
    if (restart_supported) r.faulty.set_restart_answer(hal::BusStatus::ok, /*restart_completes=*/false);
    ASSERT_TRUE(r.run_until_ready());
    ASSERT_EQ(r.loop.submit(0, scurve(0.1, 0.5)), runtime::LoopStatus::ok);
    for (int i = 0; i < 50; ++i) r.tick();
    const std::size_t before = r.events.size();
    r.faulty.inject_bus_state(hal::BusState::error_passive);
    for (int i = 0; i < 50; ++i) r.tick();
    EXPECT_EQ(r.loop.bus_state(), hal::BusState::error_passive);
    EXPECT_TRUE(r.loop.record(0).sent) << "error-passive still streams";
    EXPECT_TRUE(r.loop.record(0).moving);
    const auto sends_before_off = r.faulty.counters().sent;
    r.faulty.inject_bus_state(hal::BusState::bus_off);
    const std::uint64_t off_at = r.ticks + 1;
    for (int i = 0; i < 30; ++i) r.tick();
    EXPECT_TRUE(r.loop.halted(0));
    EXPECT_EQ(r.loop.fault(0), Fault::bus_off);
    EXPECT_EQ(r.faulty.counters().sent, sends_before_off) << "nothing is sent while bus-off";
    EXPECT_EQ(r.faulty.counters().tx_errors, 0u) << "nor tried";
    EXPECT_EQ(r.faulty.counters().restart_requests, 1u);
    r.faulty.inject_bus_state(hal::BusState::error_active);  // the controller is back
    const std::uint64_t back_at = r.ticks + 1;
    ASSERT_TRUE(r.run_until_ready());
    const std::vector<Kind> expected{Kind::bus_error_passive,
                                     Kind::bus_off,
                                     Kind::axis_stopped,
                                     Kind::move_voided,
                                     restart_supported ? Kind::bus_restart_requested : Kind::bus_restart_refused,
                                     Kind::bus_error_active,
                                     Kind::start_up_rerun,
                                     Kind::drive_ready};
    EXPECT_EQ(r.kinds(before), expected) << "restart supported: " << restart_supported;
    EXPECT_EQ(r.events[before + 1].tick, off_at);
    EXPECT_EQ(r.events[before + 6].tick, back_at);
    EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
    EXPECT_EQ(r.loop.axis_stats(0).moves_aborted, 1u);
    EXPECT_EQ(r.count(0x000, back_at), 2u) << "NMT pre-operational and start: start-up ran again";
    EXPECT_GE(r.count(0x601, back_at), 5u) << "and its SDO configuration";
    const std::int32_t held = r.drive.position();
    ASSERT_EQ(r.loop.submit(0, scurve(0.01, 0.2)), runtime::LoopStatus::ok);
    for (int i = 0; i < 300; ++i) r.tick();
    EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
    EXPECT_EQ(r.drive.position(), held + 10'000);
  }
}

TEST(ServoLoop, ARestartTheControllerCompletesAtOnceIsSeenInTheNextTick) {
  Rig r;
  r.faulty.set_restart_answer(hal::BusStatus::ok);  // back to error-active as soon as asked
  ASSERT_TRUE(r.run_until_ready());
  const std::size_t before = r.events.size();
  r.faulty.inject_bus_state(hal::BusState::bus_off);
  r.tick();
  r.tick();
  EXPECT_EQ(r.kinds(before), (std::vector<Kind>{Kind::bus_off, Kind::axis_stopped, Kind::bus_restart_requested,
                                                Kind::bus_error_active, Kind::start_up_rerun}));
  ASSERT_TRUE(r.run_until_ready());
  EXPECT_EQ(r.loop.stats().bus_offs, 1u);
}


// A pre-operational heartbeat the drive sent before it took the NMT start can arrive after the
// master sent it: that is start-up, not a third party. Only once the drive has been seen
// operational (a TPDO, an operational heartbeat) does pre-operational mean it was stopped.
TEST(ServoLoop, ALatePreOperationalHeartbeatDuringStartUpIsNotAStop) {
  Rig r;
  hal::CanFrame late{};
  late.id = 0x701;
  late.len = 1;
  late.data[0] = 0x7F;  // pre-operational
  // In the tick the master sends NMT start, the heartbeat reaches it before the drive's first TPDO.
  bool sent_late = false;
  r.before_drive = [&] {
    if (!sent_late && r.loop.drive(0).state() == hal::canopen::RemoteDriveState::enabling) {
      sent_late = r.third.send(late) == hal::SendStatus::sent;
    }
  };
  ASSERT_TRUE(r.run_until_ready()) << hal::canopen::to_string(r.loop.drive(0).state());
  ASSERT_TRUE(sent_late);
  EXPECT_EQ(r.loop.fault(0), Fault::none);
  // Once operational, the same heartbeat is a stop.
  r.before_drive = nullptr;
  ASSERT_EQ(r.third.send(late), hal::SendStatus::sent);
  r.tick();
  EXPECT_EQ(r.loop.fault(0), Fault::drive_not_operational);
  EXPECT_FALSE(r.loop.ready(0));
}

}  // namespace
