// SPDX-License-Identifier: Apache-2.0
#pragma once
// How one axis maps SI to the drive: position counts per unit (m, or rad for a rotary axis) and the
// servo period. One value shared by the servo loop, the fixed-point builder and the simulated drive,
// so that none of them holds a copy of a number that could drift from another's.
#include <cstdint>
#include <limits>

namespace settle::core {

struct AxisScale {
  double counts_per_unit{1e6};   // 1 count = 1 um by default (docs/drive.md)
  // The period in whole microseconds, the unit of CiA 402's communication-cycle object 0x1006;
  // everything that needs it in seconds asks period_s(), the one conversion.
  std::uint32_t period_us{1000};

  // period_us * 1e-6, the rounding the loop has always used (a multiplication: cheaper than a
  // division on a Cortex-M, where double arithmetic is a library call).
  [[nodiscard]] constexpr double period_s() const noexcept { return period_us * 1e-6; }
  // A positive period and a positive, finite scale (NaN fails both comparisons).
  [[nodiscard]] constexpr bool valid() const noexcept {
    return period_us > 0 && counts_per_unit > 0.0 && counts_per_unit <= std::numeric_limits<double>::max();
  }
};

}  // namespace settle::core
