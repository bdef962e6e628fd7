// SPDX-License-Identifier: Apache-2.0
#include <gtest/gtest.h>

#include "frame_helpers.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/testing/fault_injecting_bus.hpp"

namespace settle::hal {
namespace {

using testing::FaultInjectingBus;

class FaultInjectingBusTest : public ::testing::Test {
 protected:
  LoopbackHub hub;
  LoopbackBus<64> inner{hub};
  LoopbackBus<64> peer{hub};
  FaultInjectingBus bus{inner};
  CanFrame f{};
};

TEST_F(FaultInjectingBusTest, InjectedBusyIsReportedCountedAndNotForwarded) {
  bus.fail_sends(2, SendStatus::busy);
  EXPECT_EQ(bus.send(test::frame(0x1, {1})), SendStatus::busy);
  EXPECT_EQ(bus.send(test::frame(0x1, {2})), SendStatus::busy);
  EXPECT_EQ(bus.send(test::frame(0x1, {3})), SendStatus::sent);
  EXPECT_EQ(bus.counters().tx_busy, 2U);
  EXPECT_EQ(bus.stats().tx_busy, 2U);
  ASSERT_EQ(peer.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f.data[0], 3);
  EXPECT_EQ(peer.receive(f), ReceiveStatus::empty);
}

TEST_F(FaultInjectingBusTest, InjectedErrorsAreReportedAsErrors) {
  bus.fail_sends(1, SendStatus::error);
  EXPECT_EQ(bus.send(test::frame(0x1, {})), SendStatus::error);
  EXPECT_EQ(bus.counters().tx_errors, 1U);
}

TEST_F(FaultInjectingBusTest, DroppedSendsLookSentButNeverArrive) {
  bus.drop_sends(1);
  EXPECT_EQ(bus.send(test::frame(0x1, {})), SendStatus::sent);
  EXPECT_EQ(peer.pending(), 0U);
  EXPECT_EQ(bus.stats().tx_dropped, 1U);
}

TEST_F(FaultInjectingBusTest, DroppedReceivesAreCountedAndSkipped) {
  ASSERT_EQ(peer.send(test::frame(0x1, {1})), SendStatus::sent);
  ASSERT_EQ(peer.send(test::frame(0x1, {2})), SendStatus::sent);
  bus.drop_receives(1);
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f.data[0], 2);
  EXPECT_EQ(bus.stats().rx_dropped, 1U);
}

TEST_F(FaultInjectingBusTest, DelayedSendsGoOutWhenVirtualTimeReachesThem) {
  bus.delay_sends_us(500);
  bus.set_time_us(1000);
  ASSERT_EQ(bus.send(test::frame(0x1, {})), SendStatus::sent);
  bus.set_time_us(1499);
  EXPECT_EQ(peer.pending(), 0U);
  bus.set_time_us(1500);
  EXPECT_EQ(peer.pending(), 1U);
}

TEST_F(FaultInjectingBusTest, DelayedReceivesKeepTheirOrder) {
  bus.delay_receives_us(100);
  bus.set_target(CanFilter{0x080, 0x7FF});  // only SYNC is late
  ASSERT_EQ(peer.send(test::frame(0x080, {})), SendStatus::sent);
  ASSERT_EQ(peer.send(test::frame(0x181, {})), SendStatus::sent);
  EXPECT_EQ(bus.receive(f), ReceiveStatus::empty) << "the TPDO may not overtake the held SYNC";
  bus.set_time_us(100);
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f.id, 0x080U);
  ASSERT_EQ(bus.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f.id, 0x181U);
}

TEST_F(FaultInjectingBusTest, TargetLimitsFaultsToMatchingFrames) {
  bus.set_target(CanFilter{0x080, 0x7FF});
  bus.drop_sends(5);
  EXPECT_EQ(bus.send(test::frame(0x201, {})), SendStatus::sent);
  EXPECT_EQ(bus.send(test::frame(0x080, {})), SendStatus::sent);
  EXPECT_EQ(peer.pending(), 1U);
  ASSERT_EQ(peer.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f.id, 0x201U);
}

TEST_F(FaultInjectingBusTest, RandomFaultsAreReproducibleFromTheSeed) {
  const auto run = [this](std::uint32_t seed) {
    bus.clear_faults();
    bus.set_random(seed, testing::FaultRates{200'000, 0, 0, 0});
    std::uint32_t pattern = 0;
    for (int i = 0; i < 32; ++i) {
      pattern = (pattern << 1U) | (bus.send(test::frame(0x1, {})) == SendStatus::busy ? 1U : 0U);
      while (peer.receive(f) == ReceiveStatus::received) {
      }
    }
    return pattern;
  };
  const std::uint32_t first = run(7);
  EXPECT_EQ(run(7), first);
  EXPECT_NE(first, 0U);
  EXPECT_NE(run(8), first);
}

TEST_F(FaultInjectingBusTest, ControllerErrorStatesAreReportedAndBusOffSendsAndHearsNothing) {
  EXPECT_EQ(bus.bus_state(), BusState::error_active);
  bus.inject_bus_state(BusState::error_passive);
  EXPECT_EQ(bus.bus_state(), BusState::error_passive);
  // error-passive still sends and receives
  EXPECT_EQ(bus.send(test::frame(0x1, {1})), SendStatus::sent);
  ASSERT_EQ(peer.receive(f), ReceiveStatus::received);
  bus.inject_bus_state(BusState::bus_off);
  EXPECT_EQ(bus.counters().bus_off_events, 1U);
  EXPECT_EQ(bus.counters().error_frames, 2U);
  EXPECT_EQ(bus.send(test::frame(0x2, {2})), SendStatus::error);
  EXPECT_EQ(peer.receive(f), ReceiveStatus::empty) << "nothing leaves a controller that is off the bus";
  ASSERT_EQ(peer.send(test::frame(0x3, {3})), SendStatus::sent);
  EXPECT_EQ(bus.receive(f), ReceiveStatus::empty) << "and nothing reaches it";
  EXPECT_EQ(bus.stats().bus_off_rx_lost, 1U);
  // by default a restart is refused (as vcan refuses can_do_restart)
  EXPECT_EQ(bus.restart(), BusStatus::not_supported);
  EXPECT_EQ(bus.bus_state(), BusState::bus_off);
  bus.set_restart_answer(BusStatus::ok);
  EXPECT_EQ(bus.restart(), BusStatus::ok);
  EXPECT_EQ(bus.bus_state(), BusState::error_active);
  EXPECT_EQ(bus.counters().restart_requests, 2U);
  EXPECT_EQ(bus.send(test::frame(0x4, {4})), SendStatus::sent);
  ASSERT_EQ(peer.receive(f), ReceiveStatus::received);
  EXPECT_EQ(f.id, 0x4U);
}

TEST_F(FaultInjectingBusTest, ARestartThatTakesTimeLeavesTheStateToTheController) {
  bus.inject_bus_state(BusState::bus_off);
  bus.set_restart_answer(BusStatus::ok, false);
  EXPECT_EQ(bus.restart(), BusStatus::ok);
  EXPECT_EQ(bus.bus_state(), BusState::bus_off);
  bus.inject_bus_state(BusState::error_active);  // the controller's "restarted"
  EXPECT_EQ(bus.bus_state(), BusState::error_active);
  EXPECT_EQ(bus.counters().bus_off_events, 1U);
}

}  // namespace
}  // namespace settle::hal
