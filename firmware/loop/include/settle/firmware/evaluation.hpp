#pragma once
// How the servo loop turns a queued move into one integer target per tick. FloatEvaluation runs
// core's Move in float or double (a Cortex-M4F, a Linux drive); FixedEvaluation runs core's
// fixed-point Motion, integer-only per tick (a Cortex-M0 without FPU). Both convert the planned
// Move<double> when it is submitted, outside the tick, and may refuse it there; everything that
// needs double arithmetic or trigonometry is done then, so starting a move in a tick is cheap.
#include <cstdint>

#include "settle/core/fixed/motion.hpp"
#include "settle/core/setpoints.hpp"
#include "settle/core/status.hpp"

namespace settle::firmware {

template <typename Scalar>
struct FloatEvaluation {
  // The move and its setpoint stream, built together in the queue's slot when the move is
  // submitted. The stream refers to the move next to it: a Stored never moves or copies.
  struct Stored {
    Stored() = default;
    Stored(const Stored&) = delete;
    Stored& operator=(const Stored&) = delete;
    core::Move<Scalar> move{};
    core::SetpointStream<Scalar> stream{};
  };
  // The active move's stream, where it was prepared.
  class Stream {
   public:
    Stream() = default;
    explicit Stream(core::SetpointStream<Scalar>& s) noexcept : s_{&s} {}
    [[nodiscard]] std::int32_t next(bool& last) noexcept { return s_->next(last); }

   private:
    core::SetpointStream<Scalar>* s_{nullptr};
  };

  [[nodiscard]] static core::Status prepare(const core::Move<double>& m, std::uint32_t period_us,
                                            double counts_per_unit, Stored& out) noexcept {
    const core::Status st = core::check_streamable(m, period_us);
    if (st != core::Status::ok) return st;
    out.move = core::Move<Scalar>{m};
    out.stream = core::SetpointStream<Scalar>{out.move, period_us, counts_per_unit, 0};
    return core::Status::ok;
  }
  // In the tick that starts the move: only where tick 0 is.
  [[nodiscard]] static Stream start(Stored& s, std::uint32_t /*period_us*/, double /*counts_per_unit*/,
                                    std::int32_t origin) noexcept {
    s.stream.rebase(origin);
    return Stream{s.stream};
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
