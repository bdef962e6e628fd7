// SPDX-License-Identifier: Apache-2.0
#pragma once
// How the servo loop turns a queued move into one integer target per tick. FloatEvaluation runs
// core's Move in float or double (a Cortex-M4F, a Linux drive); FixedEvaluation runs core's
// fixed-point position plan, integer-only per tick (a Cortex-M0 without FPU). Both convert the planned
// Move<double> when it is submitted, outside the tick, and may refuse it there; everything that
// needs double arithmetic or trigonometry is done then, so starting a move in a tick is cheap.
// An online change's blend (core/online.hpp, planned in double by ServoLoop::service()) goes the
// same way: prepare(blend, ...) converts it to the evaluation's scalar outside the tick, start()
// hands the tick its stream, and the tick streams it like a move.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/position.hpp"
#include "settle/core/online.hpp"
#include "settle/core/setpoints.hpp"
#include "settle/core/status.hpp"

namespace settle::runtime {

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

  // At submit, outside the tick: cold, built for size (a Cortex-M image's flash).
  [[nodiscard, gnu::cold]] static core::Status prepare(const core::Move<double>& m, const core::AxisScale& scale,
                                                      Stored& out) noexcept {
    const core::Status st = core::check_streamable(m, scale.period_us);
    if (st != core::Status::ok) return st;
    out.move.convert_from(m);  // in place: no Move<Scalar> temporary on the stack
    out.stream = core::SetpointStream<Scalar>{out.move, scale, 0};
    return core::Status::ok;
  }
  // The move submit's checks sample (ServoLoop::path_within): the one prepared here, in Scalar,
  // whose stream is what is sent; no double evaluation (soft double on a Cortex-M4F) is linked.
  [[nodiscard]] static const core::Move<Scalar>& sampled_move(const Stored& s, const core::Move<double>&) noexcept {
    return s.move;
  }
  // In the tick that starts the move: only where tick 0 is.
  [[nodiscard]] static Stream start(Stored& s, std::int32_t origin) noexcept {
    s.stream.rebase(origin);
    return Stream{s.stream};
  }

  // A blend in Scalar: its segment table converted once (BasicBlend<Scalar>{blend}); tick n is at
  // n periods after the switch, on the running move's position scale.
  struct BlendStored {
    core::BasicBlend<Scalar> blend{};
    Scalar period{0};
    Scalar counts_per_unit{1};
    std::int32_t last_tick{0};  // ceil(duration / period): the first tick at rest on its end
  };
  class BlendStream {
   public:
    BlendStream() = default;
    BlendStream(const BlendStored& b, std::int32_t origin) noexcept : b_{&b}, origin_{origin} {}
    // Same contract as core::SetpointStream::next.
    [[nodiscard]] std::int32_t next(bool& last) noexcept {
      last = n_ >= b_->last_tick;
      const Scalar u = static_cast<Scalar>(n_) * b_->period;
      core::advance_tick(n_);
      return core::to_counts(b_->blend.at(u).p, b_->counts_per_unit, origin_);
    }

   private:
    const BlendStored* b_{nullptr};
    std::int32_t origin_{0};
    std::int32_t n_{0};
  };
  [[nodiscard]] static core::Status prepare(const core::Blend& b, const core::AxisScale& scale,
                                            BlendStored& out) noexcept {
    const std::int64_t ticks = core::ticks_ceil(b.duration() / scale.period_s());
    if (ticks > core::kMaxStreamTicks) return core::Status::duration_does_not_fit;
    out.blend = core::BasicBlend<Scalar>{b};
    out.period = static_cast<Scalar>(scale.period_s());
    out.counts_per_unit = static_cast<Scalar>(scale.counts_per_unit);
    out.last_tick = static_cast<std::int32_t>(ticks);
    return core::Status::ok;
  }
  [[nodiscard]] static BlendStream start(const BlendStored& b, std::int32_t origin) noexcept {
    return BlendStream{b, origin};
  }
};

// The loop streams positions only (CiA 402 cyclic synchronous position), so a slot holds the
// motion's position plan, not the motion: per tick additions and one product, never a sine, a
// Taylor shift or a per-impulse weighting, whatever the shaper (docs/fixed-point.md). `Intervals`
// bounds the plan; the default, 24 (1.6 KiB per slot with its stepper on a Cortex-M, about what a
// Motion took), holds every closed form unshaped or with up to three impulses, and four-impulse
// shapers on profiles of up to five segments; a move needing more is refused at submit
// (table_too_small), as is one the fixed-point formats cannot hold. `Motion` is the integer motion
// built at submit: core::fixed::Motion (8 segments) holds the closed forms; a pseudo-polynomial with
// non-integer exponents needs core::fixed::PolyMotion's 32 (PolyFixedEvaluation, below).
template <std::size_t Intervals, typename Motion = core::fixed::Motion>
struct BasicFixedEvaluation {
  // A blend's plan: one interval per segment (a cubic's drift stays within budget over any
  // segment a blend has; a longer one is refused at service(): table_too_small).
  static constexpr std::size_t kBlendIntervals =
      core::fixed::position_intervals_for(core::fixed::BlendMotion::kMaxSegments, core::fixed::BlendMotion::kMaxTracks);

  // The plan and a stepper on it, both built when the move is submitted. The stepper refers to the
  // plan next to it: a Stored never moves or copies.
  struct Stored {
    Stored() = default;
    Stored(const Stored&) = delete;
    Stored& operator=(const Stored&) = delete;
    core::fixed::BasicPositionPlan<Intervals> plan{};
    core::fixed::PositionStepper stepper{};
  };
  class Stream {
   public:
    Stream() = default;
    Stream(core::fixed::PositionStepper& s, std::int32_t origin, std::int32_t last_tick) noexcept
        : s_{&s}, origin_{origin}, last_tick_{last_tick} {}
    // Same contract as core::SetpointStream::next: `last` on the first tick at the move's end,
    // where the motion is exactly on its target.
    [[nodiscard]] std::int32_t next(bool& last) noexcept {
      last = s_->tick() >= last_tick_;
      return core::fixed::absolute(origin_, s_->next());
    }

   private:
    core::fixed::PositionStepper* s_{nullptr};
    std::int32_t origin_{0};
    std::int32_t last_tick_{0};
  };

  // Builds the integer motion for this axis's scale and period (a temporary: 1.5 KiB of stack at
  // submit), then its position plan; refuses what does not fit, leaving `out` unchanged.
  [[nodiscard]] static core::Status prepare(const core::Move<double>& m, const core::AxisScale& scale,
                                            Stored& out) noexcept {
    Motion motion{};
    core::Status st = motion.build(m, core::fixed::Scale{scale});
    if (st == core::Status::ok) st = out.plan.build(motion);
    if (st == core::Status::ok) out.stepper = core::fixed::PositionStepper{out.plan};
    return st;
  }
  // The move submit's checks sample (ServoLoop::path_within): the plan holds no random access,
  // so the planned Move<double> (soft double either way on a core without an FPU).
  [[nodiscard]] static const core::Move<double>& sampled_move(const Stored&, const core::Move<double>& m) noexcept {
    return m;
  }
  // In the tick that starts the move: only where tick 0 is.
  [[nodiscard]] static Stream start(Stored& s, std::int32_t origin) noexcept {
    return Stream{s.stepper, origin, s.plan.end_tick()};
  }

  // A blend as a position plan of its pieces (core::fixed::BlendMotion, built on the stack: ~4 KiB
  // on a Cortex-M), stepped by the same per-tick code as a move. Tick 0 is the switch.
  struct BlendStored {
    BlendStored() = default;
    BlendStored(const BlendStored&) = delete;
    BlendStored& operator=(const BlendStored&) = delete;
    core::fixed::BasicPositionPlan<kBlendIntervals> plan{};
    core::fixed::PositionStepper stepper{};
  };
  using BlendStream = Stream;
  [[nodiscard]] static core::Status prepare(const core::Blend& b, const core::AxisScale& scale,
                                            BlendStored& out) noexcept {
    core::fixed::BlendMotion motion{};
    core::Status st = motion.build(b, core::fixed::Scale{scale});
    if (st == core::Status::ok) st = out.plan.build(motion);
    if (st == core::Status::ok) out.stepper = core::fixed::PositionStepper{out.plan};
    return st;
  }
  [[nodiscard]] static BlendStream start(BlendStored& b, std::int32_t origin) noexcept {
    return Stream{b.stepper, origin, b.plan.end_tick()};
  }
};

using FixedEvaluation = BasicFixedEvaluation<24>;
// Room for every profile, the pseudo-polynomial's piecewise-quintic form included, where memory is
// not tight (a host: `settle stream --scalar fixed`): the same per-tick code, larger tables.
using PolyFixedEvaluation =
    BasicFixedEvaluation<core::fixed::position_intervals_for(core::fixed::PolyMotion::kMaxSegments,
                                                             core::fixed::PolyMotion::kMaxTracks),
                         core::fixed::PolyMotion>;

}  // namespace settle::runtime
