#pragma once
// A move as the drive sees it: one integer target in counts per tick, from the move's start
// (tick 0, the origin) to its end (exactly origin + round(D * counts_per_unit)). The servo loop
// streams these and the offline reference replays them, so both see the same integers.
#include <cmath>
#include <cstdint>

#include "settle/core/stepper.hpp"

namespace settle::core {

template <typename Scalar>
class SetpointStream {
 public:
  SetpointStream() = default;
  // The move must outlive the stream. Everything in double is done here, once: the tick path
  // works in Scalar and integers only (the Cortex-M4F has no double-precision FPU).
  SetpointStream(const Move<Scalar>& m, std::uint32_t period_us, double counts_per_unit, std::int32_t origin) noexcept
      : stepper_{m, static_cast<Scalar>(period_us * 1e-6)},
        last_tick_{static_cast<std::int64_t>(std::ceil(static_cast<double>(m.duration()) / (period_us * 1e-6)))},
        counts_per_unit_{static_cast<Scalar>(counts_per_unit)},
        origin_{origin} {}

  // The next target; `last` is set on the final one, the first tick at or after the move's end
  // (where the move is exactly at rest on its distance).
  [[nodiscard]] std::int32_t next(bool& last) noexcept {
    last = stepper_.tick() >= last_tick_;
    const Sample<Scalar> s = stepper_.step();
    const auto counts = static_cast<std::int64_t>(std::nearbyint(s.p * counts_per_unit_));
    return static_cast<std::int32_t>(static_cast<std::int64_t>(origin_) + counts);
  }
  [[nodiscard]] std::int32_t origin() const noexcept { return origin_; }

 private:
  MoveStepper<Scalar> stepper_{};
  std::int64_t last_tick_{0};
  Scalar counts_per_unit_{1};
  std::int32_t origin_{0};
};

}  // namespace settle::core
