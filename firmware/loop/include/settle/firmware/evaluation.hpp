#pragma once
// How the servo loop turns a queued move into one integer target per tick. FloatEvaluation runs
// core's Move in float or double (a Cortex-M4F, a Linux drive); FixedEvaluation runs core's
// fixed-point Motion, integer-only per tick (a Cortex-M0 without FPU). Both convert the planned
// Move<double> when it is submitted, outside the tick, and may refuse it there.
#include <cstdint>

#include "settle/core/fixed/motion.hpp"
#include "settle/core/setpoints.hpp"
#include "settle/core/status.hpp"

namespace settle::firmware {

template <typename Scalar>
struct FloatEvaluation {
  using Stored = core::Move<Scalar>;
  using Stream = core::SetpointStream<Scalar>;

  [[nodiscard]] static core::Status prepare(const core::Move<double>& m, std::uint32_t /*period_us*/,
                                            double /*counts_per_unit*/, Stored& out) noexcept {
    out = Stored{m};
    return core::Status::ok;
  }
  [[nodiscard]] static Stream start(const Stored& s, std::uint32_t period_us, double counts_per_unit,
                                    std::int32_t origin) noexcept {
    return Stream{s, period_us, counts_per_unit, origin};
  }
};

struct FixedEvaluation {
  using Stored = core::fixed::Motion;

  class Stream {
   public:
    Stream() = default;
    Stream(const Stored& m, std::int32_t origin) noexcept
        : stepper_{m}, origin_{origin}, last_tick_{m.end_tick()} {}
    // Same contract as core::SetpointStream::next: `last` on the first tick at the move's end,
    // where the motion is exactly on its target.
    [[nodiscard]] std::int32_t next(bool& last) noexcept {
      last = stepper_.tick() >= last_tick_;
      return core::fixed::absolute(origin_, stepper_.next().p);
    }

   private:
    core::fixed::MotionStepper<Stored::kMaxTracks> stepper_{};
    std::int32_t origin_{0};
    std::int32_t last_tick_{0};
  };

  // Builds the integer form for this axis's scale and period; refuses what does not fit.
  [[nodiscard]] static core::Status prepare(const core::Move<double>& m, std::uint32_t period_us,
                                            double counts_per_unit, Stored& out) noexcept {
    core::fixed::Scale scale{};
    scale.counts_per_unit = counts_per_unit;
    scale.tick_seconds = period_us * 1e-6;
    return out.build(m, scale);
  }
  [[nodiscard]] static Stream start(const Stored& s, std::uint32_t /*period_us*/, double /*counts_per_unit*/,
                                    std::int32_t origin) noexcept {
    return Stream{s, origin};
  }
};

}  // namespace settle::firmware
