// SPDX-License-Identifier: Apache-2.0
#pragma once
// Position-only stepping of a built fixed-point motion, for a servo loop that streams nothing but
// a position per tick (CiA 402 cyclic synchronous position). Everything a tick could need beyond
// additions and one product is done when the plan is built: the shaper's tracks are merged into one
// timeline of intervals, and the exact stepping state at the first tick of each interval is stored,
// so a tick never runs a sine, a Taylor shift or a per-track weighting (docs/fixed-point.md).
#include <array>
#include <cstddef>
#include <cstdint>

#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/poly.hpp"
#include "settle/core/status.hpp"

namespace settle::core::fixed {

// Ticks over which every track stays in one segment (or before its start, or after its end). The
// sum of the weighted tracks is there a polynomial in the tick plus at most one sinusoid, stepped as:
//   forward differences x[0..degree] of the polynomial, order i at 2^-F_i (F_0 = 32, Q32.32
//   counts), x[i] += x[i+1] >> sh[i];
//   the sinusoid y (x[4], Q32.32 counts) and its next difference D (x[5], 2^-(32+dsh)) by the
//   second-order recurrence y += D, D -= c y, c = 2 (1 - cos d) for the rotation d per tick.
// The position is x[0] + y. x holds the values at the interval's first tick: exactly the sum
// at_tick() forms there. 64 bytes.
struct PositionInterval {
  std::array<std::int64_t, kMaxDegree + 1> x{};
  std::int32_t first{0};       // first tick of the interval
  std::int8_t dsh{0};          // D's fraction bits beyond 32 (negative: coarser)
  std::uint8_t degree{0};      // of the polynomial, <= 3 when there is a sinusoid
  std::array<std::uint8_t, kMaxDegree> sh{};  // sh[i] = F_{i+1} - F_i
  std::uint8_t flags{0};       // kTrig, kPrecise
  static constexpr std::uint8_t kTrig = 1;
  static constexpr std::uint8_t kPrecise = 2;  // c to 53 bits: two products per tick instead of one
};

// Every trigonometric segment of a move turns at the same rate (a ramp-cycloid's transitions all
// last tau), so the recurrence's constant is the plan's: c = rot_near 2^-rot_exp to 32 bits, or
// c = (rot_hi + rot_lo 2^-32) 2^-rot_exp to 53 bits in `precise` intervals.
struct PositionHeader {
  std::int32_t end_tick{0};   // from this tick on the move is at rest on target
  std::int32_t target{0};     // counts
  std::uint32_t rot_near{0};  // c's mantissa rounded to nearest (at most 2^32 - 1)
  std::uint32_t rot_hi{0};    // c's mantissa truncated to 32 bits,
  std::uint32_t rot_lo{0};    // and the next 32
  std::int16_t rot_exp{0};
  std::uint16_t intervals{0};
};

struct PositionView {
  const PositionInterval* iv{nullptr};
  const PositionHeader* hdr{nullptr};
};

// Where a position stepper stands: a working copy of the current interval.
struct PositionState {
  PositionInterval cur{};
  std::int32_t n{0};       // the tick next() returns
  std::int32_t until{0};   // first tick after the current interval (before the move: its first tick)
  std::int32_t index{-1};  // current interval, -1 before the first
};

// Most intervals a motion can produce: each track changes segment at most segments + 1 times, and
// the last change (the move's end) opens none.
[[nodiscard]] constexpr std::size_t position_intervals_for(std::size_t segments, std::size_t tracks) noexcept {
  return tracks * (segments + 1) - 1;
}

namespace detail {
[[nodiscard]] Status build_position(const MotionView& m, PositionInterval* out, std::size_t capacity,
                                    PositionHeader* hdr) noexcept;
[[nodiscard]] std::int32_t position_next(const PositionView& p, PositionState& s) noexcept;
void position_restart(const PositionView& p, PositionState& s, std::int32_t n) noexcept;
}  // namespace detail

template <std::size_t MaxIntervals>
class BasicPositionPlan {
 public:
  static constexpr std::size_t kMaxIntervals = MaxIntervals;

  BasicPositionPlan() = default;  // a zero-length move at rest on 0

  // Plans `m`'s positions (m may be discarded afterwards). On failure returns a specific Status
  // (table_too_small: more intervals than MaxIntervals; precision_insufficient: an interval whose
  // drift bound stays over budget even one tick long; unsupported_request: trigonometric segments of
  // different rates, which no profile in core produces) and leaves this object unchanged.
  template <std::size_t S, std::size_t K>
  [[nodiscard]] Status build(const BasicMotion<S, K>& m) noexcept {
    return detail::build_position(m.view(), iv_.data(), MaxIntervals, &hdr_);
  }
  [[nodiscard]] std::int32_t end_tick() const noexcept { return hdr_.end_tick; }
  [[nodiscard]] std::int32_t target() const noexcept { return hdr_.target; }
  [[nodiscard]] const PositionHeader& header() const noexcept { return hdr_; }
  [[nodiscard]] const PositionInterval& interval(std::size_t i) const noexcept { return iv_[i]; }
  [[nodiscard]] PositionView view() const noexcept { return {iv_.data(), &hdr_}; }

 private:
  std::array<PositionInterval, MaxIntervals> iv_{};
  PositionHeader hdr_{};
};

// Room for any Motion (8 segments, 4 tracks) and any PolyMotion (48 segments, 4 tracks).
using PositionPlan = BasicPositionPlan<position_intervals_for(Motion::kMaxSegments, Motion::kMaxTracks)>;
using PolyPositionPlan = BasicPositionPlan<position_intervals_for(PolyMotion::kMaxSegments, PolyMotion::kMaxTracks)>;

// next() returns the position (counts from the start, the same range and rounding as at_tick().p)
// at the current tick and advances: additions, one product while a sinusoid is active (two in the
// plan's `precise` intervals), and at the last tick of an interval a copy of the next one's state
// instead of a step. The plan must outlive the stepper.
class PositionStepper {
 public:
  PositionStepper() = default;
  template <std::size_t N>
  explicit PositionStepper(const BasicPositionPlan<N>& p, std::int32_t first_tick = 0) noexcept : view_{p.view()} {
    restart(first_tick);
  }
  // The next call to next() returns tick n, the value an uninterrupted run gives there. Costs one
  // step per tick between n and the start of its interval: meant for starting, not for the tick.
  void restart(std::int32_t n) noexcept { detail::position_restart(view_, st_, n); }
  [[nodiscard]] std::int32_t next() noexcept { return detail::position_next(view_, st_); }
  [[nodiscard]] std::int32_t tick() const noexcept { return st_.n; }

 private:
  PositionView view_{};
  PositionState st_{};
};

}  // namespace settle::core::fixed
