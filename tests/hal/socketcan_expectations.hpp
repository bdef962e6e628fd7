// SPDX-License-Identifier: Apache-2.0
// Checks shared by the SocketCAN suites with and without vcan: what an interface without a
// CAN controller (lo, vcan) must answer for every controller setting.
#pragma once

#include <gtest/gtest.h>

#include "settle/hal/socketcan_bus.hpp"

namespace settle::hal::test {

inline void expect_controller_settings_not_supported(CanInterface& iface) {
  ASSERT_TRUE(iface.exists()) << iface.name();
  EXPECT_FALSE(iface.has_controller());
  std::uint32_t bitrate = 0;
  EXPECT_EQ(iface.bitrate(bitrate), ControlStatus::not_supported);
  EXPECT_EQ(iface.set_bitrate(500'000), ControlStatus::not_supported);
  EXPECT_EQ(iface.restart(), ControlStatus::not_supported);
  CanControllerState state{};
  EXPECT_EQ(iface.state(state), ControlStatus::not_supported);
  CanErrorCounters counters{};
  EXPECT_EQ(iface.error_counters(counters), ControlStatus::not_supported);
}

}  // namespace settle::hal::test
