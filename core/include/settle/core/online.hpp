// SPDX-License-Identifier: Apache-2.0
#pragma once
// Online changes of a running move: `halt` (come to rest as fast as the limits allow) and
// `retarget` (go to a new target), from any state mid-move, leaving every design mode at rest.
// The derivation (mode memory, the conditions on the blend, the solver) is in docs/online.md.
// Freestanding: no heap, no exceptions; a plan costs a few microseconds on a host.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "settle/core/kinematics.hpp"
#include "settle/core/limits.hpp"
#include "settle/core/move.hpp"
#include "settle/core/move_request.hpp"  // Mode: one (omega, zeta), the same a request designs for
#include "settle/core/piece.hpp"
#include "settle/core/residual.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

// Up to this many modes (omega, zeta) are brought to rest by one blend.
inline constexpr std::size_t kMaxOnlineModes = 4;
static_assert(kMaxModes <= kMaxOnlineModes, "a halt keeps every mode a request designs for");
// A blend is this many constant-jerk segments of equal length.
inline constexpr std::size_t kBlendSegments = 24;

// The limits a blend keeps (each > 0): the one limits type (limits.hpp).
using OnlineLimits = Limits;

// ModeMemory and mode_memory(move, t, mode): residual.hpp.

// What the running command (the move, or the blend a halt interrupts) does if left alone: it ends
// at rest on `end` (positions on the move's scale) `remaining` s after the switch, having started at
// `origin`. `at_rest`: it leaves every mode of the request at rest (its memory at its end is zero to
// rounding), so finishing it is itself a zero-residual halt. online_request fills it in.
struct OnlineRunning {
  double origin{0.0};
  double end{0.0};
  double remaining{0.0};
  bool at_rest{false};
};

// Where a blend starts and what it must achieve.
struct OnlineRequest {
  Sample<double> start{};               // p, v, a of the command at the switch (j is not used)
  std::array<Mode, kMaxOnlineModes> modes{};
  std::array<ModeMemory, kMaxOnlineModes> memory{};  // Q of each mode at the switch
  std::size_t mode_count{0};
  OnlineLimits limits{};
  std::optional<double> target;  // retarget: the final position; none: halt wherever it stops
  // A halt (target none) of a command that would run on: the halt stops no further than its end
  // (seen from its origin) and comes to rest no later than it would (plan_online, OnlinePlan).
  std::optional<OnlineRunning> running;
};

// A blend: kBlendSegments constant-jerk segments of length h from the switch state to rest.
// Its clock starts at the switch (u = 0); past its end it is at rest on its final position. Planned
// in double (plan_online); a servo loop evaluates it in its own scalar like every move: the float
// copy (BasicBlend<float>{blend}) converts the segment table, not the plan, and the fixed-point
// evaluation quantises its pieces (piece(), the same decomposition the profiles give).
template <typename T>
class BasicBlend {
 public:
  BasicBlend() = default;
  BasicBlend(const Sample<T>& start, T h, const std::array<T, kBlendSegments>& jerk) noexcept : h_{h}, j_{jerk} {
    p_[0] = start.p;
    v_[0] = start.v;
    a_[0] = start.a;
    for (std::size_t k = 0; k < kBlendSegments; ++k) {
      const T j = j_[k];
      p_[k + 1] = p_[k] + h * (v_[k] + h * (a_[k] / T(2) + h * j / T(6)));
      v_[k + 1] = v_[k] + h * (a_[k] + h * j / T(2));
      a_[k + 1] = a_[k] + h * j;
    }
    p_end_ = p_[kBlendSegments];
  }
  // The same segment table in another scalar (each value rounded once, none recomputed).
  template <typename U>
  explicit BasicBlend(const BasicBlend<U>& o) noexcept
      : h_{static_cast<T>(o.segment_length())}, p_end_{static_cast<T>(o.end_position())} {
    for (std::size_t k = 0; k <= kBlendSegments; ++k) {
      const Sample<U> s = o.knot(k);
      p_[k] = static_cast<T>(s.p);
      v_[k] = static_cast<T>(s.v);
      a_[k] = static_cast<T>(s.a);
      if (k < kBlendSegments) j_[k] = static_cast<T>(o.jerk(k));
    }
  }

  [[nodiscard]] Sample<T> at(T u) const noexcept {
    if (!(u < duration())) return {p_end_, T(0), T(0), T(0)};
    if (!(u > T(0))) return {p_[0], v_[0], a_[0], j_[0]};
    auto k = static_cast<std::size_t>(u / h_);
    if (k >= kBlendSegments) k = kBlendSegments - 1;
    const T w = u - static_cast<T>(k) * h_;
    const T j = j_[k];
    return {p_[k] + w * (v_[k] + w * (a_[k] / T(2) + w * j / T(6))), v_[k] + w * (a_[k] + w * j / T(2)),
            a_[k] + w * j, j};
  }
  [[nodiscard]] T duration() const noexcept { return h_ * static_cast<T>(kBlendSegments); }
  [[nodiscard]] T segment_length() const noexcept { return h_; }
  [[nodiscard]] T jerk(std::size_t k) const noexcept { return j_[k]; }
  [[nodiscard]] Sample<T> start() const noexcept { return knot(0); }
  // p, v, a at the start of segment k (k = kBlendSegments: the end); j is 0.
  [[nodiscard]] Sample<T> knot(std::size_t k) const noexcept { return {p_[k], v_[k], a_[k], T(0)}; }
  // Position at rest at the end (units, on the running move's position scale).
  [[nodiscard]] T end_position() const noexcept { return p_end_; }
  // Exact peaks of |v|, |a|, |j| over the blend (a is piecewise linear, v piecewise quadratic).
  [[nodiscard]] Peaks<T> peaks() const noexcept {
    Peaks<T> pk{};
    for (std::size_t k = 0; k <= kBlendSegments; ++k) {
      pk.v = std::fmax(pk.v, std::fabs(v_[k]));
      pk.a = std::fmax(pk.a, std::fabs(a_[k]));
    }
    for (std::size_t k = 0; k < kBlendSegments; ++k) {
      const T j = j_[k];
      pk.j = std::fmax(pk.j, std::fabs(j));
      if (j != T(0)) {
        const T w = -a_[k] / j;  // where a crosses zero: a velocity extremum
        if (w > T(0) && w < h_) pk.v = std::fmax(pk.v, std::fabs(v_[k] + w * (a_[k] + w * j / T(2))));
      }
    }
    return pk;
  }
  // Its exact decomposition into pieces (piece.hpp): segment k is the cubic
  // p_k + v_k h s + a_k h^2 s^2 / 2 + j_k h^3 s^3 / 6 in its phase s. None when it has no duration.
  [[nodiscard]] int piece_count() const noexcept { return h_ > T(0) ? static_cast<int>(kBlendSegments) : 0; }
  [[nodiscard]] Piece piece(int i) const noexcept {
    const auto k = static_cast<std::size_t>(i);
    const double h = static_cast<double>(h_);
    Piece pc{};
    pc.start = static_cast<double>(k) * h;
    pc.length = h;
    pc.c[0] = static_cast<double>(p_[k]);
    pc.c[1] = static_cast<double>(v_[k]) * h;
    pc.c[2] = static_cast<double>(a_[k]) * h * h / 2.0;
    pc.c[3] = static_cast<double>(j_[k]) * h * h * h / 6.0;
    return pc;
  }

 private:
  T h_{0};
  std::array<T, kBlendSegments + 1> p_{}, v_{}, a_{};
  std::array<T, kBlendSegments> j_{};
  T p_end_{0};
};

using Blend = BasicBlend<double>;

// Whether the blend from `start` with these jerks on segments of length h stays within the limits:
// within_limits(Blend{start, h, jerk}.peaks(), l), the same to the bit (the same recurrences for v
// and a, the same velocity extremum inside a segment, the same bounds; a NaN is passed over as
// peaks' max passes it over), without the positions and stopping at the first excess. The halt's
// duration search tests every candidate blend with it (online.cpp); kept beside peaks() so the two
// change together, and OnlineBlend.WithinIsWithinLimitsOfPeaksToTheBit checks that they agree.
[[nodiscard]] inline bool blend_within(const Sample<double>& start, double h,
                                       const std::array<double, kBlendSegments>& jerk, const OnlineLimits& l) noexcept {
  const double vb = l.vmax * (1.0 + kLimitSlack), ab = l.amax * (1.0 + kLimitSlack),
               jb = l.jmax * (1.0 + kLimitSlack);
  double v = start.v, a = start.a;
  if (std::fabs(v) > vb || std::fabs(a) > ab) return false;
  for (std::size_t k = 0; k < kBlendSegments; ++k) {
    const double j = jerk[k];
    if (std::fabs(j) > jb) return false;
    if (j != 0.0) {
      const double w = -a / j;
      if (w > 0.0 && w < h && std::fabs(v + w * (a + w * j / 2.0)) > vb) return false;
    }
    v = v + h * (a + h * j / 2.0);
    a = a + h * j;
    if (std::fabs(v) > vb || std::fabs(a) > ab) return false;
  }
  return true;
}

// What a change does. A retarget, or a halt without `running`: always `blend`. A halt of a running
// command is the first of these that stops no further than the command's end (seen from
// its origin) and comes to rest no later than the command would:
//   blend      the fastest blend (the halt as asked);
//   to_target  a blend to the command's end, when that ends sooner than finishing the command;
//   finish     no blend: the running command continues to its end, at rest there (it must leave
//              every mode at rest: running.at_rest).
enum class OnlineChoice : std::uint8_t { blend, to_target, finish };

struct OnlinePlan {
  OnlineChoice choice{OnlineChoice::blend};
  Blend blend{};  // blend, to_target: the blend to switch to; finish: empty
  // Why it is not the fastest blend: that one would stop beyond the end / come to rest later.
  bool fastest_passes_target{false};
  bool fastest_ends_later{false};
  // The choice comes to rest later than the running command would: only when that command does not
  // leave every mode at rest (no finish to fall back on) and no blend ends in time.
  bool ends_later{false};
  // The blend durations the plan tried (every search's), its cost: each is a least-squares solve
  // per blend kind tried, with pinning passes (docs/online.md, "Cost"). (In the flags' padding.)
  int durations_tried{0};
  double rest_after{0.0};  // s from the switch to rest: the blend's duration, or running.remaining
};

// Plans the fastest blend (within its family, docs/online.md) that meets the request within the
// limits; for a halt with `running`, chooses as OnlinePlan says. halt_passes_target when every
// blend within the limits stops beyond the end and the command cannot be finished instead. A failed
// plan leaves `out` untouched.
[[nodiscard]] Status plan_online(const OnlineRequest& req, OnlinePlan& out) noexcept;
// The same for a caller that can only switch to a blend: `out` is the chosen blend (blend or
// to_target); halt_finishes_command when the choice is to finish the running command (out untouched).
[[nodiscard]] Status plan_online(const OnlineRequest& req, Blend& out) noexcept;

// The modes a move planned from `req` is designed for, which a change of it leaves at rest: its
// every mode, in order (at most kMaxModes <= kMaxOnlineModes), or
// `fallback` when it names none (the plant's fundamental, say). Returns how many it wrote.
[[nodiscard]] std::size_t design_modes(const MoveRequest& req, std::array<Mode, kMaxOnlineModes>& out,
                                       const Mode* fallback = nullptr) noexcept;

// The limits a change of a move keeps: vmax, amax, jmax where given, else the move's own peaks
// `pk`. A move that steps in acceleration (a trapezoid) has no jerk peak to keep: the blend's jerk
// is held to amax times the fastest of `modes` (1 rad/s without one), the jerk of an acceleration
// change over 1/omega. unsupported_request when the move steps in velocity (no blend can start from
// it with continuous acceleration); non_positive_limit when a limit is zero (a move that does not move).
[[nodiscard]] Status online_limits(const OptionalLimits& limits, const Peaks<double>& pk, const Mode* modes, std::size_t mode_count,
                                   OnlineLimits& out) noexcept;

// Convenience: the request of a halt (target none) or a retarget (target = new distance from the
// move's start) of the running move `m` at time t on its clock, for the given modes; `running` is
// the move's remainder (from its start 0 to its distance, at its duration). Each mode's memory at
// the switch and at the move's end (whether it ends at rest) is integrated, in one pass.
[[nodiscard]] Status online_request(const Move<double>& m, double t, const Mode* modes, std::size_t mode_count,
                                    const OnlineLimits& limits, std::optional<double> target,
                                    OnlineRequest& out) noexcept;

// Each mode's memory at the end of a move: at_end[i] is mode_memory(m, m.duration(), modes[i]) for
// i < mode_count (whether finishing the move leaves the mode at rest). It does not depend on the
// switch time: a caller that keeps moves to change later (the servo loop's queue) or changes one
// move at many times takes it once per move (end_memory) and passes it to online_request.
// Beside it, per mode, the sums of the move's first kEndMemoryPieces pieces (piece.hpp) that the
// mode's memory at a switch reads of every piece that has ended by then (each taken at its piece's
// end, the same sums to the bit), so that online_request integrates only the pieces not yet ended.
inline constexpr std::size_t kEndMemoryPieces = 8;
struct EndMemory {
  std::array<ModeMemory, kMaxOnlineModes> at_end{};
  struct Pieces {
    Mode mode{};  // the mode they were taken for (read only for that mode)
    int count{0};
    std::array<ModeMemory, kEndMemoryPieces> sum{};
  };
  std::array<Pieces, kMaxOnlineModes> pieces{};
  [[nodiscard]] ModeMemory& operator[](std::size_t i) noexcept { return at_end[i]; }
  [[nodiscard]] const ModeMemory& operator[](std::size_t i) const noexcept { return at_end[i]; }
};
// The modes are refused as online_request refuses them (out untouched).
[[nodiscard]] Status end_memory(const Move<double>& m, const Mode* modes, std::size_t mode_count,
                                EndMemory& out) noexcept;
// The same request as above, to the bit, given at_end = end_memory(m, modes, mode_count) (or of
// more modes with these first): only the memory at the switch is integrated.
[[nodiscard]] Status online_request(const Move<double>& m, const EndMemory& at_end, double t, const Mode* modes,
                                    std::size_t mode_count, const OnlineLimits& limits, std::optional<double> target,
                                    OnlineRequest& out) noexcept;

// A blend's own mode memory: Q at u on the clock of blend `b`, of the command that reached the
// blend's start with memory `at_start` and then followed the blend (the composition rule,
// docs/online.md), from the blend's exact pieces. u past its end: the blend at rest on its end.
[[nodiscard]] ModeMemory mode_memory(const Blend& b, const ModeMemory& at_start, double u, const Mode& mode) noexcept;

// The request of a second change while a blend runs: halt or retarget (target: from the running
// move's start, as before) at u on the clock of blend `b`, planned from `planned` (its start's
// memory, its modes and limits are kept). A command changed twice leaves every mode at rest.
// `running` is the blend's remainder (from its start to its end position, at its end).
[[nodiscard]] Status online_request(const Blend& b, const OnlineRequest& planned, double u,
                                    std::optional<double> target, OnlineRequest& out) noexcept;

}  // namespace settle::core
