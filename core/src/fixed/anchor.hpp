// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal to core/fixed: the exact random-access state of one track at one tick, shared by the
// evaluator (motion_eval.cpp) and the position-plan builder (position_build.cpp), so that a plan's
// anchors are the integers at_tick() computes, bit for bit.
#include <cstdint>

#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/poly.hpp"

namespace settle::core::fixed::detail {

struct TrackAnchor {
  int seg{-1};          // -1: before the track's start; header.segments: after its end
  Coeffs t{};           // Taylor coefficients at the tick's phase, every order (Q32.32 counts per phase^k)
  std::int64_t wr{0};   // the phasor Z e^{2 pi i s} (Q32.32), 0 when the segment has none
  std::int64_t wi{0};
};

// Track `t` of `m` at tick n, unweighted.
[[nodiscard]] TrackAnchor track_anchor(const MotionView& m, const Track& t, std::int32_t n) noexcept;

// The first tick at which track t's local time reaches `edge` (Q32.32 ticks from the unshaped start).
[[nodiscard]] std::int32_t track_first_tick(const Track& t, std::int64_t edge) noexcept;

}  // namespace settle::core::fixed::detail
