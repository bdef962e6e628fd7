// SPDX-License-Identifier: Apache-2.0
// The drive's safety rules against the faults a hostile or broken peer produces (issue 12,
// items 6-9), frame by frame on a virtual clock: enabling with a far target, steps beyond
// 0x607F, SDO writes of 0x607A, duplicated and foreign SYNCs, a third party's NMT commands.
// Each test checks the EMCY (code, register, cause byte), the CiA 402 state reached and that the
// axis never moved further than the step limit allows.
#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/drive_node.hpp"

namespace settle::hal::canopen {
namespace {

constexpr NodeId node = 5;
constexpr std::uint64_t period_us = 1000;

class DriveSafety : public ::testing::Test {
 protected:
  DriveSafety() { drive.emplace(config()); }

  static DriveNodeConfig config() {
    DriveNodeConfig c{};
    c.node = node;
    c.heartbeat_period_ms = 0;  // no heartbeats: every frame the drive sends is one under test
    return c;
  }

  // One frame from the bus, received at `at` (default: now). A SYNC that runs a period moves
  // the ideal axis to the setpoint (or holds it, or completes a stop) and publishes.
  DriveEvent deliver(CanFrame f, std::optional<std::uint64_t> at = std::nullopt) {
    f.timestamp_us = at.value_or(now);
    const DriveEvent e = drive->on_frame(f, now, out);
    if (e == DriveEvent::sync) {
      ++periods_run;
      if (drive->stopping()) {
        drive->stop_complete();
      } else if (drive->following()) {
        const std::int64_t step = std::int64_t{drive->setpoint()} - std::int64_t{axis};
        largest_step = std::max(largest_step, step < 0 ? -step : step);
        axis = drive->setpoint();
      }
      drive->publish(DriveFeedback{axis, 0, axis}, now, out);
    }
    collect();
    return e;
  }

  // A servo period as a master runs it: RPDO (controlword, target), then SYNC.
  DriveEvent period(std::uint16_t cw, std::int32_t target, std::uint8_t counter = 0) {
    now += period_us;
    (void)deliver(encode_rpdo1(node, Rpdo1{cw, target}));
    const DriveEvent e = deliver(encode_sync(counter));
    drive->poll(now, out);
    collect();
    return e;
  }

  void collect() {
    for (const CanFrame& f : out.frames()) {
      sent.push_back(f);
    }
    out.clear();
  }

  // NMT start and the enable sequence, every RPDO carrying the position the axis is at.
  void enable(std::uint8_t counter_overflow = 0) {
    (void)deliver(encode_nmt(NmtCommand::start, node));
    ASSERT_EQ(drive->nmt_state(), NmtState::operational);
    for (const std::uint16_t cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
      (void)period(cw, axis, next_counter(counter_overflow));
    }
    ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
    ASSERT_TRUE(emcys().empty());
  }

  std::uint8_t next_counter(std::uint8_t overflow) {
    if (overflow == 0) {
      return 0;
    }
    last_counter = last_counter >= overflow ? 1 : static_cast<std::uint8_t>(last_counter + 1);
    return last_counter;
  }

  SdoAbort sdo_write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size) {
    (void)deliver(encode_sdo_download_request(node, index, sub, value, size));
    for (auto it = sent.rbegin(); it != sent.rend(); ++it) {
      if (const auto r = decode_sdo_response(*it, node)) {
        return r->kind == SdoKind::abort ? static_cast<SdoAbort>(r->abort_code) : SdoAbort::none;
      }
    }
    return SdoAbort::general_error;
  }

  // 0x1019 is written while 0x1006 is 0 (CiA 301): 0x1006 = 0, 0x1019, 0x1006 back. The abort of
  // the 0x1019 write.
  SdoAbort write_sync_counter_overflow(std::uint32_t value) {
    const std::uint32_t cycle = drive->objects().comm.cycle_period_us;
    (void)sdo_write(obj::communication_cycle_period, 0, 0, 4);
    const SdoAbort abort = sdo_write(obj::sync_counter_overflow, 0, value, 1);
    (void)sdo_write(obj::communication_cycle_period, 0, cycle, 4);
    return abort;
  }

  // An enabled drive with an RPDO latched is sent `sync`, one that does not match 0x1019: no period
  // runs for it (the axis stays), one EMCY 0x8240 with the cause and detail, and the fault reaction.
  void expect_sync_refused_while_enabled(const CanFrame& sync, std::uint8_t cause, std::uint8_t detail) {
    now += period_us;
    (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 10}));
    EXPECT_EQ(deliver(sync), DriveEvent::sync_rejected) << "no period is run for it";
    EXPECT_EQ(axis, 0);
    const auto e = emcys();
    ASSERT_EQ(e.size(), 1U);
    EXPECT_EQ(e[0].error_code, emcy_code::sync_data_length);
    EXPECT_EQ(e[0].data[0], cause);
    EXPECT_EQ(e[0].data[1], detail);
    EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active);
  }

  std::vector<EmcyMessage> emcys() const {
    std::vector<EmcyMessage> v;
    for (const CanFrame& f : sent) {
      if (const auto e = decode_emcy(f); e && e->node == node) {
        v.push_back(e->message);
      }
    }
    return v;
  }

  std::size_t tpdos_sent() const {
    std::size_t n = 0;
    for (const CanFrame& f : sent) {
      n += f.id == cob_id(cob::tpdo1, node) ? 1U : 0U;
    }
    return n;
  }

  std::optional<DriveNode> drive;
  FrameBuffer<16> out;
  std::vector<CanFrame> sent;
  std::uint64_t now{0};
  std::int32_t axis{0};
  std::int64_t largest_step{0};
  std::uint64_t periods_run{0};
  std::uint8_t last_counter{0};  // the master's SYNC counter, when 0x1019 is set
};

// The cause byte and its 32-bit detail, as the drive puts them in the EMCY.
std::int32_t emcy_value(const EmcyMessage& m) {
  return static_cast<std::int32_t>(std::uint32_t{m.data[1]} | (std::uint32_t{m.data[2]} << 8U) |
                                   (std::uint32_t{m.data[3]} << 16U) | (std::uint32_t{m.data[4]} << 24U));
}

// --- Item 6: enabling never moves the axis ---------------------------------------------------

TEST_F(DriveSafety, TheEnablingRpdoWithAFarTargetLeavesTheAxisWhereItIs) {
  (void)deliver(encode_nmt(NmtCommand::start, node));
  (void)period(controlword::shutdown, 0);
  (void)period(controlword::switch_on, 0);
  // The frame: enable operation and a target a million counts away, in one RPDO.
  EXPECT_EQ(period(controlword::enable_operation, 1'000'000), DriveEvent::sync);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_EQ(axis, 0) << "enabling latched the target to the position actual";
  EXPECT_EQ(drive->objects().app.target_position, 0) << "0x607A reads the latched position";
  EXPECT_TRUE(emcys().empty());

  // The first setpoint after enabling is checked against the latched position: the same far
  // target again is a step of 1e6 counts in one period, 100 times the step limit.
  EXPECT_EQ(period(controlword::enable_operation, 1'000'000), DriveEvent::sync);
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(axis, 0);
  EXPECT_EQ(largest_step, 0) << "the axis never moved";
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].error_code, emcy_code::velocity);
  EXPECT_EQ(e[0].error_register, error_register::generic | error_register::device_profile);
  EXPECT_EQ(e[0].data[0], emcy_cause::step_limit);
  EXPECT_EQ(emcy_value(e[0]), 1'000'000) << "the refused step";
  EXPECT_EQ(drive->objects().app.error_code, emcy_code::velocity);
  EXPECT_EQ(drive->counters().steps_refused, 1U);
}

TEST_F(DriveSafety, EnablingLatchesThePositionTheAxisIsAtNotZero) {
  // An axis powered on away from zero: the drive reports it before it is enabled.
  axis = -70'000;
  (void)deliver(encode_nmt(NmtCommand::start, node));
  (void)period(controlword::shutdown, 0);
  (void)period(controlword::switch_on, 0);
  (void)period(controlword::enable_operation, 0);  // a stale target of 0, 70 000 counts away
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_EQ(axis, -70'000);
  EXPECT_EQ(drive->setpoint(), -70'000);
  // From there the master's stream is applied, step by step.
  for (std::int32_t k = 1; k <= 10; ++k) {
    (void)period(controlword::enable_operation, -70'000 + 1000 * k);
    ASSERT_EQ(axis, -70'000 + 1000 * k);
  }
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_TRUE(emcys().empty());
}

// --- Item 7: the step limit ---------------------------------------------------------------

TEST_F(DriveSafety, StepsOfTwoBillionCountsAreNeverAppliedAndFaultTheDrive) {
  enable();
  for (const std::int32_t target : {2'000'000'000, -2'000'000'000}) {
    SCOPED_TRACE(target);
    sent.clear();
    (void)period(controlword::enable_operation, target);
    EXPECT_EQ(drive->state(), Cia402State::fault);
    EXPECT_EQ(axis, 0);
    const auto e = emcys();
    ASSERT_EQ(e.size(), 1U);
    EXPECT_EQ(e[0].error_code, emcy_code::velocity);
    EXPECT_EQ(emcy_value(e[0]), target);
    // Recovery: fault reset (rising bit 7), then the enable sequence again.
    (void)period(controlword::fault_reset, 0);
    EXPECT_EQ(drive->state(), Cia402State::switch_on_disabled);
    for (const std::uint16_t cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
      (void)period(cw, target);  // the far target rides along: still never applied
    }
    EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
    EXPECT_EQ(axis, 0);
  }
  // Alternating +-2e9 per period, as the issue streamed them: the first is refused and faults,
  // the drive follows nothing after it.
  for (int k = 0; k < 20; ++k) {
    (void)period(controlword::enable_operation, k % 2 == 0 ? 2'000'000'000 : -2'000'000'000);
  }
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(largest_step, 0);
  EXPECT_EQ(axis, 0);
}

TEST_F(DriveSafety, TheStepLimitIsMaxProfileVelocityTimesThePeriod) {
  enable();
  // Defaults: 0x607F = 1e7 counts/s, 0x60C2 = 0x1006 = 1 ms: 10 000 counts per SYNC.
  EXPECT_EQ(drive->objects().app.max_profile_velocity, 10'000'000U);
  EXPECT_EQ(drive->step_limit_counts(), 10'000);
  (void)period(controlword::enable_operation, 10'000);
  (void)period(controlword::enable_operation, 0);
  EXPECT_EQ(axis, 0);
  EXPECT_EQ(largest_step, 10'000) << "a step at the limit is applied";
  (void)period(controlword::enable_operation, -10'001);
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(axis, 0) << "one count over it is not";
}

TEST_F(DriveSafety, TheStepLimitFollowsTheConfiguredObjects) {
  EXPECT_EQ(sdo_write(obj::max_profile_velocity, 0, 0, 4), SdoAbort::value_too_low) << "0 would forbid all motion";
  EXPECT_EQ(sdo_write(obj::max_profile_velocity, 0, 2'500'000, 4), SdoAbort::none);
  EXPECT_EQ(drive->step_limit_counts(), 2'500);
  // The shorter of 0x1006 and 0x60C2 sets it: a 2 ms cycle with a 1 ms interpolation period
  // still allows one millisecond's worth.
  EXPECT_EQ(sdo_write(obj::communication_cycle_period, 0, 2'000, 4), SdoAbort::none);
  EXPECT_EQ(drive->step_limit_counts(), 2'500);
  EXPECT_EQ(sdo_write(obj::interpolation_time_period, 1, 2, 1), SdoAbort::none);
  EXPECT_EQ(drive->step_limit_counts(), 5'000);
  // Rounded up: 7 counts/s over 2 ms is 0.014 counts, a step of 1 is allowed.
  EXPECT_EQ(sdo_write(obj::max_profile_velocity, 0, 7, 4), SdoAbort::none);
  EXPECT_EQ(drive->step_limit_counts(), 1);
  // The largest product does not overflow: 0xFFFFFFFF counts/s over 255 s.
  EXPECT_EQ(sdo_write(obj::max_profile_velocity, 0, 0xFFFF'FFFFU, 4), SdoAbort::none);
  EXPECT_EQ(sdo_write(obj::communication_cycle_period, 0, 0, 4), SdoAbort::none);
  EXPECT_EQ(sdo_write(obj::interpolation_time_period, 1, 255, 1), SdoAbort::none);
  EXPECT_EQ(sdo_write(obj::interpolation_time_period, 2, 0, 1), SdoAbort::none);
  EXPECT_EQ(drive->step_limit_counts(), std::int64_t{0xFFFF'FFFF} * 255);
}

TEST_F(DriveSafety, AnSdoWriteOfTheTargetWhileEnabledIsCheckedLikeAnRpdo) {
  enable();
  // Within the limit: applied at the next SYNC, as CSP applies 0x607A.
  EXPECT_EQ(sdo_write(obj::target_position, 0, 4'000, 4), SdoAbort::none);
  now += period_us;
  EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);
  EXPECT_EQ(axis, 4'000);
  // Beyond it: the write itself succeeds (the object holds what was written), the SYNC that
  // would apply it refuses the step and faults the drive.
  EXPECT_EQ(sdo_write(obj::target_position, 0, static_cast<std::uint32_t>(2'000'000'000), 4), SdoAbort::none);
  now += period_us;
  EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(axis, 4'000);
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].error_code, emcy_code::velocity);
  EXPECT_EQ(emcy_value(e[0]), 2'000'000'000 - 4'000);
}

TEST_F(DriveSafety, StepsAreMeasuredTheShortWayRoundTheCountersWrap) {
  axis = std::numeric_limits<std::int32_t>::max() - 5;
  enable();
  // Across the wrap: 11 counts, applied.
  (void)period(controlword::enable_operation, std::numeric_limits<std::int32_t>::min() + 5);
  EXPECT_EQ(axis, std::numeric_limits<std::int32_t>::min() + 5);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  // Half the counter away (the largest step there is, whose magnitude overflows int32): refused.
  (void)period(controlword::enable_operation, 5);
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(axis, std::numeric_limits<std::int32_t>::min() + 5);
  EXPECT_EQ(emcy_value(emcys().at(0)), std::numeric_limits<std::int32_t>::min());
}

TEST_F(DriveSafety, TheFollowingErrorCheckIsOnByDefault) {
  EXPECT_EQ(drive->objects().app.following_error_window, default_following_error_window);
  EXPECT_EQ(drive->objects().app.following_error_timeout_ms, default_following_error_timeout_ms);
  enable();
  // The axis stops following (a seized motor): the drive reports it where it stands while the
  // setpoints run away at 9 000 counts per period.
  std::int32_t target = 0;
  int faulted_at = 0;
  for (int k = 1; k <= 40 && faulted_at == 0; ++k) {
    target += 9'000;
    now += period_us;
    (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, target}));
    CanFrame sync = encode_sync();
    sync.timestamp_us = now;
    if (drive->on_frame(sync, now, out) == DriveEvent::sync) {
      if (drive->stopping()) {
        drive->stop_complete();
      }
      drive->publish(DriveFeedback{0, 0, 0}, now, out);  // position actual stays 0
    }
    collect();
    if (drive->state() != Cia402State::operation_enabled) {
      faulted_at = k;
    }
  }
  // The error passes 100 000 counts at period 12 (108 000) and stays there for 10 ms.
  EXPECT_EQ(faulted_at, 12 + 10);
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].error_code, emcy_code::following_error);
  EXPECT_EQ(e[0].data[0], emcy_cause::following_error);
  EXPECT_EQ(emcy_value(e[0]), 22 * 9'000);
}

// --- Item 8: duplicated SYNC, a second SYNC producer --------------------------------------

TEST_F(DriveSafety, ADuplicatedSyncIsRefusedAtOnceWhenTheCounterIsOn) {
  EXPECT_EQ(write_sync_counter_overflow(16), SdoAbort::none);
  enable(16);
  (void)period(controlword::enable_operation, 100, next_counter(16));
  EXPECT_EQ(axis, 100);
  const std::uint64_t periods = periods_run;
  // The same SYNC twice (a duplicating bus, or a second producer in step with the first).
  now += period_us;
  (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 200}));
  const std::uint8_t c = next_counter(16);
  EXPECT_EQ(deliver(encode_sync(c)), DriveEvent::sync);
  EXPECT_EQ(deliver(encode_sync(c)), DriveEvent::sync_rejected);
  EXPECT_EQ(periods_run, periods + 1) << "the plant advanced one period, not two";
  EXPECT_EQ(axis, 200);
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active) << "0x6007 = 1: fault";
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].error_code, emcy_code::communication);
  EXPECT_EQ(e[0].error_register, error_register::generic | error_register::communication);
  EXPECT_EQ(e[0].data[0], emcy_cause::sync_counter);
  EXPECT_EQ(e[0].data[1], c);
  EXPECT_EQ(drive->counters().sync_errors, 1U);
  // The fault reaction runs on the next good SYNC; the axis stays.
  (void)period(controlword::enable_operation, 300, next_counter(16));
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(axis, 200);
}

TEST_F(DriveSafety, ASecondProducersCountersAreOutOfSequence) {
  EXPECT_EQ(write_sync_counter_overflow(240), SdoAbort::none);
  enable(240);
  // Another producer's SYNC, with its own counter, between the master's RPDO and SYNC: refused;
  // the latched RPDO waits for the master's SYNC, which the fault reaction then runs.
  now += period_us;
  (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 50}));
  EXPECT_EQ(deliver(encode_sync(200)), DriveEvent::sync_rejected);
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active);
  EXPECT_EQ(emcys().at(0).data[0], emcy_cause::sync_counter);
  EXPECT_EQ(axis, 0);
}

TEST_F(DriveSafety, ACounterAboveTheConfiguredOverflowDoesNotMatch0x1019) {
  EXPECT_EQ(write_sync_counter_overflow(8), SdoAbort::none);
  enable(8);
  expect_sync_refused_while_enabled(encode_sync(9), emcy_cause::sync_counter, 9);
}

TEST_F(DriveSafety, ASyncWithoutTheConfiguredCounterIsAnUnexpectedLength) {
  EXPECT_EQ(write_sync_counter_overflow(8), SdoAbort::none);
  enable(8);
  EXPECT_EQ(period(controlword::enable_operation, 10, 0), DriveEvent::sync_rejected);
  EXPECT_EQ(axis, 0);
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].error_code, emcy_code::sync_data_length);
  EXPECT_EQ(e[0].data[0], emcy_cause::sync_length);
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active);
}

TEST_F(DriveSafety, TheSyncCounterOverflowIsSetBeforeEnablingAndOnlyToValidValues) {
  EXPECT_EQ(write_sync_counter_overflow(1), SdoAbort::invalid_value);
  EXPECT_EQ(write_sync_counter_overflow(241), SdoAbort::value_too_high);
  EXPECT_EQ(drive->objects().comm.sync_counter_overflow, 0);
  EXPECT_EQ(write_sync_counter_overflow(2), SdoAbort::none);
  enable(2);
  EXPECT_EQ(write_sync_counter_overflow(0), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(drive->objects().comm.sync_counter_overflow, 2);
  // The counter wraps 1, 2, 1, 2, ...: in order.
  for (int k = 0; k < 10; ++k) {
    ASSERT_EQ(period(controlword::enable_operation, k, next_counter(2)), DriveEvent::sync) << k;
  }
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_EQ(drive->counters().sync_errors, 0U);
}

TEST_F(DriveSafety, DuplicatedSyncsWithoutACounterAreCaughtByTheirRate) {
  enable();
  const std::uint64_t periods = periods_run;
  // Every SYNC arrives twice. Without a counter the drive cannot tell the copy from a SYNC that
  // is late: it tolerates 0x2001 (3) SYNCs in excess of one per period, then refuses.
  int first_refused = 0;
  for (int k = 1; k <= 10 && first_refused == 0; ++k) {
    now += period_us;
    (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 10 * k}));
    EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync) << k;
    if (deliver(encode_sync()) == DriveEvent::sync_rejected) {
      first_refused = k;
    }
  }
  EXPECT_EQ(first_refused, 4);
  EXPECT_EQ(periods_run - periods, 4U + 3U) << "four genuine periods, three copies before the fourth was refused";
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active);
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].error_code, emcy_code::communication);
  EXPECT_EQ(e[0].data[0], emcy_cause::sync_rate);
  EXPECT_LE(largest_step, 10) << "the copies ran no new setpoint: the axis held";
}

TEST_F(DriveSafety, ASecondProducerHalfAPeriodOutOfPhaseIsCaughtByTheRate) {
  enable();
  int first_refused = 0;
  for (int k = 1; k <= 20 && first_refused == 0; ++k) {
    (void)period(controlword::enable_operation, 0);
    if (deliver(encode_sync(), now + period_us / 2) == DriveEvent::sync_rejected) {
      first_refused = k;
    }
  }
  EXPECT_GT(first_refused, 0);
  EXPECT_LE(first_refused, 5) << "within (0x2001 + 1) / (1 - 1/8) periods";
  EXPECT_EQ(emcys().at(0).data[0], emcy_cause::sync_rate);
  EXPECT_NE(drive->state(), Cia402State::operation_enabled);
}

TEST_F(DriveSafety, AForeignSyncThatTakesTheMastersRpdoGetsTheMastersSyncRefused) {
  enable();
  // The foreign SYNC arrives between the master's RPDO and SYNC: it applies the master's
  // setpoint (one period early, within the step limit) and leaves the master's SYNC without an
  // RPDO, and that SYNC is the extra one.
  int first_refused = 0;
  for (std::int32_t k = 1; k <= 20 && first_refused == 0; ++k) {
    now += period_us;
    (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 10 * k}));
    (void)deliver(encode_sync(), now - period_us / 3);
    if (deliver(encode_sync()) == DriveEvent::sync_rejected) {
      first_refused = k;
    }
  }
  EXPECT_GT(first_refused, 0);
  EXPECT_LE(first_refused, 5);
  EXPECT_EQ(emcys().at(0).data[0], emcy_cause::sync_rate);
  EXPECT_LE(largest_step, 10);
}

TEST_F(DriveSafety, AMasterCatchingUpWithItsOwnRpdosIsNotRefused) {
  // A replay (canplayer) that fell behind sends the periods it owes in one burst, each SYNC
  // with its RPDO: the SYNCs come far faster than 0x1006 allows, but every one brings the
  // master's next setpoint. Applied in order, step by step, no error; and the step window keeps
  // the burst from moving the axis more than one step limit (10 000 counts) in its period.
  enable();
  const std::int64_t limit = drive->step_limit_counts();
  ASSERT_EQ(limit, 10'000);
  for (std::int32_t k = 1; k <= 300; ++k) {
    (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 100 * k}));
    ASSERT_EQ(deliver(encode_sync()), DriveEvent::sync) << k;  // all at the same instant
    ASSERT_EQ(axis, std::min<std::int32_t>(100 * k, 10'000)) << k;
  }
  EXPECT_EQ(largest_step, 100);
  EXPECT_EQ(drive->counters().steps_bounded, 200U);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_TRUE(emcys().empty());
  // Right after it, with no credit left, a SYNC without an RPDO of its own is an extra one.
  EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync_rejected);
  EXPECT_EQ(emcys().at(0).data[0], emcy_cause::sync_rate);
}

TEST_F(DriveSafety, TwoPairsInOnePeriodMoveTheAxisOneStepAndItCatchesUp) {
  // The fuzz harness's item08 inputs: a delayed bus delivers two of the master's SYNC+RPDO pairs
  // within one period, each step within the limit. The axis moves one limit in that period
  // (not two), keeps following, and reaches the master's targets at the next SYNCs.
  enable();
  const auto limit = static_cast<std::int32_t>(drive->step_limit_counts());
  (void)period(controlword::enable_operation, limit);
  ASSERT_EQ(axis, limit);
  now += 2 * period_us;  // a period late, then both at once
  for (const std::int32_t target : {2 * limit, 3 * limit}) {
    (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, target}));
    ASSERT_EQ(deliver(encode_sync()), DriveEvent::sync);
  }
  EXPECT_EQ(axis, 2 * limit);
  EXPECT_EQ(drive->counters().steps_bounded, 1U);
  (void)period(controlword::enable_operation, 4 * limit);
  EXPECT_EQ(axis, 3 * limit);
  (void)period(controlword::enable_operation, 4 * limit);
  EXPECT_EQ(axis, 4 * limit);
  EXPECT_EQ(largest_step, limit);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_TRUE(emcys().empty());
}

TEST_F(DriveSafety, AnAxisSimulatedInSyncTimeFollowsABurstStepByStep) {
  // settle plant's axis advances one period per SYNC: a replay's burst of 300 pairs at one
  // instant is 300 periods of its time, every setpoint applied as sent (each within the step
  // limit); the same burst on a drive in processing time is held to one limit (see above).
  DriveNodeConfig c = config();
  c.axis_moves_one_period_per_sync = true;
  drive.emplace(c);
  enable();
  for (std::int32_t k = 1; k <= 300; ++k) {
    (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 100 * k}));
    ASSERT_EQ(deliver(encode_sync()), DriveEvent::sync) << k;  // all at the same instant
    ASSERT_EQ(axis, 100 * k) << k;
  }
  EXPECT_EQ(drive->counters().steps_bounded, 0U);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_TRUE(emcys().empty());
}

TEST_F(DriveSafety, ALateMasterIsNoSecondProducer) {
  // The master's SYNCs leave anywhere up to a whole period late (a loaded host), and the
  // receiving process reads them in bursts; the frames' receive times say when they were sent.
  // Late-then-on-time is never an error, and neither is a reader that stalls.
  enable();
  std::mt19937 rng{12};
  std::uniform_int_distribution<std::uint64_t> late{0, period_us - 1};
  const std::uint64_t t0 = now;
  std::vector<CanFrame> pending;
  for (std::int32_t k = 1; k <= 20'000; ++k) {
    const std::uint64_t sent_at = t0 + static_cast<std::uint64_t>(k) * period_us + late(rng);
    CanFrame rpdo = encode_rpdo1(node, Rpdo1{controlword::enable_operation, k});
    CanFrame sync = encode_sync();
    rpdo.timestamp_us = sent_at;
    sync.timestamp_us = sent_at;
    pending.push_back(rpdo);
    pending.push_back(sync);
    if (k % 7 == 0) {  // the reader wakes every 7 ms and reads what queued up
      now = sent_at;
      for (const CanFrame& f : pending) {
        ASSERT_NE(deliver(f, f.timestamp_us), DriveEvent::sync_rejected) << k;
      }
      pending.clear();
      drive->poll(now, out);
      collect();
    }
  }
  EXPECT_EQ(drive->counters().sync_errors, 0U);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_TRUE(emcys().empty());
  EXPECT_EQ(largest_step, 1);
}

TEST_F(DriveSafety, SyncBurstsWhileDisabledAreCountedNotActedOn) {
  (void)deliver(encode_nmt(NmtCommand::start, node));
  for (int k = 0; k < 20; ++k) {
    EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);  // all at the same instant
  }
  EXPECT_GT(drive->counters().sync_errors, 0U);
  EXPECT_TRUE(emcys().empty());
  // Enabling starts the check afresh: the stream that follows is clean.
  enable();
  for (std::int32_t k = 1; k <= 10; ++k) {
    ASSERT_EQ(period(controlword::enable_operation, k), DriveEvent::sync);
  }
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
}

// --- Item 9: a third party's NMT command while enabled --------------------------------------

TEST_F(DriveSafety, AThirdPartysNmtPreOperationalFaultsTheDriveWithAnEmcy) {
  enable();
  (void)period(controlword::enable_operation, 500);
  const std::size_t tpdos = tpdos_sent();
  sent.clear();
  EXPECT_EQ(deliver(encode_nmt(NmtCommand::enter_pre_operational, node)), DriveEvent::handled);
  EXPECT_EQ(drive->nmt_state(), NmtState::pre_operational);
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active) << "0x6007 = 1 (the EDS default): fault";
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].error_code, emcy_code::communication);
  EXPECT_EQ(e[0].error_register, error_register::generic | error_register::communication);
  EXPECT_EQ(e[0].data[0], emcy_cause::nmt_command);
  EXPECT_EQ(e[0].data[1], static_cast<std::uint8_t>(NmtCommand::enter_pre_operational));
  // SYNC still runs periods in pre-operational: the fault reaction completes, the axis holds;
  // RPDOs are not taken and no TPDO is sent.
  EXPECT_EQ(period(controlword::enable_operation, 9'000), DriveEvent::sync);
  EXPECT_EQ(drive->state(), Cia402State::fault);
  EXPECT_EQ(axis, 500);
  EXPECT_EQ(tpdos_sent(), 0U);
  EXPECT_GT(tpdos, 0U);
}

TEST_F(DriveSafety, AThirdPartysNmtStopSendsTheEmcyBeforeTheNodeFallsSilent) {
  enable();
  sent.clear();
  EXPECT_EQ(deliver(encode_nmt(NmtCommand::stop, 0)), DriveEvent::handled);  // broadcast
  EXPECT_EQ(drive->nmt_state(), NmtState::stopped);
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active);
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].error_code, emcy_code::communication);
  EXPECT_EQ(e[0].data[1], static_cast<std::uint8_t>(NmtCommand::stop));
  EXPECT_EQ(axis, 0);
}

TEST_F(DriveSafety, AResetOfCommunicationWhileEnabledFaultsAndKeepsTheErrorRegister) {
  enable();
  sent.clear();
  EXPECT_EQ(deliver(encode_nmt(NmtCommand::reset_communication, node)), DriveEvent::handled);
  EXPECT_EQ(drive->nmt_state(), NmtState::pre_operational);
  EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active);
  ASSERT_EQ(emcys().size(), 1U);
  EXPECT_EQ(emcys()[0].data[1], static_cast<std::uint8_t>(NmtCommand::reset_communication));
  EXPECT_NE(drive->objects().comm.error_register, 0) << "the drive is still in fault";
}

TEST_F(DriveSafety, TheNmtReactionFollowsTheAbortConnectionOption) {
  struct Case {
    std::int16_t option;
    Cia402State after;
  };
  for (const Case c : {Case{0, Cia402State::switch_on_disabled}, Case{1, Cia402State::fault_reaction_active},
                       Case{2, Cia402State::switch_on_disabled}, Case{3, Cia402State::quick_stop_active}}) {
    SCOPED_TRACE(c.option);
    drive.emplace(config());
    sent.clear();
    EXPECT_EQ(sdo_write(obj::abort_connection_option, 0, static_cast<std::uint32_t>(c.option), 2), SdoAbort::none);
    enable();
    (void)deliver(encode_nmt(NmtCommand::enter_pre_operational, node));
    EXPECT_EQ(drive->state(), c.after);
    const auto e = emcys();
    ASSERT_EQ(e.size(), 1U) << "an EMCY whatever the reaction";
    EXPECT_EQ(e[0].error_code, emcy_code::communication);
  }
}

TEST_F(DriveSafety, NmtCommandsThatChangeNothingOrComeWhileDisabledNeedNoReaction) {
  (void)deliver(encode_nmt(NmtCommand::start, node));
  (void)deliver(encode_nmt(NmtCommand::enter_pre_operational, node));  // not enabled: no reaction
  EXPECT_TRUE(emcys().empty());
  enable();
  (void)deliver(encode_nmt(NmtCommand::start, node));         // already operational
  (void)deliver(encode_nmt(NmtCommand::stop, node + 1));      // another node
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_TRUE(emcys().empty());
}

// CiA 301 PDO length rules as common stacks apply them (CANopenNode, Lely): a frame shorter than
// the mapping is not processed (0x8210) and must not displace the good RPDO of its period; a
// longer one is processed from its mapped bytes (0x8220). Either way 0x1001/0x603F report the
// error while the drive runs on, and the next RPDO of the right length clears them (EMCY 0000).
TEST_F(DriveSafety, AShortRpdoNeverReplacesTheGoodOneOfItsPeriod) {
  enable();
  now += period_us;
  (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 500}));
  CanFrame shorter = encode_rpdo1(node, Rpdo1{controlword::enable_operation, 9000});
  shorter.len = 5;
  (void)deliver(shorter);
  EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);
  EXPECT_EQ(axis, 500) << "the good RPDO of the period was applied";
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].error_code, emcy_code::pdo_length);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
}

TEST_F(DriveSafety, ALongerRpdoIsAppliedFromItsMappedBytesAndReported) {
  enable();
  now += period_us;
  CanFrame longer = encode_rpdo1(node, Rpdo1{controlword::enable_operation, 700});
  longer.len = 8;
  longer.data[6] = 0xAA;
  longer.data[7] = 0x55;
  (void)deliver(longer);
  EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);
  EXPECT_EQ(axis, 700);
  const auto e = emcys();
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].error_code, emcy_code::pdo_length_exceeded);
  EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
}

TEST_F(DriveSafety, TheLengthErrorIsClearedWithEmcyZeroOnceRpdosAreRightAgain) {
  enable();
  for (const std::uint8_t len : {std::uint8_t{5}, std::uint8_t{8}}) {
    sent.clear();
    now += period_us;
    CanFrame bad = encode_rpdo1(node, Rpdo1{controlword::enable_operation, axis + 10});
    bad.len = len;
    (void)deliver(bad);
    (void)deliver(encode_sync());
    drive->poll(now, out);
    collect();
    // Set while the drive runs on: the error register and 0x603F say what happened.
    EXPECT_EQ(drive->objects().comm.error_register, error_register::generic | error_register::communication) << int{len};
    EXPECT_EQ(drive->objects().app.error_code, len < 6 ? emcy_code::pdo_length : emcy_code::pdo_length_exceeded);
    EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
    // Still set after a period without any RPDO (the condition is not known to be gone).
    now += period_us;
    (void)deliver(encode_sync());
    EXPECT_NE(drive->objects().comm.error_register, 0) << int{len};
    // A good RPDO: cleared, and the master is told with EMCY 0000.
    (void)period(controlword::enable_operation, axis + 20);
    EXPECT_EQ(drive->objects().comm.error_register, 0) << int{len};
    EXPECT_EQ(drive->objects().app.error_code, 0) << int{len};
    const auto e = emcys();
    ASSERT_EQ(e.size(), 2u) << int{len};
    EXPECT_EQ(e[1].error_code, emcy_code::no_error);
    EXPECT_EQ(e[1].error_register, 0);
  }
}

TEST_F(DriveSafety, AGoodRpdoDoesNotClearAFaultThatFollowedALengthError) {
  enable();
  now += period_us;
  CanFrame bad = encode_rpdo1(node, Rpdo1{controlword::enable_operation, axis});
  bad.len = 8;
  (void)deliver(bad);
  (void)deliver(encode_sync());
  // Then a step far beyond 0x607F x period: the drive faults (0x8400).
  (void)period(controlword::enable_operation, axis + 5'000'000);
  ASSERT_EQ(drive->objects().app.error_code, emcy_code::velocity);
  (void)period(controlword::enable_operation, axis);
  EXPECT_EQ(drive->objects().app.error_code, emcy_code::velocity) << "only a fault reset clears a fault";
  EXPECT_NE(drive->objects().comm.error_register, 0);
}

// --- Issue 34, item 1: the position actual is the machine's ------------------------------------
// A machine standing at 500 000 counts when the drive powers on or its node is reset: enabling
// by SDO or by RPDO, before or after the first SYNC, latches 500 000, and no SYNC that follows
// commands the axis anywhere else.

constexpr std::int32_t far_from_zero = 500'000;

class DrivePositionActual : public DriveSafety {
 protected:
  void enable_by_sdo(std::initializer_list<std::uint16_t> cws = {controlword::shutdown, controlword::switch_on,
                                                                   controlword::enable_operation}) {
    for (const std::uint16_t cw : cws) {
      ASSERT_EQ(sdo_write(obj::controlword, 0, cw, 2), SdoAbort::none) << cw;
    }
  }

  // The drive knows the machine's position (published at a SYNC), then its node is reset.
  void reset_node_at_far_position() {
    axis = far_from_zero;
    (void)deliver(encode_nmt(NmtCommand::start, node));
    (void)period(controlword::disable_voltage, axis);
    ASSERT_EQ(drive->objects().app.position_actual, far_from_zero);
    ASSERT_EQ(deliver(encode_nmt(NmtCommand::reset_node, node)), DriveEvent::reset);
    sent.clear();
  }

  // A SYNC without an RPDO (the target the drive latched stands), then a stream from where the
  // axis is: the axis never steps further than the stream does.
  void expect_no_jump() {
    now += period_us;
    EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);
    EXPECT_EQ(axis, far_from_zero) << "the first SYNC after enabling moved the axis";
    EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
    for (std::int32_t k = 1; k <= 5; ++k) {
      (void)period(controlword::enable_operation, far_from_zero + 100 * k);
      ASSERT_EQ(axis, far_from_zero + 100 * k);
    }
    EXPECT_LE(largest_step, 100) << "the commanded position jumped";
    EXPECT_EQ(drive->state(), Cia402State::operation_enabled);
    EXPECT_TRUE(emcys().empty());
  }
};

TEST_F(DrivePositionActual, ResetNodeKeepsThePositionActual) {
  reset_node_at_far_position();
  EXPECT_EQ(drive->objects().app.position_actual, far_from_zero) << "0x6064 is the machine's, not a default";
  EXPECT_EQ(drive->setpoint(), far_from_zero);
}

TEST_F(DrivePositionActual, EnablingBySdoBeforeTheFirstSyncAfterResetNodeLatchesTheMachinesPosition) {
  reset_node_at_far_position();
  (void)deliver(encode_nmt(NmtCommand::start, node));
  enable_by_sdo();
  ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_EQ(drive->objects().app.target_position, far_from_zero);
  EXPECT_EQ(drive->setpoint(), far_from_zero);
  expect_no_jump();
}

TEST_F(DrivePositionActual, EnablingByRpdoAtTheFirstSyncAfterResetNodeLatchesTheMachinesPosition) {
  reset_node_at_far_position();
  (void)deliver(encode_nmt(NmtCommand::start, node));
  enable_by_sdo({controlword::shutdown, controlword::switch_on});
  // The enabling RPDO carries a stale target of 0; it is applied at the first SYNC.
  now += period_us;
  (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 0}));
  EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);
  EXPECT_EQ(axis, far_from_zero);
  expect_no_jump();
}

TEST_F(DrivePositionActual, EnablingBySdoBeforeTheFirstSyncAfterPowerOnHoldsUntilTheAxisReports) {
  axis = far_from_zero;  // powered on there; the drive has not been told
  (void)deliver(encode_nmt(NmtCommand::start, node));
  enable_by_sdo();
  ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_FALSE(drive->following()) << "where the axis is is not known yet: hold";
  expect_no_jump();
  EXPECT_EQ(drive->objects().app.target_position, far_from_zero + 500);
}

TEST_F(DrivePositionActual, EnablingByRpdoAtTheFirstSyncAfterPowerOnHoldsUntilTheAxisReports) {
  axis = far_from_zero;
  (void)deliver(encode_nmt(NmtCommand::start, node));
  enable_by_sdo({controlword::shutdown});
  now += period_us;
  (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 0}));  // switch on + enable
  EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);
  ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
  EXPECT_EQ(axis, far_from_zero);
  EXPECT_EQ(drive->setpoint(), far_from_zero) << "latched at the publish of that SYNC";
  expect_no_jump();
}

TEST_F(DrivePositionActual, EnablingAfterTheFirstSyncLatchesThePublishedPosition) {
  for (const bool by_sdo : {true, false}) {
    SCOPED_TRACE(by_sdo);
    drive.emplace(config());
    sent.clear();
    largest_step = 0;
    axis = far_from_zero;
    (void)deliver(encode_nmt(NmtCommand::start, node));
    now += period_us;
    (void)deliver(encode_sync());
    if (by_sdo) {
      enable_by_sdo();
    } else {
      for (const std::uint16_t cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
        (void)period(cw, 0);
      }
    }
    ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
    expect_no_jump();
  }
}

TEST_F(DrivePositionActual, SetFeedbackTellsTheDriveWhereTheMachineStandsBeforeAnySync) {
  axis = far_from_zero;
  drive->set_feedback(DriveFeedback{axis, 0, axis});
  EXPECT_EQ(drive->objects().app.position_actual, far_from_zero);
  (void)deliver(encode_nmt(NmtCommand::start, node));
  enable_by_sdo();
  EXPECT_TRUE(drive->following()) << "known: no need to wait for the first SYNC";
  EXPECT_EQ(drive->setpoint(), far_from_zero);
  expect_no_jump();
}

// --- Issue 34, item 2: the step limit cannot be configured away while enabled -------------------

TEST_F(DriveSafety, TheStepLimitSyncPeriodAndChecksCannotBeChangedWhileEnabled) {
  enable();
  const std::int64_t limit = drive->step_limit_counts();
  struct Write {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint32_t value;
    std::uint8_t size;
  };
  for (const Write w : {Write{obj::communication_cycle_period, 0, 0, 4}, Write{obj::communication_cycle_period, 0, 2000, 4},
                        Write{obj::interpolation_time_period, 1, 255, 1}, Write{obj::interpolation_time_period, 2, 0, 1},
                        Write{obj::max_profile_velocity, 0, 0xFFFF'FFFFU, 4},
                        Write{obj::communication_loss_periods, 0, 255, 1},
                        Write{obj::following_error_window, 0, following_error_window_off, 4},
                        Write{obj::following_error_timeout, 0, 60'000, 2},
                        Write{obj::consumer_heartbeat_time, 1, 0x007F'0064U, 4}}) {
    SCOPED_TRACE(w.index);
    EXPECT_EQ(sdo_write(w.index, w.sub, w.value, w.size), SdoAbort::cannot_store_device_state);
  }
  EXPECT_EQ(drive->step_limit_counts(), limit);
  EXPECT_EQ(drive->objects().comm.cycle_period_us, period_us);
  EXPECT_EQ(drive->objects().app.max_profile_velocity, default_max_profile_velocity);
  // Writing what an object holds changes nothing: accepted.
  EXPECT_EQ(sdo_write(obj::max_profile_velocity, 0, default_max_profile_velocity, 4), SdoAbort::none);
  // The attacks: a 2e9 target, then 4e6 counts in one period, are still refused.
  for (const std::int32_t target : {2'000'000'000, 4'000'000}) {
    SCOPED_TRACE(target);
    (void)period(controlword::enable_operation, target);
    EXPECT_EQ(drive->state(), Cia402State::fault);
    EXPECT_EQ(axis, 0);
    EXPECT_EQ(largest_step, 0);
    // Disabled (fault): the objects may be changed again, and the drive enabled anew.
    EXPECT_EQ(sdo_write(obj::max_profile_velocity, 0, 5'000'000, 4), SdoAbort::none);
    EXPECT_EQ(sdo_write(obj::max_profile_velocity, 0, default_max_profile_velocity, 4), SdoAbort::none);
    (void)period(controlword::fault_reset, 0);
    for (const std::uint16_t cw : {controlword::shutdown, controlword::switch_on, controlword::enable_operation}) {
      (void)period(cw, axis);
    }
    ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
  }
}

TEST_F(DriveSafety, ACyclePeriodOfZeroDoesNotSwitchTheSyncChecksOff) {
  // 0x1006 = 0 before enabling is allowed; the SYNC loss and rate checks then run on 0x60C2.
  EXPECT_EQ(sdo_write(obj::communication_cycle_period, 0, 0, 4), SdoAbort::none);
  enable();
  EXPECT_EQ(drive->step_limit_counts(), 10'000);
  // Duplicated SYNCs: refused for their rate after the tolerated burst.
  bool refused = false;
  for (int k = 1; k <= 10 && !refused; ++k) {
    now += period_us;
    (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, k}));
    (void)deliver(encode_sync());
    refused = deliver(encode_sync()) == DriveEvent::sync_rejected;
  }
  EXPECT_TRUE(refused) << "the rate check runs with 0x1006 = 0";

  // SYNC loss: a fresh drive, 0x1006 = 0, enabled, then silence.
  drive.emplace(config());
  sent.clear();
  EXPECT_EQ(sdo_write(obj::abort_connection_option, 0, 0, 2), SdoAbort::none);
  EXPECT_EQ(sdo_write(obj::communication_cycle_period, 0, 0, 4), SdoAbort::none);
  enable();
  const std::uint64_t last_sync = now;
  while (now < last_sync + 20'000 && drive->state() == Cia402State::operation_enabled) {
    now += 100;
    drive->poll(now, out);
    collect();
  }
  EXPECT_NE(drive->state(), Cia402State::operation_enabled) << "SYNC loss detected";
  EXPECT_EQ(now, last_sync + 4'500) << "(0x2001 + 1.5) periods of 0x60C2";
  ASSERT_FALSE(emcys().empty());
  EXPECT_EQ(emcys().back().data[0], emcy_cause::sync_loss);
}

// --- Issue 34, item 4: SYNC lengths, 0x1019, fault reset after NMT start, NMT stop with 0x6007 = 0

CanFrame sync_of_length(std::uint8_t len) {
  CanFrame f = encode_sync();
  f.len = len;
  for (std::uint8_t i = 0; i < len; ++i) {
    f.data[i] = static_cast<std::uint8_t>(i + 1);
  }
  return f;
}

TEST_F(DriveSafety, ASyncOfTwoToEightBytesIsAnUnexpectedLengthWhateverTheCounterSetting) {
  for (const std::uint8_t overflow : {std::uint8_t{0}, std::uint8_t{8}}) {
    for (std::uint8_t len = 2; len <= 8; ++len) {
      SCOPED_TRACE(testing::Message() << "0x1019 = " << int{overflow} << ", DLC " << int{len});
      drive.emplace(config());
      sent.clear();
      last_counter = 0;
      axis = 0;
      if (overflow != 0) {
        ASSERT_EQ(write_sync_counter_overflow(overflow), SdoAbort::none);
      }
      enable(overflow);
      now += period_us;
      (void)deliver(encode_rpdo1(node, Rpdo1{controlword::enable_operation, 10}));
      EXPECT_EQ(deliver(sync_of_length(len)), DriveEvent::sync_rejected) << "no period is run for it";
      EXPECT_EQ(axis, 0);
      const auto e = emcys();
      ASSERT_EQ(e.size(), 1U);
      EXPECT_EQ(e[0].error_code, emcy_code::sync_data_length);
      EXPECT_EQ(e[0].data[0], emcy_cause::sync_length);
      EXPECT_EQ(e[0].data[1], len);
      EXPECT_EQ(drive->state(), Cia402State::fault_reaction_active) << "0x6007 = 1";
    }
  }
}

// 0x1019 = 0 and a SYNC with a counter byte: the producer counts, the drive was told it does not.
// CiA 301's unexpected length (EMCY 0x8240, as CANopenNode sends it); while enabled no period runs
// for it and the drive faults (0x6007 = 1), as for any SYNC that does not match 0x1019.
TEST_F(DriveSafety, ASyncWithACounterWhile0x1019IsZeroIsAnUnexpectedLength) {
  ASSERT_EQ(drive->objects().comm.sync_counter_overflow, 0);
  enable(0);
  expect_sync_refused_while_enabled(encode_sync(5), emcy_cause::sync_length, 5);
  // Disabled: the period runs (the axis holds) and the master still hears of it, once.
  drive.emplace(config());
  sent.clear();
  (void)deliver(encode_nmt(NmtCommand::start, node));
  now += period_us;
  EXPECT_EQ(deliver(encode_sync(1)), DriveEvent::sync);
  now += period_us;
  EXPECT_EQ(deliver(encode_sync(2)), DriveEvent::sync);
  ASSERT_EQ(emcys().size(), 1U);
  EXPECT_EQ(emcys()[0].error_code, emcy_code::sync_data_length);
}

TEST_F(DriveSafety, ASyncOfTheWrongLengthWhileDisabledIsReportedNotIgnored) {
  (void)deliver(encode_nmt(NmtCommand::start, node));
  EXPECT_EQ(deliver(sync_of_length(2)), DriveEvent::sync_rejected);
  ASSERT_EQ(emcys().size(), 1U);
  EXPECT_EQ(emcys()[0].error_code, emcy_code::sync_data_length);
  EXPECT_EQ(drive->state(), Cia402State::switch_on_disabled);
  // 0x1019 set and a SYNC without its counter: the period runs (the axis holds) and is reported.
  drive.emplace(config());
  sent.clear();
  ASSERT_EQ(write_sync_counter_overflow(8), SdoAbort::none);
  (void)deliver(encode_nmt(NmtCommand::start, node));
  now += period_us;
  EXPECT_EQ(deliver(encode_sync()), DriveEvent::sync);
  ASSERT_EQ(emcys().size(), 1U);
  EXPECT_EQ(emcys()[0].error_code, emcy_code::sync_data_length);
  EXPECT_EQ(emcys()[0].data[0], emcy_cause::sync_length);
}

TEST_F(DriveSafety, TheSyncCounterOverflowIsWrittenOnlyWhileTheCyclePeriodIsZero) {
  ASSERT_NE(drive->objects().comm.cycle_period_us, 0U);
  EXPECT_EQ(sdo_write(obj::sync_counter_overflow, 0, 8, 1), SdoAbort::cannot_store_device_state);
  EXPECT_EQ(drive->objects().comm.sync_counter_overflow, 0);
  EXPECT_EQ(sdo_write(obj::communication_cycle_period, 0, 0, 4), SdoAbort::none);
  EXPECT_EQ(sdo_write(obj::sync_counter_overflow, 0, 8, 1), SdoAbort::none);
  EXPECT_EQ(drive->objects().comm.sync_counter_overflow, 8);
}

TEST_F(DriveSafety, AFaultResetInTheFirstRpdoAfterNmtStartIsARisingEdge) {
  enable();
  // A master that sent bit 7 with its enable (no effect while enabled)...
  (void)period(controlword::enable_operation | controlword::fault_reset, axis);
  ASSERT_EQ(drive->state(), Cia402State::operation_enabled);
  // ...a third party's NMT pre-operational faults the drive (0x6007 = 1), the reaction completes.
  (void)deliver(encode_nmt(NmtCommand::enter_pre_operational, node));
  now += period_us;
  (void)deliver(encode_sync());
  ASSERT_EQ(drive->state(), Cia402State::fault);
  // The master starts the node and resets the fault in its first RPDO.
  (void)deliver(encode_nmt(NmtCommand::start, node));
  (void)period(controlword::fault_reset, axis);
  EXPECT_EQ(drive->state(), Cia402State::switch_on_disabled);
}

TEST_F(DriveSafety, AThirdPartysNmtStopNeverLeavesThePowerStageEnabled) {
  // 0x6007 = 0 (no action): the drive disables itself, with the EMCY.
  EXPECT_EQ(sdo_write(obj::abort_connection_option, 0, 0, 2), SdoAbort::none);
  enable();
  sent.clear();
  EXPECT_EQ(deliver(encode_nmt(NmtCommand::stop, node)), DriveEvent::handled);
  EXPECT_EQ(drive->nmt_state(), NmtState::stopped);
  EXPECT_EQ(drive->state(), Cia402State::switch_on_disabled);
  ASSERT_EQ(emcys().size(), 1U);
  EXPECT_EQ(emcys()[0].data[0], emcy_cause::nmt_command);
  EXPECT_EQ(emcys()[0].data[1], static_cast<std::uint8_t>(NmtCommand::stop));

  // 0x6007 = 3 with 0x605A = 6 (stay in quick stop active): the stop ends switch on disabled.
  drive.emplace(config());
  sent.clear();
  EXPECT_EQ(sdo_write(obj::abort_connection_option, 0, 3, 2), SdoAbort::none);
  EXPECT_EQ(sdo_write(obj::quick_stop_option, 0, 6, 2), SdoAbort::none);
  enable();
  (void)deliver(encode_nmt(NmtCommand::stop, node));
  EXPECT_EQ(drive->state(), Cia402State::quick_stop_active);
  drive->stop_complete();  // the application has brought the axis to rest
  EXPECT_EQ(drive->state(), Cia402State::switch_on_disabled);
}

}  // namespace
}  // namespace settle::hal::canopen
