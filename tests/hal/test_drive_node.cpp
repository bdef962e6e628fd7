// SPDX-License-Identifier: Apache-2.0
// Master (RemoteDrive) and drive (DriveNode) talking over the loopback bus on a virtual 1 kHz
// clock: start-up, enable sequence, CSP streaming, and the drive-side safety rules, with the
// exact period at which each timeout must fire.
#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/testing/fault_injecting_bus.hpp"

namespace settle::hal::canopen {
namespace {

constexpr NodeId drive_id = 2;
constexpr std::uint64_t period_us = 1000;

class DriveOverLoopback : public ::testing::Test {
 protected:
  DriveOverLoopback() { bus_under_test = &master_port; }

  DriveNodeConfig drive_config() {
    DriveNodeConfig c{};
    c.node = drive_id;
    c.heartbeat_period_ms = 20;
    return c;
  }
  RemoteDriveConfig remote_config() {
    RemoteDriveConfig c{};
    c.node = drive_id;
    c.heartbeat_timeout_ms = 100;
    c.sdo_timeout_us = 20'000;
    c.enable_timeout_us = 50'000;
    return c;
  }

  // One servo period. The master sends its RPDO and the SYNC; the drive (an ideal axis that
  // reaches each setpoint by the end of the period) answers; the master reads the answers.
  void tick(std::int32_t target, bool send_rpdo = true, bool send_sync = true, bool run_drive = true) {
    now += period_us;
    hub.set_time_us(now);
    fault.set_time_us(now);
    remote->poll(now, *bus_under_test);
    if (send_rpdo) {
      if (CanFrame rpdo{}; remote->rpdo(target, rpdo)) {
        (void)bus_under_test->send(rpdo);
      }
    }
    if (send_sync) {
      (void)bus_under_test->send(sync.next());
    }
    if (run_drive) {
      run_drive_side();
    }
    CanFrame f{};
    while (bus_under_test->receive(f) == ReceiveStatus::received) {
      remote->on_frame(f, now, *bus_under_test);
    }
  }

  void run_drive_side() {
    CanFrame f{};
    while (drive_port.receive(f) == ReceiveStatus::received) {
      received_by_drive.push_back(f);
      if (drive->on_frame(f, now, drive_port) == DriveEvent::sync) {
        if (drive->stopping()) {
          drive->stop_complete();  // this axis stops at once
        } else if (drive->following() && !frozen_axis) {
          axis = drive->setpoint();
        }
        drive->publish(DriveFeedback{axis, 0, axis / 2}, now, drive_port);
      }
    }
    drive->poll(now, drive_port);
  }

  bool run_until_ready(int max_ticks = 200) {
    for (int i = 0; i < max_ticks && !remote->ready(); ++i) {
      tick(axis);
    }
    return remote->ready();
  }

  void start() {
    drive->start(now, drive_port);
    remote->start(now, *bus_under_test);
  }

  std::vector<EmcyMessage> emcys_seen_by(const std::vector<CanFrame>& frames) const {
    std::vector<EmcyMessage> out;
    for (const CanFrame& f : frames) {
      if (const auto e = decode_emcy(f); e && e->node == drive_id) {
        out.push_back(e->message);
      }
    }
    return out;
  }

  LoopbackHub hub;
  LoopbackBus<64> master_port{hub};
  LoopbackBus<64> drive_port{hub};
  LoopbackBus<256> monitor{hub};  // hears everything, like candump
  testing::FaultInjectingBus fault{master_port};
  CanBus* bus_under_test;
  std::optional<DriveNode> drive{std::in_place, drive_config()};
  std::optional<RemoteDrive> remote{std::in_place, remote_config()};
  SyncProducer sync{static_cast<std::uint32_t>(period_us)};
  std::vector<CanFrame> received_by_drive;
  std::uint64_t now{0};
  std::int32_t axis{0};
  bool frozen_axis{false};

  std::vector<CanFrame> monitor_frames() {
    std::vector<CanFrame> frames;
    CanFrame f{};
    while (monitor.receive(f) == ReceiveStatus::received) {
      frames.push_back(f);
    }
    return frames;
  }
};

TEST_F(DriveOverLoopback, StartUpConfiguresTheDriveAndEnablesItWithoutMovingTheAxis) {
  axis = 12345;
  drive.emplace(drive_config());
  start();
  ASSERT_TRUE(run_until_ready()) << to_string(remote->state());
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_EQ(drive->nmt_state(), NmtState::operational);
  EXPECT_EQ(drive->mode(), OperationMode::cyclic_synchronous_position);
  EXPECT_EQ(drive->objects().comm.cycle_period_us, 1000U);
  EXPECT_EQ(drive->interpolation_period_us(), 1000U);
  EXPECT_EQ(axis, 12345) << "enabling holds the axis where it is";
  EXPECT_EQ(remote->take_events() & remote_event::became_ready, remote_event::became_ready);

  // The controlwords seen by the drive: shutdown, switch on, enable operation, in that order.
  std::vector<std::uint16_t> controlwords;
  for (const CanFrame& f : received_by_drive) {
    if (const auto r = decode_rpdo1(f, drive_id); r && (controlwords.empty() || controlwords.back() != r->controlword)) {
      controlwords.push_back(r->controlword);
    }
  }
  const std::vector<std::uint16_t> expected{0x0000, 0x0006, 0x0007, 0x000F};
  EXPECT_EQ(controlwords, expected);
}

TEST_F(DriveOverLoopback, EverySetpointIsAppliedExactlyOnceInOrder) {
  start();
  ASSERT_TRUE(run_until_ready());
  const std::uint64_t applied_before = drive->counters().rpdos_applied;
  for (std::int32_t k = 1; k <= 1000; ++k) {
    const std::int32_t target = 7 * k - 3 * (k % 5);
    tick(target);
    ASSERT_EQ(axis, target) << "tick " << k;
    ASSERT_EQ(remote->feedback().position_actual, target) << "TPDO1 of tick " << k;
    ASSERT_EQ(remote->feedback().load_position, target / 2);
  }
  EXPECT_EQ(drive->counters().rpdos_applied - applied_before, 1000U);
  EXPECT_EQ(drive->counters().rpdos_overwritten, 0U);
  EXPECT_EQ(drive->counters().rpdos_missing, 0U);
  EXPECT_EQ(remote->state(), RemoteDriveState::ready);
}

TEST_F(DriveOverLoopback, RemoteDriveSaysWhatEachFrameWasAndIgnoresOtherNodes) {
  start();
  ASSERT_TRUE(run_until_ready());
  const auto kind = [&](const CanFrame& f) { return remote->on_frame(f, now, *bus_under_test); };
  EXPECT_EQ(kind(encode_tpdo1(drive_id, Tpdo1{0x0237, 11})), RemoteFrame::tpdo1);
  EXPECT_EQ(remote->feedback().position_actual, 11);
  EXPECT_EQ(kind(encode_tpdo2(drive_id, Tpdo2{22, 33})), RemoteFrame::tpdo2);
  EXPECT_EQ(remote->feedback().load_position, 22);
  EXPECT_EQ(remote->feedback().velocity_actual, 33);
  EXPECT_EQ(kind(encode_heartbeat(drive_id, NmtState::operational)), RemoteFrame::heartbeat);
  EXPECT_EQ(kind(encode_emcy(drive_id, EmcyMessage{emcy_code::generic, 0x01, {}})), RemoteFrame::emcy);
  EXPECT_NE(remote->take_events() & remote_event::emcy, 0);

  // Another node's feedback, a SYNC, a TPDO of the wrong length, an extended frame with the
  // same low bits: ignored, and the feedback is untouched.
  const RemoteFeedback before = remote->feedback();
  EXPECT_EQ(kind(encode_tpdo1(drive_id + 1, Tpdo1{0x0237, 99})), RemoteFrame::ignored);
  EXPECT_EQ(kind(encode_tpdo2(drive_id + 1, Tpdo2{99, 99})), RemoteFrame::ignored);
  EXPECT_EQ(kind(encode_sync()), RemoteFrame::ignored);
  CanFrame short_tpdo2 = encode_tpdo2(drive_id, Tpdo2{99, 99});
  short_tpdo2.len = 7;
  EXPECT_EQ(kind(short_tpdo2), RemoteFrame::ignored);
  CanFrame extended = encode_tpdo1(drive_id, Tpdo1{0x0237, 99});
  extended.flags = can_flag::extended;
  EXPECT_EQ(kind(extended), RemoteFrame::ignored);
  CanFrame long_tpdo1 = encode_tpdo1(drive_id, Tpdo1{0x0237, 99});
  long_tpdo1.len = 7;
  EXPECT_EQ(kind(long_tpdo1), RemoteFrame::ignored);
  CanFrame rtr_tpdo1 = encode_tpdo1(drive_id, Tpdo1{0x0237, 99});
  rtr_tpdo1.flags = can_flag::rtr;
  EXPECT_EQ(kind(rtr_tpdo1), RemoteFrame::ignored);
  // A heartbeat of two bytes, or with node guarding's toggle bit, or an unknown state: not one.
  CanFrame hb = encode_heartbeat(drive_id, NmtState::operational);
  hb.len = 2;
  EXPECT_EQ(kind(hb), RemoteFrame::ignored);
  hb = encode_heartbeat(drive_id, NmtState::operational);
  hb.data[0] = 0x85;
  EXPECT_EQ(kind(hb), RemoteFrame::ignored);
  hb.data[0] = 0x06;
  EXPECT_EQ(kind(hb), RemoteFrame::ignored);
  EXPECT_EQ(kind(encode_heartbeat(drive_id + 1, NmtState::initialising)), RemoteFrame::ignored);
  EXPECT_EQ(remote->feedback().position_actual, before.position_actual);
  EXPECT_EQ(remote->feedback().load_position, before.load_position);
  EXPECT_EQ(remote->feedback().tpdo1_received, before.tpdo1_received);
  EXPECT_EQ(remote->feedback().periods_complete, before.periods_complete);
  EXPECT_EQ(remote->take_events(), 0);
}

TEST_F(DriveOverLoopback, RpdoIsWrittenOverTheCallersFrame) {
  start();
  ASSERT_TRUE(run_until_ready());
  CanFrame f = encode_tpdo2(drive_id, Tpdo2{-1, -1});  // a different frame, all bytes set
  f.flags = can_flag::fd;
  ASSERT_TRUE(remote->rpdo(-123456, f));
  EXPECT_EQ(f, encode_rpdo1(drive_id, Rpdo1{controlword::enable_operation, -123456}));
}

TEST_F(DriveOverLoopback, SyncLossQuickStopsTheDriveAndSendsEmcy) {
  start();
  ASSERT_TRUE(run_until_ready());
  (void)monitor_frames();
  const std::uint64_t last_sync = now;
  // The master goes silent; the drive keeps its own time. Three missing SYNCs are tolerated
  // (0x2001 = 3), the loss is declared 4.5 periods after the last SYNC.
  while (now < last_sync + 4'400) {
    now += 100;
    drive->poll(now, drive_port);
  }
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  now = last_sync + 4'500;
  drive->poll(now, drive_port);
  EXPECT_EQ(drive->state(), Cia402State::quick_stop_active);
  const auto emcys = emcys_seen_by(monitor_frames());
  ASSERT_EQ(emcys.size(), 1U);
  EXPECT_EQ(emcys[0].error_code, emcy_code::communication);
  EXPECT_EQ(emcys[0].error_register & error_register::communication, error_register::communication);
  drive->stop_complete();
  EXPECT_EQ(drive->state(), Cia402State::switch_on_disabled) << "quick-stop option 2";
}

TEST_F(DriveOverLoopback, RpdoLossQuickStopsAndRecoveryReenablesAndClearsTheError) {
  start();
  ASSERT_TRUE(run_until_ready());
  (void)remote->take_events();
  for (int i = 0; i < 3; ++i) {
    tick(0, false);
    EXPECT_EQ(drive->state(), Cia402State::operation_enabled) << "missing RPDO " << i + 1 << " is tolerated";
  }
  tick(0, false);
  EXPECT_EQ(drive->counters().rpdos_missing, 4U);
  EXPECT_EQ(remote->state(), RemoteDriveState::stopped);
  const std::uint16_t events = remote->take_events();
  EXPECT_NE(events & remote_event::left_enabled, 0);
  EXPECT_NE(events & remote_event::emcy, 0);
  EXPECT_EQ(remote->emcy().last().error_code, emcy_code::rpdo_timeout);
  EXPECT_TRUE(remote->emcy().in_error());

  CanFrame untouched = encode_sync(7);
  EXPECT_FALSE(remote->rpdo(0, untouched)) << "no process data to a drive that stopped";
  EXPECT_EQ(untouched, encode_sync(7)) << "a refused RPDO leaves the caller's frame as it was";
  remote->recover(now);
  ASSERT_TRUE(run_until_ready());
  EXPECT_FALSE(remote->emcy().in_error()) << "re-enabling ends the communication error (EMCY 0000)";
  EXPECT_EQ(drive->objects().comm.error_register, 0);
}

TEST_F(DriveOverLoopback, BusyOnTheMastersTransmitIsCountedAndToleratedBelowTheLossLimit) {
  bus_under_test = &fault;
  start();
  ASSERT_TRUE(run_until_ready());
  fault.set_target(CanFilter{cob_id(cob::rpdo1, drive_id), 0x7FF});
  fault.fail_sends(2, SendStatus::busy);
  for (std::int32_t k = 1; k <= 10; ++k) {
    tick(k);
  }
  EXPECT_EQ(fault.counters().tx_busy, 2U);
  EXPECT_EQ(drive->counters().rpdos_missing, 2U);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_EQ(axis, 10);
}

TEST_F(DriveOverLoopback, MasterHeartbeatLossFollowsTheAbortConnectionOption) {
  RemoteDriveConfig rc = remote_config();
  rc.master_node = 0x7F;
  rc.master_heartbeat_timeout_ms = 30;
  remote.emplace(rc);
  HeartbeatProducer master_heartbeat{0x7F, 10};
  master_heartbeat.start(0);
  std::uint64_t last_beat = 0;
  start();
  for (int i = 0; i < 200 && !remote->ready(); ++i) {
    if (master_heartbeat.poll(now, NmtState::operational, master_port)) {
      last_beat = now + period_us;  // the drive reads it in the next tick
    }
    tick(axis);
  }
  ASSERT_TRUE(remote->ready());
  EXPECT_EQ(drive->objects().comm.consumer_heartbeat, 0x007F'001EU);
  // Keep streaming, but the master's heartbeat stops: 0x6007 = 1 -> fault.
  while (now < last_beat + 40'000 && drive->state() == Cia402State::operation_enabled) {
    tick(axis);
  }
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active);
  EXPECT_EQ(now, last_beat + 30'000) << "the 30 ms consumer time, to the period";
  tick(axis);  // the axis reports it has stopped: the fault reaction ends
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(remote->emcy().last().error_code, emcy_code::life_guard);
  EXPECT_EQ(remote->state(), RemoteDriveState::stopped);
}

TEST_F(DriveOverLoopback, NmtStopWhileEnabledAppliesQuickStopWhenOptionSaysSo) {
  start();
  ASSERT_TRUE(run_until_ready());
  std::uint32_t raw = 3;
  ASSERT_EQ(drive->dictionary().write(obj::abort_connection_option, 0, raw, 2), SdoAbort::none);
  FrameBuffer<4> out;
  EXPECT_EQ(drive->on_frame(encode_nmt(NmtCommand::stop, drive_id), now, out), DriveEvent::handled);
  EXPECT_EQ(drive->nmt_state(), NmtState::stopped);
  EXPECT_EQ(drive->state(), Cia402State::quick_stop_active);
}

TEST_F(DriveOverLoopback, FollowingErrorBeyondTheWindowFaultsTheDrive) {
  DriveNodeConfig dc = drive_config();
  dc.following_error_window = 50;
  dc.following_error_timeout_ms = 3;
  drive.emplace(dc);
  start();
  ASSERT_TRUE(run_until_ready());
  tick(40);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  frozen_axis = true;  // the axis stops following
  tick(100);
  EXPECT_NE(drive->objects().app.statusword & statusword::following_error, 0);
  tick(100);
  tick(100);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled) << "within the 3 ms timeout";
  tick(100);
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active);
  tick(100);
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(drive->objects().app.error_code, emcy_code::following_error);
  EXPECT_EQ(remote->emcy().last().error_code, emcy_code::following_error);
  // The master's recovery resets the fault with a rising bit 7 and enables again.
  frozen_axis = false;
  remote->recover(now);
  ASSERT_TRUE(run_until_ready());
  EXPECT_EQ(drive->objects().app.error_code, 0);
}

TEST_F(DriveOverLoopback, SoftwareLimitsClampTheSetpointAndRaiseInternalLimit) {
  DriveNodeConfig dc = drive_config();
  dc.position_limit_min = -1000;
  dc.position_limit_max = 1000;
  drive.emplace(dc);
  start();
  ASSERT_TRUE(run_until_ready());
  tick(5000);
  EXPECT_EQ(axis, 1000);
  EXPECT_NE(remote->feedback().statusword & statusword::internal_limit, 0);
  tick(-5000);
  EXPECT_EQ(axis, -1000);
  tick(10);
  EXPECT_EQ(axis, 10);
  EXPECT_EQ(remote->feedback().statusword & statusword::internal_limit, 0);
}

TEST_F(DriveOverLoopback, DriveRestartMakesTheMasterConfigureAndEnableAgain) {
  start();
  ASSERT_TRUE(run_until_ready());
  (void)remote->take_events();
  drive.emplace(drive_config());  // power cycle: default mode, not configured, not enabled
  drive->start(now, drive_port);
  tick(axis);
  EXPECT_NE(remote->take_events() & remote_event::boot_up, 0);
  EXPECT_FALSE(remote->ready());
  ASSERT_TRUE(run_until_ready());
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
}

TEST_F(DriveOverLoopback, NmtResetNodeRestoresDefaultsAndBootsAgain) {
  start();
  ASSERT_TRUE(run_until_ready());
  FrameBuffer<8> out;
  EXPECT_EQ(drive->on_frame(encode_nmt(NmtCommand::reset_node, 0), now, out), DriveEvent::reset);
  EXPECT_EQ(drive->state(), Cia402State::switch_on_disabled);
  EXPECT_EQ(drive->nmt_state(), NmtState::pre_operational);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0], encode_heartbeat(drive_id, NmtState::initialising));
}

TEST_F(DriveOverLoopback, SilentDriveIsReportedLost) {
  start();
  ASSERT_TRUE(run_until_ready());
  (void)remote->take_events();
  const std::uint64_t t0 = now;
  while (now < t0 + 150'000 && remote->state() != RemoteDriveState::lost) {
    tick(axis, true, true, false);
  }
  EXPECT_EQ(remote->state(), RemoteDriveState::lost);
  EXPECT_NE(remote->take_events() & remote_event::heartbeat_lost, 0);
  CanFrame unused{};
  EXPECT_FALSE(remote->rpdo(0, unused));
}

TEST_F(DriveOverLoopback, UnsupportedModeFailsStartUpWithTheDrivesAbortCode) {
  RemoteDriveConfig rc = remote_config();
  rc.mode = OperationMode::profile_position;
  remote.emplace(rc);
  start();
  for (int i = 0; i < 20; ++i) {
    tick(0);
  }
  EXPECT_EQ(remote->state(), RemoteDriveState::failed);
  EXPECT_EQ(remote->failure().index, obj::modes_of_operation);
  EXPECT_EQ(remote->failure().abort, SdoAbort::invalid_value);
}

// The first request times out, is sent once more, and times out again.
TEST_F(DriveOverLoopback, AbsentDriveTimesOutTheFirstSdo) {
  remote->start(now, master_port);
  for (int i = 0; i < 39; ++i) {
    tick(0, true, true, false);
  }
  EXPECT_EQ(remote->state(), RemoteDriveState::configuring);
  tick(0, true, true, false);
  EXPECT_EQ(remote->state(), RemoteDriveState::failed);
  EXPECT_EQ(remote->failure().status, SdoClientStatus::timed_out);
  EXPECT_EQ(remote->failure().error, StartupError::sdo_timed_out);
  EXPECT_EQ(remote->failure().index, obj::device_type);
}

TEST_F(DriveOverLoopback, InterpolatedPositionModeFollowsOnlyWithIpEnabled) {
  RemoteDriveConfig rc = remote_config();
  rc.mode = OperationMode::interpolated_position;
  remote.emplace(rc);
  start();
  ASSERT_TRUE(run_until_ready());
  EXPECT_EQ(drive->mode(), OperationMode::interpolated_position);
  tick(77);
  EXPECT_EQ(axis, 77);
  EXPECT_NE(remote->feedback().statusword & statusword::mode_specific_12, 0) << "ip mode active";
}

}  // namespace
}  // namespace settle::hal::canopen
