// SPDX-License-Identifier: Apache-2.0
#pragma once
// A planned move as constant tables, for firmware that streams a plan made elsewhere: `settle export
// --plan-from FILE` prints a header of them (docs/export.md), and these types evaluate it. No
// planner, no heap, no exceptions; the tables can live in flash.
//   ExportedPlan<T> (T float or double): the profile's pieces (settle/core/piece.hpp: a polynomial
//     in each piece's phase plus a phasor), the shaper's impulses, the move's scale, in T.
//   FixedExportedPlan: core::fixed's integer motion (segments, tracks, header) for the scale.
// ExportedStream<T> / FixedExportedStream give one target in counts per tick, as the servo loop's
// streams do: tick 0 at the move's start, `last` on the first tick at rest on the target.
#include <cstddef>
#include <cstdint>

#include "settle/core/fixed/motion.hpp"
#include "settle/core/kinematics.hpp"
#include "settle/core/piece.hpp"
#include "settle/core/setpoints.hpp"

namespace settle::core {

// A piece over [start, start + length] of the profile's clock: P(s) = sum_k c[k] s^k + zr sin(2 pi s)
// + zi cos(2 pi s), s the phase in [0, 1] (Piece in T; trig false: no phasor).
template <typename T>
struct ExportedPiece {
  T start;
  T length;
  T c[kMaxPieceDegree + 1];
  T zr;
  T zi;
  bool trig;
};

// One shaper impulse: the move is sum_i amp_i * profile(t - time_i).
template <typename T>
struct ExportedImpulse {
  T amp;
  T time;  // s
};

template <typename T>
struct ExportedPlan {
  const ExportedPiece<T>* pieces;
  std::size_t piece_count;
  const ExportedImpulse<T>* impulses;
  std::size_t impulse_count;
  T profile_end;      // s: the unshaped profile's duration; from then on it rests on profile_distance
  T profile_distance;  // units
  T distance;          // units: where the shaped move rests (sum of the amplitudes times profile_distance)
  T counts_per_unit;
  T period;              // s per tick
  std::int32_t end_tick;  // ceil(move duration / period): the first tick at rest on the target
  std::int32_t target;    // counts: round(distance x counts_per_unit), rounded in double when exported

  // The unshaped profile at time u (s): at rest on 0 before its start and on its distance after
  // its end; the piece containing u found by bisection.
  [[nodiscard]] Sample<T> profile_at(T u) const noexcept {
    if (!(u > T(0)) || piece_count == 0) return {T(0), T(0), T(0), T(0)};
    if (u >= profile_end) return {profile_distance, T(0), T(0), T(0)};
    std::size_t lo = 0, hi = piece_count - 1;
    while (lo < hi) {
      const std::size_t mid = (lo + hi + 1) / 2;
      if (pieces[mid].start <= u) {
        lo = mid;
      } else {
        hi = mid - 1;
      }
    }
    return piece_sample(pieces[lo], u);
  }
  // The shaped move at time t (s); at and past its end exactly on `distance`.
  [[nodiscard]] Sample<T> at(T t) const noexcept {
    if (t >= static_cast<T>(end_tick) * period) return {distance, T(0), T(0), T(0)};
    Sample<T> acc{};
    for (std::size_t i = 0; i < impulse_count; ++i) {
      const Sample<T> s = profile_at(t - impulses[i].time);
      acc.p += impulses[i].amp * s.p;
      acc.v += impulses[i].amp * s.v;
      acc.a += impulses[i].amp * s.a;
      acc.j += impulses[i].amp * s.j;
    }
    return acc;
  }

};

template <typename T>
class ExportedStream {
 public:
  ExportedStream(const ExportedPlan<T>& plan, std::int32_t origin) noexcept : plan_{&plan}, origin_{origin} {}
  // The target of the current tick (origin + the move's position, rounded to counts as to_counts
  // does); `last` on the first tick at rest on the target, origin + target exactly.
  [[nodiscard]] std::int32_t next(bool& last) noexcept {
    last = n_ >= plan_->end_tick;
    const T t = static_cast<T>(n_) * plan_->period;
    advance_tick(n_);
    // At rest: exactly the target (a float product could round the other way at a tie).
    if (last) return static_cast<std::int32_t>(static_cast<std::uint32_t>(origin_) + static_cast<std::uint32_t>(plan_->target));
    return to_counts(plan_->at(t).p, plan_->counts_per_unit, origin_);
  }

 private:
  const ExportedPlan<T>* plan_;
  std::int32_t origin_;
  std::int32_t n_{0};
};

// core::fixed's integer motion of the move, for a core without an FPU: evaluated by random access
// per tick (integer only).
struct FixedExportedPlan {
  fixed::MotionView motion;
};

class FixedExportedStream {
 public:
  FixedExportedStream(const FixedExportedPlan& plan, std::int32_t origin) noexcept : plan_{&plan}, origin_{origin} {}
  [[nodiscard]] std::int32_t next(bool& last) noexcept {
    last = n_ >= plan_->motion.hdr->end_tick;
    const fixed::Sample s = fixed::detail::motion_at(plan_->motion, n_);
    advance_tick(n_);
    return fixed::absolute(origin_, s.p);
  }

 private:
  const FixedExportedPlan* plan_;
  std::int32_t origin_;
  std::int32_t n_{0};
};

}  // namespace settle::core
