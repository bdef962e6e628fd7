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
  // The move must outlive the stream.
  SetpointStream(const Move<Scalar>& m, std::uint32_t period_us, double counts_per_unit, std::int32_t origin) noexcept
      : move_{&m},
        stepper_{m, static_cast<Scalar>(period_us * 1e-6)},
        period_s_{period_us * 1e-6},
        counts_per_unit_{counts_per_unit},
        origin_{origin} {}

  // The next target; `last` is set on the final one, at or after the move's end.
  [[nodiscard]] std::int32_t next(bool& last) noexcept {
    last = static_cast<double>(stepper_.tick()) * period_s_ >= static_cast<double>(move_->duration());
    const Sample<Scalar> s = stepper_.step();
    const double counts = std::nearbyint(static_cast<double>(s.p) * counts_per_unit_);
    return static_cast<std::int32_t>(static_cast<std::int64_t>(origin_) + static_cast<std::int64_t>(counts));
  }
  [[nodiscard]] std::int32_t origin() const noexcept { return origin_; }

 private:
  const Move<Scalar>* move_{nullptr};
  MoveStepper<Scalar> stepper_{};
  double period_s_{0.0};
  double counts_per_unit_{1.0};
  std::int32_t origin_{0};
};

}  // namespace settle::core
