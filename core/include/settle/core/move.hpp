// SPDX-License-Identifier: Apache-2.0
#pragma once
// A planned move: a profile, the shaper applied to it, and its true peaks. This is what the
// servo loop evaluates each tick and what the simulator drives its plants with.
#include <cstddef>
#include <type_traits>

#include "settle/core/kinematics.hpp"
#include "settle/core/profile.hpp"
#include "settle/core/shaper.hpp"

namespace settle::core {

template <typename T>
class Move {
 public:
  Move() = default;
  Move(const Profile<T>& p, const Shaper<T>& s, const Peaks<T>& peaks) noexcept
      : profile_{p}, shaper_{s}, peaks_{peaks} {
    duration_ = profile_.duration() + shaper_.duration();
    distance_ = profile_.distance();
    note_shaper();
  }
  template <typename U>
  explicit Move(const Move<U>& o) noexcept {
    convert_from(o);
  }
  // Becomes `o` converted to T, in place: the same move as Move<T>{o} without its temporaries (a
  // profile, a shaper and a move: over a kilobyte of stack where the servo loop converts a
  // submitted Move<double> on a Cortex-M).
  template <typename U>
  void convert_from(const Move<U>& o) noexcept {
    profile_.convert_from(o.profile());
    shaper_.convert_from(o.shaper());
    peaks_ = Peaks<T>{static_cast<T>(o.peaks().v), static_cast<T>(o.peaks().a), static_cast<T>(o.peaks().j),
                      o.peaks().velocity_step, o.peaks().acceleration_step};
    duration_ = profile_.duration() + shaper_.duration();
    distance_ = profile_.distance();
    note_shaper();
  }

  // Becomes the move of a Shape (built from `arg`, its Params or a Shape) through `s` (nullptr:
  // no shaper): the same move as Move{Profile{kind, Shape{arg}}, s, peaks}, built in place. A Move
  // is kilobytes, mostly the largest shape's room and 32 impulses; plan() is timed in ns, so only
  // the shape and the impulses in use are written (entries past count are not the shaper's).
  template <typename Shape, typename Arg>
  void assign(ProfileKind kind, const Arg& arg, const Shaper<T>* s, const Peaks<T>& peaks) noexcept {
    const Shape& shape = profile_.template emplace<Shape>(kind, arg);
    if (s != nullptr) {
      shaper_.count = s->count;
      for (std::size_t i = 0; i < s->count; ++i) {
        shaper_.amp[i] = s->amp[i];
        shaper_.time[i] = s->time[i];
      }
    } else {
      shaper_.count = 1;
      shaper_.amp[0] = T(1);
      shaper_.time[0] = T(0);
    }
    peaks_ = peaks;
    duration_ = shape.duration() + shaper_.duration();
    distance_ = shape.distance();
    note_shaper();
  }

  [[nodiscard]] const Profile<T>& profile() const noexcept { return profile_; }
  [[nodiscard]] const Shaper<T>& shaper() const noexcept { return shaper_; }
  [[nodiscard]] const Peaks<T>& peaks() const noexcept { return peaks_; }
  [[nodiscard]] T duration() const noexcept { return duration_; }
  [[nodiscard]] T distance() const noexcept { return distance_; }
  // One impulse at time 0 (Shaper::is_identity): the move is its profile.
  [[nodiscard]] bool unshaped() const noexcept {
    if constexpr (kSplitEvaluation) {
      return unshaped_;
    } else {
      return shaper_.is_identity();
    }
  }

  // Exact shaped evaluation: sum_i A_i p(t - t_i). Past the end the move is at rest on its
  // target exactly (not at sum_i A_i D, which rounding could move by an ulp).
  // Where evaluation is split (kSplitEvaluation: hosts), an unshaped move (one impulse at 0, the
  // common move) is its profile: its duration and distance are the move's, and every shape is at
  // rest on its distance from its duration on, so the profile's own evaluation is returned with
  // no check of the move's (one flag tested, then the profile's dispatch, inline: profile.hpp),
  // and the sum over impulses is out of line. On M-profile cores one path serves every move
  // (flash: the Cortex-M4F's image is budgeted).
  [[nodiscard]] Sample<T> at(T t) const noexcept {
    if constexpr (kSplitEvaluation) {
      if (unshaped_) [[likely]] return profile_.at(t);
    }
    if (t >= duration_) return {distance_, T(0), T(0), T(0)};
    if (shaper_.count == 1) return profile_.at(t - shaper_.time[0]);
    if constexpr (kSplitEvaluation) {
      return shaped_at_out_of_line(t);
    } else {
      return shaped_at(t);
    }
  }

 private:
  // Where evaluation is split, at() tests one flag for the unshaped move; on M-profile cores
  // neither the flag (RAM per queued move) nor the code that sets it (flash) is there.
  struct NoFlag {};
  using UnshapedFlag = std::conditional_t<kSplitEvaluation, bool, NoFlag>;
  static constexpr UnshapedFlag unshaped_default() noexcept {
    if constexpr (kSplitEvaluation) {
      return true;  // the default move: one impulse at 0
    } else {
      return NoFlag{};
    }
  }
  void note_shaper() noexcept {
    if constexpr (kSplitEvaluation) unshaped_ = shaper_.is_identity();
  }
  [[gnu::noinline]] Sample<T> shaped_at_out_of_line(T t) const noexcept { return shaped_at(t); }
  [[nodiscard]] Sample<T> shaped_at(T t) const noexcept {
    Sample<T> acc{};
    for (std::size_t i = 0; i < shaper_.count; ++i) {
      const Sample<T> s = profile_.at(t - shaper_.time[i]);
      const T w = shaper_.amp[i];
      acc.p += w * s.p;
      acc.v += w * s.v;
      acc.a += w * s.a;
      acc.j += w * s.j;
    }
    return acc;
  }

  Profile<T> profile_{};
  Shaper<T> shaper_{};
  Peaks<T> peaks_{};
  T duration_{};
  T distance_{};
  [[no_unique_address]] UnshapedFlag unshaped_{unshaped_default()};  // shaper_.is_identity()
};

}  // namespace settle::core
