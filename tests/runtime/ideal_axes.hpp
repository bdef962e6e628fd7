// SPDX-License-Identifier: Apache-2.0
#pragma once
// N ideal drives on nodes 1..N of one loopback hub, each added to a loop as an axis: the rig of the
// multi-axis loop tests.
#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "settle/hal/testing/ideal_drive.hpp"
#include "settle/runtime/servo_loop.hpp"

namespace settle::testing {

// Axis i: a drive on node i + 1 and the loop's axis i, configured as `a` (its node set to the drive's).
template <typename Loop, std::size_t N>
void add_ideal_axes(Loop& loop, hal::LoopbackHub& hub, std::array<std::unique_ptr<hal::testing::IdealDrive<>>, N>& drives,
                    runtime::AxisConfig a) {
  for (std::size_t i = 0; i < N; ++i) {
    hal::canopen::DriveNodeConfig dc{};
    dc.node = static_cast<std::uint8_t>(i + 1);
    drives[i] = std::make_unique<hal::testing::IdealDrive<>>(hub, dc);
    a.drive.node = dc.node;
    EXPECT_EQ(loop.add_axis(a), runtime::LoopStatus::ok);
  }
}

}  // namespace settle::testing
