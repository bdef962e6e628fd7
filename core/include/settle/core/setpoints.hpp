// SPDX-License-Identifier: Apache-2.0
#pragma once
// A move as the drive sees it: one integer target in counts per tick, from the move's start
// (tick 0, the origin) to its end (exactly origin + round(D * counts_per_unit)). The servo loop
// streams these and the offline reference replays them, so both see the same integers.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "settle/core/axis_scale.hpp"
#include "settle/core/status.hpp"
#include "settle/core/stepper.hpp"

namespace settle::core {

// The longest stream, in ticks: the same bound as core/fixed's (2^30 ticks, 12 days at 1 kHz),
// so that tick counters are int32 on every target (an int64 to float conversion is a library
// call on a Cortex-M4F).
inline constexpr std::int64_t kMaxStreamTicks = std::int64_t{1} << 30;

// ceil(q) when that is a stream's tick count (0 to kMaxStreamTicks), kMaxStreamTicks + 1 when it
// is not (NaN among them). Without libm's ceil: a Cortex-M4F image links the double one for
// nothing else (256 B of its budgeted flash), and a truncation and one comparison are exact here.
[[nodiscard]] constexpr std::int64_t ticks_ceil(double q) noexcept {
  // ceil(q) >= 0 exactly when q > -1; ceil(q) <= K exactly when q <= K (K an integer).
  if (!(q > -1.0 && q <= static_cast<double>(kMaxStreamTicks))) return kMaxStreamTicks + 1;
  const auto n = static_cast<std::int64_t>(q);  // towards zero: ceil for q <= 0, floor above
  return static_cast<double>(n) < q ? n + 1 : n;
}

// x rounded to the nearest integer, halves away from zero: std::llround's result for |x| < 2^52,
// without libm's llround (the servo loop's submit, on a Cortex-M4F's budgeted flash). x - trunc(x)
// is exact there, so the comparison with one half is too.
[[nodiscard]] constexpr std::int64_t round_half_away(double x) noexcept {
  const auto n = static_cast<std::int64_t>(x);
  const double r = x - static_cast<double>(n);
  return r >= 0.5 ? n + 1 : (r <= -0.5 ? n - 1 : n);
}

// Ticks from a move's start to its final setpoint: ceil(duration / period) (kMaxStreamTicks + 1
// when that does not fit a stream).
template <typename Scalar>
[[nodiscard]] std::int64_t stream_ticks(const Move<Scalar>& m, std::uint32_t period_us) noexcept {
  return ticks_ceil(static_cast<double>(m.duration()) / (period_us * 1e-6));
}

// Status::duration_does_not_fit when the move has more than kMaxStreamTicks ticks at this
// period (or the period is 0): the servo loop refuses such a move when it is submitted.
template <typename Scalar>
[[nodiscard]] Status check_streamable(const Move<Scalar>& m, std::uint32_t period_us) noexcept {
  return period_us > 0 && stream_ticks(m, period_us) <= kMaxStreamTicks ? Status::ok : Status::duration_does_not_fit;
}

// A position (units from tick 0's origin) as the drive's target: rounded to whole counts, then
// added to the origin modulo 2^32 (positions wrap as a drive's position counter does); a
// displacement beyond +-2^31 counts saturates (the loop refuses such moves when they are submitted).
template <typename Scalar>
[[nodiscard]] std::int32_t to_counts(Scalar p, Scalar counts_per_unit, std::int32_t origin) noexcept {
  Scalar x = std::nearbyint(p * counts_per_unit);
  constexpr Scalar lo = -2147483648.0;  // -2^31 and the largest float/double below 2^31
  constexpr Scalar hi = std::is_same_v<Scalar, float> ? Scalar(2147483520.0F) : Scalar(2147483647.0);
  x = x < lo ? lo : (x > hi ? hi : x);
  const auto counts = static_cast<std::int32_t>(x);
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(origin) + static_cast<std::uint32_t>(counts));
}

template <typename Scalar>
class SetpointStream {
 public:
  SetpointStream() = default;
  // The move must outlive the stream, and pass check_streamable. Everything in double is done
  // here, once: the tick path works in Scalar and int32 only (the Cortex-M4F has no
  // double-precision FPU and no 64-bit conversions).
  SetpointStream(const Move<Scalar>& m, const AxisScale& scale, std::int32_t origin) noexcept
      : stepper_{m, static_cast<Scalar>(scale.period_s())},
        last_tick_{static_cast<std::int32_t>(std::min(stream_ticks(m, scale.period_us), kMaxStreamTicks))},
        counts_per_unit_{static_cast<Scalar>(scale.counts_per_unit)},
        origin_{origin} {}

  // The next target; `last` is set on the final one, the first tick at or after the move's end
  // (where the move is exactly at rest on its distance), in counts as to_counts() gives them.
  [[nodiscard]] std::int32_t next(bool& last) noexcept {
    last = stepper_.tick() >= last_tick_;
    return to_counts(stepper_.step().p, counts_per_unit_, origin_);
  }
  [[nodiscard]] std::int32_t origin() const noexcept { return origin_; }
  // Moves tick 0 to another origin; before the first next() (a stream prepared in advance learns
  // where the axis is only when its move starts).
  void rebase(std::int32_t origin) noexcept { origin_ = origin; }

 private:
  MoveStepper<Scalar> stepper_{};
  std::int32_t last_tick_{0};
  Scalar counts_per_unit_{1};
  std::int32_t origin_{0};
};

}  // namespace settle::core
