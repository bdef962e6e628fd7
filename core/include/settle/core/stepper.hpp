// SPDX-License-Identifier: Apache-2.0
#pragma once
// Stepping evaluation: the servo loop asks for setpoints at evenly spaced ticks, so instead of
// sin/cos per tick the ramp-cycloid's trigonometric terms advance by a fixed rotation, re-anchored
// exactly (one sin/cos) at each segment boundary and every kReanchor ticks so rounding cannot
// drift. Other profiles step by random access. Results match Move::at to rounding.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <variant>

#include "settle/core/move.hpp"
#include "settle/core/trig.hpp"

namespace settle::core {

// Tick counters are int32 (an int64 to float conversion is a library call on a Cortex-M4F); a
// counter stops at INT32_MAX instead of overflowing, ~25 days at 1 kHz, far past any move
// the servo loop accepts (core::kMaxStreamTicks).
constexpr void advance_tick(std::int32_t& n) noexcept {
  if (n < INT32_MAX) ++n;
}

// On hosts (kSplitEvaluation) the ramp-cycloid stepper is forced inline into MoveStepper::step:
// out of line it costs about half as much again per tick (its state reloaded and spilled around
// the call; bench/core/settle_tick_instructions). On M-profile cores, whose flash is budgeted, the
// compiler decides (one out-of-line copy on the Cortex-M4F).
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
#define SETTLE_STEPPER_INLINE
#else
#define SETTLE_STEPPER_INLINE [[gnu::always_inline]]
#endif

template <typename T>
class RampCycloidStepper {
 public:
  static constexpr std::int32_t kReanchor = 128;

  RampCycloidStepper() = default;
  // Tick n is at time t0 + n dt of the profile's own clock (t0 < 0 delays it, as a shaper does).
  // The profile must outlive the stepper.
  RampCycloidStepper(const RampCycloid<T>& rc, T dt, T t0) noexcept
      : rc_{&rc}, dt_{dt}, t0_{t0} {
    const SinCos<T> rot = sin_cos(two_pi_v<T>() * dt / rc.tau());
    rot_c_ = rot.cos;
    rot_s_ = rot.sin;
  }

  SETTLE_STEPPER_INLINE [[nodiscard]] Sample<T> step() noexcept {
    const T t = t0_ + static_cast<T>(n_) * dt_;
    advance_tick(n_);
    if (!(t > T(0))) return {};
    if (t >= rc_->duration()) return {rc_->distance(), T(0), T(0), T(0)};
    const int k = seg_ >= 0 && seg_ < 4 && t < rc_->segment(seg_ + 1).start && t >= rc_->segment(seg_).start
                      ? seg_
                      : rc_->segment_at(t);
    const T u = t - rc_->segment(k).start;
    if (rc_->segment(k).cruise) {
      seg_ = k;
      return rc_->in_segment(k, u, T(0), T(1));
    }
    if (k != seg_ || since_anchor_ >= kReanchor) {
      const SinCos<T> a = sin_cos(two_pi_v<T>() * u / rc_->tau());
      sn_ = a.sin;
      cs_ = a.cos;
      seg_ = k;
      since_anchor_ = 0;
    } else {
      const T s = sn_ * rot_c_ + cs_ * rot_s_;
      cs_ = cs_ * rot_c_ - sn_ * rot_s_;
      sn_ = s;
      ++since_anchor_;
    }
    return rc_->in_segment(k, u, sn_, cs_);
  }

 private:
  const RampCycloid<T>* rc_{nullptr};
  T dt_{}, t0_{};
  T rot_c_{1}, rot_s_{0};
  T sn_{0}, cs_{1};
  std::int32_t n_{0};
  int seg_{-1};
  std::int32_t since_anchor_{0};
};

// Steps any Move: per-impulse ramp-cycloid steppers when the profile is a ramp-cycloid and the
// shaper fits MaxImpulses; on hosts (kSplitEvaluation), an unshaped piecewise-jerk move (the
// trapezoid, the jerk-limited S-curve) by its own evaluator, its segment found forward from the
// last tick's (PiecewiseJerk::at_forward: Move::at's result, with neither the move's nor the
// profile's dispatch); random access otherwise. The Move must outlive the stepper.
template <typename T, std::size_t MaxImpulses = 4>
class MoveStepper {
 public:
  MoveStepper() = default;
  MoveStepper(const Move<T>& m, T dt) noexcept : move_{&m}, dt_{dt} {
    const auto* rc = std::get_if<RampCycloid<T>>(&m.profile().variant());
    if (rc != nullptr && m.shaper().count <= MaxImpulses && rc->tau() > T(0)) {
      count_ = m.shaper().count;
      for (std::size_t i = 0; i < count_; ++i) steppers_[i] = RampCycloidStepper<T>{*rc, dt, -m.shaper().time[i]};
    }
    if constexpr (kSplitEvaluation) {
      if (m.unshaped()) piecewise_.table = std::get_if<PiecewiseJerk<T>>(&m.profile().variant());
    }
  }

  [[nodiscard]] Sample<T> step() noexcept {
    const T t = static_cast<T>(n_) * dt_;
    advance_tick(n_);
    if (count_ == 0) {
      if constexpr (kSplitEvaluation) {
        if (piecewise_.table != nullptr) return piecewise_.table->at_forward(t, piecewise_.segment);
        return at_out_of_line(t);
      } else {
        return move_->at(t);
      }
    }
    if (t >= move_->duration()) {
      for (std::size_t i = 0; i < count_; ++i) (void)steppers_[i].step();  // keep clocks aligned
      return {move_->distance(), T(0), T(0), T(0)};
    }
    if (count_ == 1) return steppers_[0].step();
    Sample<T> acc{};
    for (std::size_t i = 0; i < count_; ++i) {
      const Sample<T> s = steppers_[i].step();
      const T w = move_->shaper().amp[i];
      acc.p += w * s.p;
      acc.v += w * s.v;
      acc.a += w * s.a;
      acc.j += w * s.j;
    }
    return acc;
  }
  [[nodiscard]] std::int32_t tick() const noexcept { return n_; }

 private:
  // Any other move by random access; out of line on hosts, where every shape but the piecewise
  // table, and every shaped move, is evaluated out of line by Move::at anyway (profile.hpp): this
  // keeps step() small enough that the ramp-cycloid stepper stays inline in it.
  [[gnu::noinline]] Sample<T> at_out_of_line(T t) const noexcept { return move_->at(t); }

  const Move<T>* move_{nullptr};
  T dt_{};
  std::int32_t n_{0};
  std::size_t count_{0};
  // The unshaped piecewise move and its segment at the last tick; hosts only (on M-profile
  // cores, no RAM per queued move).
  struct Piecewise {
    const PiecewiseJerk<T>* table{nullptr};
    std::size_t segment{0};
  };
  struct NoPiecewise {};
  [[no_unique_address]] std::conditional_t<kSplitEvaluation, Piecewise, NoPiecewise> piecewise_{};
  std::array<RampCycloidStepper<T>, MaxImpulses> steppers_{};
};

}  // namespace settle::core
