// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fixed-point evaluation of a planned Move<double>: ramp-cycloid S-curves (both variants),
// ramp-versine, trapezoid and jerk-limited profiles exactly, pseudo-polynomials as a verified
// piecewise quintic, any shaper as delayed weighted copies. Integer-only per tick, no heap; random
// access (at_tick) or stepping (MotionStepper::next, additions and one rotation per tick).
#include <array>
#include <cstddef>
#include <cstdint>

#include "settle/core/fixed/format.hpp"
#include "settle/core/fixed/poly.hpp"
#include "settle/core/fixed/qmath.hpp"
#include "settle/core/move.hpp"
#include "settle/core/online.hpp"
#include "settle/core/piece.hpp"
#include "settle/core/status.hpp"

namespace settle::core::fixed {

// One piece of the move. Over its phase s (0 at its start, 1 at its end) the position is
//   P(s) = sum_k c_k s^k + Im(Z e^{2 pi i s})
// which covers every closed-form profile in core: a cubic plus a cycloid/versine term
// (ramp-cycloid transitions, ramp-versine), cubics (piecewise jerk), quintics (pseudo-poly fit).
struct Segment {
  std::int64_t start{0};  // Q32.32 ticks from the start of the unshaped move
  std::uint64_t ds{0};    // phase per tick, Q1.63
  Coeffs c{};             // Q32.32 counts
  std::int64_t zr{0};     // Z, Q32.32 counts
  std::int64_t zi{0};
  std::array<Factor, kMaxDegree> dsp{};  // ds^1 .. ds^5
  Factor kv{};            // 2 pi ds: d/dtick of the phasor
  Factor ka{};            // (2 pi ds)^2
  // The stepping rotation by d = 2 pi ds as three products (Gauss): with u = 1 - cos d and
  // s = sin d, W += (-u (Wr + Wi) - (s - u) Wi) + i (-u (Wr + Wi) + (s + u) Wr).
  Factor rot_u{};
  Factor rot_sum{};   // s + u
  Factor rot_diff{};  // s - u (>= 0: only segments of 4 ticks and more are stepped)
  Shifts sh{};            // forward-difference scales (poly.hpp)
  std::uint8_t degree{0};
  bool trig{false};
  bool steppable{false};  // false: the stepper evaluates this segment by random access
};

// One shaper impulse: weight * move(n - delay - frac). An unshaped move has one track of weight 1.
struct Track {
  std::int32_t delay{0};   // whole ticks
  std::uint32_t frac{0};   // Q0.32 of a tick: impulse times need not be whole ticks
  std::int32_t weight{0};  // Q2.30
};

struct MotionHeader {
  std::int64_t end{0};       // Q32.32 ticks: end of the last segment (unshaped)
  std::int64_t final_p{0};   // Q32.32 counts: where each track rests after its end
  std::int32_t target{0};    // counts: the move's distance, rounded
  std::int32_t end_tick{0};  // from this tick on the move is at rest on target
  std::uint16_t segments{0};
  std::uint8_t tracks{0};
  std::uint8_t v_frac{16};
  std::uint8_t a_frac{16};
  bool unit_weight{true};    // one track of weight 1: no weighting multiplies
};

struct MotionView {
  const Segment* seg{nullptr};
  const Track* trk{nullptr};
  const MotionHeader* hdr{nullptr};
};

// Where a track stands in a stepping evaluation.
struct TrackState {
  Chains fd{};
  std::int64_t wr{0};  // the phasor Z e^{2 pi i s}, rotated by 2 pi ds per tick
  std::int64_t wi{0};
  std::int32_t seg{0};
  std::int32_t until{0};  // first tick that needs a new anchor
  std::uint8_t mode{0};   // detail::Mode
};

// Writable storage handed to the builder (the capacities come from BasicMotion's parameters).
struct MotionStorage {
  Segment* seg;
  std::size_t seg_capacity;
  Track* trk;
  std::size_t trk_capacity;
  MotionHeader* hdr;
};

namespace detail {
[[nodiscard]] Sample motion_at(const MotionView& m, std::int32_t n) noexcept;
[[nodiscard]] Sample motion_next(const MotionView& m, TrackState* st, std::int32_t n) noexcept;
void motion_restart(TrackState* st, std::size_t count) noexcept;
[[nodiscard]] Status build_motion(const Move<double>& move, const Scale& scale, const MotionStorage& out) noexcept;
[[nodiscard]] Status build_blend_motion(const Blend& blend, const Scale& scale, const MotionStorage& out) noexcept;
}  // namespace detail

template <std::size_t MaxSegments, std::size_t MaxTracks>
class BasicMotion {
 public:
  static constexpr std::size_t kMaxSegments = MaxSegments;
  static constexpr std::size_t kMaxTracks = MaxTracks;

  BasicMotion() = default;  // a zero-length move at rest on 0

  // The sample at tick n (n < 0: before the start; n >= end_tick(): at rest on target).
  [[nodiscard]] Sample at_tick(std::int32_t n) const noexcept { return detail::motion_at(view(), n); }
  [[nodiscard]] std::int32_t end_tick() const noexcept { return hdr_.end_tick; }
  [[nodiscard]] std::int32_t target() const noexcept { return hdr_.target; }
  [[nodiscard]] const MotionHeader& header() const noexcept { return hdr_; }
  [[nodiscard]] const Segment& segment(std::size_t i) const noexcept { return seg_[i]; }
  [[nodiscard]] const Track& track(std::size_t i) const noexcept { return trk_[i]; }
  [[nodiscard]] MotionView view() const noexcept { return {seg_.data(), trk_.data(), &hdr_}; }

  // Converts a planned move. On failure returns a specific Status and leaves this object unchanged.
  [[nodiscard]] Status build(const Move<double>& move, const Scale& scale) noexcept {
    return detail::build_motion(move, scale, {seg_.data(), MaxSegments, trk_.data(), MaxTracks, &hdr_});
  }
  // Converts a blend (an online change, core/online.hpp): its pieces, one track of weight 1, tick 0
  // at the switch, positions on the running move's scale. Needs kBlendSegments segments.
  [[nodiscard]] Status build(const Blend& blend, const Scale& scale) noexcept {
    return detail::build_blend_motion(blend, scale, {seg_.data(), MaxSegments, trk_.data(), MaxTracks, &hdr_});
  }

 private:
  std::array<Segment, MaxSegments> seg_{};
  std::array<Track, MaxTracks> trk_{{{0, 0, std::int32_t{1} << 30}}};
  MotionHeader hdr_{0, 0, 0, 0, 0, 1, 16, 16, true};
};

// Closed-form moves (at most 8 pieces: ramp-cycloid 5, jerk-limited 7) with up to 4 impulses.
using Motion = BasicMotion<8, 4>;
// Room for the piecewise-quintic form of a pseudo-polynomial with non-integer exponents (up to
// 32 pieces), and for a `fastest` move's table (kFastestSegments, 47: its chains of up to 23 turns,
// holds and dwells), so that `settle export --scalar fixed` and `settle stream --scalar fixed`
// hold every planned move. Host-only: no Cortex-M image holds one.
using PolyMotion = BasicMotion<48, 4>;
// A blend: its constant-jerk segments, one track.
using BlendMotion = BasicMotion<kBlendSegments, 1>;

// The pieces (settle/core/piece.hpp) a motion of `profile` is built from, in double: a closed-form
// shape's own exact decomposition, or a pseudo-polynomial's quintic fit for this scale (within
// 1/32 count of the profile at every piece's interior check points). At most `capacity` are written
// (table_too_small beyond); `count` is how many. `settle export` writes them as a constant table.
[[nodiscard]] Status move_pieces(const Profile<double>& profile, const Scale& scale, Piece* out, std::size_t capacity,
                                 std::size_t& count) noexcept;

// Converts `move` into `out`; see BasicMotion::build.
template <std::size_t S, std::size_t K>
[[nodiscard]] Status build_motion(const Move<double>& move, const Scale& scale, BasicMotion<S, K>& out) noexcept {
  return out.build(move, scale);
}

// Stepping evaluation: next() returns the sample at the current tick and advances by one. Inside
// a segment a tick costs additions (forward differences) and one rotation of the trig phasor;
// at each segment boundary it re-anchors on the exact random-access values, so rounding cannot
// drift across segments (within one, the builder bounds the drift and steps only where the bound
// is below 1/16 count). The motion must outlive the stepper.
template <std::size_t MaxTracks>
class MotionStepper {
 public:
  MotionStepper() = default;
  template <std::size_t S>
  explicit MotionStepper(const BasicMotion<S, MaxTracks>& m, std::int32_t first_tick = 0) noexcept
      : view_{m.view()} {
    restart(first_tick);
  }
  // The next call to next() returns tick n (any tick: the stepper re-anchors as needed).
  void restart(std::int32_t n) noexcept {
    n_ = n;
    detail::motion_restart(st_.data(), MaxTracks);
  }
  [[nodiscard]] Sample next() noexcept { return detail::motion_next(view_, st_.data(), n_++); }
  [[nodiscard]] std::int32_t tick() const noexcept { return n_; }

 private:
  MotionView view_{};
  std::array<TrackState, MaxTracks> st_{};
  std::int32_t n_{0};
};

}  // namespace settle::core::fixed
