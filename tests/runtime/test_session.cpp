// SPDX-License-Identifier: Apache-2.0
// A whole streaming session on the virtual clock: it refuses to stream before the drive is
// enabled, completes with the settling window, and ends (without streaming further) with the
// outcome that names why: the drive's heartbeat lost, its feedback stopped, a second SYNC
// producer, or a refused move. A drive still enabled at the end is released (Shutdown) before
// the master goes quiet, so it does not report the master lost. With several axes (issue 17) every
// move starts on the same SYNC, and one axis lost ends the session for every axis.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "settle/runtime/session.hpp"
#include "settle/hal/testing/ideal_drive.hpp"
#include "ideal_axes.hpp"

using namespace settle;

namespace {

core::Move<double> move(double d, double t) {
  core::MoveRequest r{};
  r.profile = core::ProfileKind::scurve;
  r.distance = d;
  r.time = t;
  r.set_mode(22.0);
  core::Move<double> m{};
  EXPECT_EQ(core::plan(r, m), core::Status::ok);
  return m;
}

struct Rig {
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  hal::testing::IdealDrive<> drive{hub, hal::canopen::DriveNodeConfig{}};
  std::vector<std::int32_t> applied_log = std::vector<std::int32_t>(1 << 16);  // what drive.applied() holds
  runtime::ServoLoop<double, 1, 4> loop{master, 1000};
  runtime::VirtualClock clock{1000};
  explicit Rig(std::uint16_t feedback_timeout_periods = runtime::kDefaultFeedbackTimeoutPeriods) {
    runtime::AxisConfig a{};
    a.feedback_timeout_periods = feedback_timeout_periods;
    a.drive.heartbeat_timeout_ms = 300;
    EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::ok);
    drive.record_applied(applied_log);
    drive.start(0);
  }
};

TEST(Session, CompletesAfterTheSettlingWindow) {
  Rig r;
  const core::Move<double> moves[] = {move(0.1, 0.5), move(-0.02, 0.2)};
  std::size_t applied_before_streaming = 0;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 2, runtime::SessionConfig{},
                                         [&](std::uint64_t, bool streaming) {
                                           r.hub.set_time_us(r.clock.now_us());
                                           r.drive.process(r.clock.now_us());
                                           if (!streaming) applied_before_streaming = r.drive.applied().size();
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::completed) << runtime::to_string(res.outcome);
  EXPECT_EQ(res.fault, runtime::AxisFault::none);
  // Before the session streamed, the enabled drive was only ever told to hold where it was.
  for (std::size_t k = 0; k < applied_before_streaming; ++k) ASSERT_EQ(r.drive.applied()[k], 0) << k;
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 2u);
  EXPECT_GT(res.ready_tick, 0u);
  EXPECT_EQ(res.ticks - res.stream_end_tick, 1000u);
  EXPECT_GE(res.stream_end_tick - res.ready_tick, 700u);
  EXPECT_EQ(r.drive.position(), 80'000);
}

// The drive's view after the session: the master then sends nothing (its process ends), and the
// drive's own supervision runs on (here for 2 s, 2000 of its SYNC-loss periods).
struct Aftermath {
  std::uint64_t emcy{0};
  hal::canopen::Cia402State state{};
};
Aftermath silence_after(Rig& r) {
  const std::uint64_t emcy_before = r.drive.node().counters().emcy_sent;
  for (int k = 0; k < 2000; ++k) {
    (void)r.clock.wait();
    r.hub.set_time_us(r.clock.now_us());
    r.drive.process(r.clock.now_us());
  }
  return {r.drive.node().counters().emcy_sent - emcy_before, r.drive.node().state()};
}

TEST(Session, TheDriveIsReleasedBeforeTheMasterGoesQuiet) {
  Rig r;
  const core::Move<double> moves[] = {move(0.1, 0.5)};
  std::uint64_t last_tick = 0;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 1, runtime::SessionConfig{},
                                         [&](std::uint64_t tick, bool) {
                                           last_tick = tick;
                                           r.hub.set_time_us(r.clock.now_us());
                                           r.drive.process(r.clock.now_us());
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::completed) << runtime::to_string(res.outcome);
  EXPECT_TRUE(res.released);
  // Shutdown goes out with the first release tick's SYNC; the next tick's feedback confirms it.
  EXPECT_EQ(res.release_ticks, 2u);
  EXPECT_EQ(last_tick, res.ticks + res.release_ticks);
  EXPECT_EQ(r.loop.drive(0).state(), hal::canopen::RemoteDriveState::released);
  EXPECT_EQ(r.loop.drive(0).drive_state(), hal::canopen::Cia402State::ready_to_switch_on);
  EXPECT_FALSE(r.loop.ready(0));
  EXPECT_EQ(r.drive.position(), 100'000) << "held where the move ended";
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 1u);
  EXPECT_EQ(r.loop.axis_stats(0).moves_aborted, 0u);
  EXPECT_EQ(r.drive.node().counters().emcy_sent, 0u);
  const Aftermath after = silence_after(r);
  EXPECT_EQ(after.emcy, 0u) << "a released drive does not report the master's silence";
  EXPECT_EQ(after.state, hal::canopen::Cia402State::ready_to_switch_on);
}

// What the release prevents (the same session with no tick to release in): the drive, left
// operation enabled, detects the missing SYNCs, reports them (EMCY) and quick-stops.
TEST(Session, ADriveLeftEnabledReportsTheMasterLost) {
  Rig r;
  const core::Move<double> moves[] = {move(0.1, 0.5)};
  runtime::SessionConfig cfg{};
  cfg.release_ticks = 0;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 1, cfg, [&](std::uint64_t, bool) {
    r.hub.set_time_us(r.clock.now_us());
    r.drive.process(r.clock.now_us());
  });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::completed);
  EXPECT_FALSE(res.released);
  EXPECT_EQ(r.drive.node().state(), hal::canopen::Cia402State::operation_enabled);
  const Aftermath after = silence_after(r);
  EXPECT_EQ(after.emcy, 1u);
  EXPECT_NE(after.state, hal::canopen::Cia402State::operation_enabled);
}

// A drive that is not enabled at the end (its heartbeat lost) is not released: nothing is sent to it.
TEST(Session, ALostDriveIsNotReleased) {
  Rig r(0);
  const core::Move<double> moves[] = {move(0.1, 0.5)};
  std::uint64_t streaming_ticks = 0;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 1, runtime::SessionConfig{},
                                         [&](std::uint64_t, bool streaming) {
                                           r.hub.set_time_us(r.clock.now_us());
                                           if (streaming) ++streaming_ticks;
                                           if (streaming_ticks < 200) r.drive.process(r.clock.now_us());
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::drive_lost);
  EXPECT_FALSE(res.released);
  EXPECT_EQ(res.release_ticks, 0u);
}

// The loop's own step guard stopping a move is the loop's outcome, not a lost drive: a move whose
// peaks claim 0.1 m/s but which moves at ~3 m/s (the axis allows 2) ends step_guard, and the drive,
// which was never lost, is released at the end like any drive still enabled.
TEST(Session, AStepGuardTripIsTheLoopsOutcomeNotALostDrive) {
  Rig r;
  const core::Move<double> fast = move(0.5, 0.3);
  ASSERT_GT(fast.peaks().v, 2.5);
  core::Peaks<double> lie = fast.peaks();
  lie.v = 0.1;
  const core::Move<double> moves[] = {core::Move<double>{fast.profile(), fast.shaper(), lie}};
  const auto res = runtime::run_session(r.loop, r.clock, moves, 1, runtime::SessionConfig{},
                                         [&](std::uint64_t, bool) {
                                           r.hub.set_time_us(r.clock.now_us());
                                           r.drive.process(r.clock.now_us());
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::step_guard) << runtime::to_string(res.outcome);
  EXPECT_EQ(res.fault, runtime::AxisFault::step_guard);
  EXPECT_STREQ(runtime::to_string(res.outcome), "step_guard");
  EXPECT_EQ(r.loop.axis_stats(0).step_guard_trips, 1u);
  EXPECT_TRUE(res.released);
  EXPECT_LT(r.drive.position(), 500'000);
}

TEST(Session, HeartbeatLossMidMoveStopsStreaming) {
  Rig r(0);  // the feedback watchdog off: the heartbeat alone must notice
  const core::Move<double> moves[] = {move(0.1, 0.5)};
  std::uint64_t sent_after_loss = 0, streaming_ticks = 0;
  bool lost = false;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 1, runtime::SessionConfig{},
                                         [&](std::uint64_t, bool streaming) {
                                           r.hub.set_time_us(r.clock.now_us());
                                           if (lost && r.loop.record(0).sent) ++sent_after_loss;
                                           if (r.loop.drive(0).state() == hal::canopen::RemoteDriveState::lost) lost = true;
                                           if (streaming) ++streaming_ticks;
                                           // the plant process dies 200 ticks into the move
                                           if (streaming_ticks < 200) r.drive.process(r.clock.now_us());
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::drive_lost) << runtime::to_string(res.outcome);
  EXPECT_EQ(res.fault, runtime::AxisFault::heartbeat_lost);
  EXPECT_EQ(r.loop.axis_stats(0).heartbeat_losses, 1u);
  EXPECT_EQ(sent_after_loss, 0u);
  EXPECT_NE(r.drive.position(), 100'000);  // stopped mid-move
}

TEST(Session, ADriveThatStopsAnsweringEndsWithFeedbackTimeout) {
  Rig r;
  const core::Move<double> moves[] = {move(0.1, 0.5)};
  std::uint64_t streaming_ticks = 0;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 1, runtime::SessionConfig{},
                                         [&](std::uint64_t, bool streaming) {
                                           r.hub.set_time_us(r.clock.now_us());
                                           if (streaming) ++streaming_ticks;
                                           if (streaming_ticks < 200) r.drive.process(r.clock.now_us());
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::feedback_timeout) << runtime::to_string(res.outcome);
  EXPECT_EQ(res.fault, runtime::AxisFault::feedback_timeout);
  EXPECT_EQ(std::string{runtime::to_string(res.outcome)}, "feedback_timeout");
  EXPECT_EQ(r.loop.axis_stats(0).heartbeat_losses, 0u) << "long before the 300 ms heartbeat timeout";
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
}

TEST(Session, ASecondSyncProducerEndsWithForeignSync) {
  Rig r;
  hal::LoopbackBus<16> other{r.hub};
  const core::Move<double> moves[] = {move(0.1, 0.5)};
  std::uint64_t streaming_ticks = 0;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 1, runtime::SessionConfig{},
                                         [&](std::uint64_t, bool streaming) {
                                           r.hub.set_time_us(r.clock.now_us());
                                           r.drive.process(r.clock.now_us());
                                           if (streaming && ++streaming_ticks == 100) {
                                             hal::CanFrame sync{};
                                             sync.id = 0x080;
                                             (void)other.send(sync);
                                           }
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::foreign_sync) << runtime::to_string(res.outcome);
  EXPECT_EQ(r.loop.axis_stats(0).moves_completed, 0u);
}

TEST(Session, RefusedMoveEndsTheSessionBeforeStreamingIt) {
  Rig r;
  const core::Move<double> moves[] = {move(5.0, 0.5)};  // 15 m/s peak: over the axis's 1 m/s
  const auto res = runtime::run_session(r.loop, r.clock, moves, 1, runtime::SessionConfig{},
                                         [&](std::uint64_t, bool) {
                                           r.hub.set_time_us(r.clock.now_us());
                                           r.drive.process(r.clock.now_us());
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::rejected);
  EXPECT_EQ(res.rejection, runtime::LoopStatus::exceeds_axis_velocity);
  EXPECT_EQ(r.drive.position(), 0);
}

// Three axes on one bus, nodes 1..3, one move each.
struct ThreeAxisRig {
  static constexpr std::size_t kAxes = 3;
  hal::LoopbackHub hub;
  hal::LoopbackBus<256> master{hub};
  std::array<std::unique_ptr<hal::testing::IdealDrive<>>, kAxes> drives;
  runtime::ServoLoop<double, kAxes, 4> loop{master, 1000};
  runtime::VirtualClock clock{1000};
  ThreeAxisRig() {
    runtime::AxisConfig a{};
    a.drive.heartbeat_timeout_ms = 300;
    settle::testing::add_ideal_axes(loop, hub, drives, a);
    for (auto& d : drives) d->start(0);
  }
  // Every drive but `dead` answers (dead: none).
  void process(std::size_t dead = kAxes) {
    hub.set_time_us(clock.now_us());
    for (std::size_t i = 0; i < kAxes; ++i) {
      if (i != dead) drives[i]->process(clock.now_us());
    }
  }
};

constexpr std::uint64_t kNever = ~std::uint64_t{0};

TEST(Session, EveryAxisStartsOnTheSameSync) {
  ThreeAxisRig r;
  // Three distances, one duration: every axis ends on the same tick too.
  const core::Move<double> moves[] = {move(0.1, 0.5), move(0.05, 0.5), move(-0.2, 0.5)};
  std::array<std::uint64_t, 3> first_moving{kNever, kNever, kNever}, last{kNever, kNever, kNever};
  const auto res = runtime::run_session(r.loop, r.clock, moves, 3, runtime::SessionConfig{},
                                         [&](std::uint64_t tick, bool) {
                                           for (std::size_t i = 0; i < 3; ++i) {
                                             const auto& rec = r.loop.record(i);
                                             if (rec.moving && rec.sent && first_moving[i] == kNever) first_moving[i] = tick;
                                             if (rec.move_end) last[i] = tick;
                                           }
                                           r.process();
                                         });
  ASSERT_EQ(res.outcome, runtime::SessionOutcome::completed) << runtime::to_string(res.outcome);
  EXPECT_EQ(res.axis, 0u);
  EXPECT_NE(first_moving[0], kNever);
  EXPECT_EQ(first_moving[0], res.ready_tick + 1) << "the moves start in the tick after they are submitted";
  EXPECT_EQ(first_moving[1], first_moving[0]);
  EXPECT_EQ(first_moving[2], first_moving[0]);
  EXPECT_NE(last[0], kNever);
  EXPECT_EQ(last[1], last[0]);
  EXPECT_EQ(last[2], last[0]);
  EXPECT_EQ(last[0] - first_moving[0], 500u) << "0.5 s at 1 kHz: 501 setpoints";
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(r.loop.axis_stats(i).moves_completed, 1u) << i;
  EXPECT_EQ(r.drives[0]->position(), 100'000);
  EXPECT_EQ(r.drives[1]->position(), 50'000);
  EXPECT_EQ(r.drives[2]->position(), -200'000);
  EXPECT_TRUE(res.released);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(r.loop.drive(i).state(), hal::canopen::RemoteDriveState::released) << i;
  }
}

// Axis 2 (index 1) stops answering mid-move: the session ends with its outcome, names it, and no
// axis streams a move after that tick; the other two are released.
TEST(Session, OneAxisFaultingStopsEveryAxis) {
  ThreeAxisRig r;
  const core::Move<double> moves[] = {move(0.1, 0.5), move(0.05, 0.5), move(-0.2, 0.5)};
  std::uint64_t streaming_ticks = 0, moving_after_end = 0;
  bool ended = false;
  std::uint64_t end_tick = 0;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 3, runtime::SessionConfig{},
                                         [&](std::uint64_t tick, bool streaming) {
                                           if (ended && tick > end_tick) {
                                             for (std::size_t i = 0; i < 3; ++i) {
                                               moving_after_end += r.loop.record(i).moving ? 1u : 0u;
                                             }
                                           }
                                           if (streaming) ++streaming_ticks;
                                           if (!ended && r.loop.halted(1)) {
                                             ended = true;
                                             end_tick = tick;
                                           }
                                           r.process(streaming_ticks < 200 ? std::size_t{3} : std::size_t{1});
                                         });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::feedback_timeout) << runtime::to_string(res.outcome);
  EXPECT_EQ(res.fault, runtime::AxisFault::feedback_timeout);
  EXPECT_EQ(res.axis, 1u);
  EXPECT_TRUE(ended);
  EXPECT_EQ(res.ticks, end_tick) << "the session ends in the tick the loop halted the axis";
  EXPECT_EQ(moving_after_end, 0u) << "no axis streams its move after the fault";
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(r.loop.axis_stats(i).moves_completed, 0u) << i;
    EXPECT_EQ(r.loop.axis_stats(i).moves_aborted, 1u) << i;
  }
  EXPECT_NE(r.drives[0]->position(), 100'000);  // stopped mid-move
  EXPECT_NE(r.drives[2]->position(), -200'000);
  EXPECT_TRUE(res.released) << "the two drives still enabled confirm their release";
  EXPECT_EQ(r.loop.drive(0).state(), hal::canopen::RemoteDriveState::released);
  EXPECT_EQ(r.loop.drive(2).state(), hal::canopen::RemoteDriveState::released);
  EXPECT_NE(r.loop.drive(1).state(), hal::canopen::RemoteDriveState::released);
}

TEST(Session, ARefusedMoveNamesItsAxisAndNothingStreams) {
  ThreeAxisRig r;
  const core::Move<double> moves[] = {move(0.1, 0.5), move(0.05, 0.5), move(5.0, 0.5)};  // axis 3 over 1 m/s
  const auto res = runtime::run_session(r.loop, r.clock, moves, 3, runtime::SessionConfig{},
                                         [&](std::uint64_t, bool) { r.process(); });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::rejected);
  EXPECT_EQ(res.rejection, runtime::LoopStatus::exceeds_axis_velocity);
  EXPECT_EQ(res.axis, 2u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(r.loop.axis_stats(i).moves_started, 0u) << i;
    EXPECT_EQ(r.drives[i]->position(), 0) << i;
  }
}

TEST(Session, ADriveThatNeverEnablesIsNamed) {
  ThreeAxisRig r;
  const core::Move<double> moves[] = {move(0.1, 0.5), move(0.05, 0.5), move(-0.2, 0.5)};
  runtime::SessionConfig cfg{};
  cfg.enable_timeout_ticks = 500;
  const auto res = runtime::run_session(r.loop, r.clock, moves, 3, cfg, [&](std::uint64_t, bool) { r.process(2); });
  EXPECT_EQ(res.outcome, runtime::SessionOutcome::enable_failed);
  EXPECT_EQ(res.axis, 2u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(r.drives[i]->position(), 0) << i;
}

}  // namespace
