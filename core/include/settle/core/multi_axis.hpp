// SPDX-License-Identifier: Apache-2.0
#pragma once
// Coordinated moves of up to kMaxAxes axes that start together and end together, each at rest on
// its own mode (docs/multi_axis.md). Two ways to synchronise them:
//   path  one common path parameter s(t) from 0 to 1, planned under the path limits
//         min_i(limit_i / |D_i|) and shaped so that every moving axis's mode is at rest; axis i is
//         D_i s(t). The path is a straight line by construction; every axis inherits every mode.
//   time  each axis its own move on its own mode, all stretched to one common duration, the
//         slowest axis's shortest; the path is no longer straight (line_deviation measures it).
// Planning runs in double, allocation-free and exception-free like the rest of core.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "settle/core/kinematics.hpp"
#include "settle/core/move.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/online.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

inline constexpr std::size_t kMaxAxes = 8;

enum class SyncMode : std::uint8_t { path, time };
[[nodiscard]] constexpr const char* to_string(SyncMode s) noexcept { return s == SyncMode::path ? "path" : "time"; }

// One axis's part of the request: its distance, its limits (absent: unlimited on that axis) and
// the mode it is designed for (absent: none declared on that axis).
struct AxisSpec {
  double distance{0.0};
  OptionalLimits limits;
  std::optional<double> omega;  // rad/s
  double zeta{0.0};
};

struct MultiAxisRequest {
  // What every axis shares: profile, shaper, vtol, the unshaped move time when given, gammas, y.
  // Its own distance, limits and modes are not read: they are the axes'.
  MoveRequest base{};
  std::array<AxisSpec, kMaxAxes> axes{};
  std::size_t count{0};  // 1..kMaxAxes (else bad_shape_parameter)
  SyncMode sync{SyncMode::path};
};

// A planned coordinated move: what every axis does from the common start.
class MultiAxisPlan {
 public:
  [[nodiscard]] SyncMode sync() const noexcept { return sync_; }
  [[nodiscard]] std::size_t count() const noexcept { return count_; }
  [[nodiscard]] double duration() const noexcept { return duration_; }
  [[nodiscard]] double distance(std::size_t axis) const noexcept { return distance_[axis]; }
  // Peaks of axis `axis`'s own command.
  [[nodiscard]] const Peaks<double>& peaks(std::size_t axis) const noexcept { return peaks_[axis]; }
  // path: the path parameter's move s(t), 0 -> 1 (an empty move when no axis moves).
  [[nodiscard]] const Move<double>& path() const noexcept { return path_; }
  // time: axis `axis`'s own move (an empty move for an axis that does not move).
  [[nodiscard]] const Move<double>& axis_move(std::size_t axis) const noexcept { return moves_[axis]; }
  // The modes the path was shaped for (path sync), in the order of the axes that first named them.
  [[nodiscard]] std::size_t path_mode_count() const noexcept { return path_mode_count_; }
  [[nodiscard]] const Mode& path_mode(std::size_t k) const noexcept { return path_modes_[k]; }

  // Axis `axis` at time t from the common start; at rest on its distance from duration() on.
  [[nodiscard]] Sample<double> at(std::size_t axis, double t) const noexcept {
    if (sync_ == SyncMode::time) return moves_[axis].at(t);
    const Sample<double> s = path_.at(t);
    const double d = distance_[axis];
    if (t >= duration_) return {d, 0.0, 0.0, 0.0};
    return {d * s.p, d * s.v, d * s.a, d * s.j};
  }

 private:
  friend Status plan_axes(const MultiAxisRequest& req, MultiAxisPlan& out, std::size_t& culprit) noexcept;
  SyncMode sync_{SyncMode::path};
  std::size_t count_{0};
  double duration_{0.0};
  std::array<double, kMaxAxes> distance_{};
  std::array<Peaks<double>, kMaxAxes> peaks_{};
  Move<double> path_{};
  std::array<Move<double>, kMaxAxes> moves_{};
  std::array<Mode, kMaxAxes> path_modes_{};
  std::size_t path_mode_count_{0};
};

// Axis i's own request: the shared one with that axis's distance, limits and mode (and no extra
// modes), as time sync plans it and as an error about that axis is reported.
[[nodiscard]] MoveRequest axis_request(const MultiAxisRequest& req, std::size_t i) noexcept;

// Plans a coordinated move. On failure `out` is untouched and `culprit` is the axis whose limits or
// mode the status is about (time sync: the axis whose own plan failed), or kMaxAxes when it is about
// the shared path or request.
[[nodiscard]] Status plan_axes(const MultiAxisRequest& req, MultiAxisPlan& out, std::size_t& culprit) noexcept;

// Axis `axis`'s command as a move of its own, for a loop that streams each axis (`settle stream --axes`).
// Time sync: plan.axis_move(axis). Path sync: D_i s(t), planned as the path is at distance D_i under the
// path limits times |D_i| with the same modes and shapers; `fastest`: the plan's path scaled by D_i (planned
// at each scale, its refined chains agree only to ~1e-8). Equal to plan.at(axis, t) to rounding, of the path's
// duration (every axis ends on the same tick); an axis at rest gets the empty move. `req`: `plan`'s request.
[[nodiscard]] Status axis_command(const MultiAxisRequest& req, const MultiAxisPlan& plan, std::size_t axis,
                                  Move<double>& out) noexcept;

// What a halt or retarget of axis `axis` of a coordinated move keeps at rest and within
// (docs/multi_axis.md, "Halt and retarget"), for the blend planned from axis_command's move:
//   path  the path's modes on every axis, and the path limits times |D_i| (a limit no axis gives:
//         the path's own peak times |D_i|). The blend planner is linear in the state, the mode
//         memory and the limits, so every axis's blend is D_i times the path parameter's own (to
//         rounding); planned once and scaled (plan_path_online, below), a halt keeps the straight
//         line and every axis comes to rest at the same instant, and so does a retarget to targets
//         on the line (lambda D).
//   time  the axis's own mode and limits (absent: its move's own peaks); each axis blends on its own.
// `fallback` (the plant's fundamental, say): the mode kept at rest when the axis would have none.
// The limits follow online_limits (a trapezoid's jerk: amax x the fastest mode's omega).
// unsupported_request with more than kMaxOnlineModes path modes or a move that steps in velocity;
// non_positive_limit for an axis that does not move (it has nothing to change).
struct AxisOnline {
  std::array<Mode, kMaxOnlineModes> modes{};
  std::size_t mode_count{0};
  OnlineLimits limits{};
};
[[nodiscard]] Status axis_online(const MultiAxisRequest& req, const MultiAxisPlan& plan, std::size_t axis,
                                 AxisOnline& out, const Mode* fallback = nullptr) noexcept;

// Path sync: a halt, or a retarget to targets on the line (lambda D_i), of every moving axis at
// once, planned once and scaled per axis (docs/multi_axis.md, "Halt and retarget"). Each axis
// planning its own blend agrees with the others only to rounding, and the durations at which a
// blend fits do not form an interval (docs/online.md): axes rounded to either side of one blend
// for different times and leave the line. So one axis, the reference, plans; every other moving
// axis gets exactly its choice and its segment length (bit for bit) with every jerk times
// D_i / D_ref, started from its own state, and comes to rest at the same instant.
// The reference is the first moving axis: its blend, and a refusal's message about it, are
// what planning that axis alone gives; the planner is invariant under scaling (durations stay,
// jerks scale), so which axis plans does not matter beyond rounding. Its request is what
// online_request gives, the one the loop and `simulate` plan from.
//
// requests[i]: axis i's change as it would plan it alone (null: it does not move, nothing to
// change); distance[i] its D_i. path_change says whether they are one path's change: every
// moving axis's request a scaled copy of the reference's (start state, remainder, targets
// lambda D_i, to 1e-9 of each axis's own scale), of the same modes, with limits at least the
// reference's scaled (so that the scaled blend keeps them). A retarget off the line is not: each
// axis then plans alone.
[[nodiscard]] std::size_t path_reference(const double* distance, std::size_t n) noexcept;
[[nodiscard]] bool path_change(const OnlineRequest* const* requests, const double* distance, std::size_t n) noexcept;
// Axis i's plan from the reference's: the same choice, flags and rest_after, a blend of the same
// segment length with jerks times `ratio` (D_i / D_ref) from `start` (axis i's p, v, a at the
// switch); a finish stays empty.
[[nodiscard]] OnlinePlan scaled_online(const OnlinePlan& ref, double ratio, const Sample<double>& start) noexcept;
// The whole change: plans the reference's request (plan_online) and writes every moving axis's
// plan to out[i] (the others untouched). bad_shape_parameter when !path_change; any plan_online
// status of the reference's, with `culprit` the reference and `out` untouched.
[[nodiscard]] Status plan_path_online(const OnlineRequest* const* requests, const double* distance, std::size_t n,
                                      OnlinePlan* out, std::size_t& culprit) noexcept;

// A point p's offset from the straight line through the origin along dir (n axes, any one unit):
// each axis's component p_i - dir_i sigma, sigma = p.dir / dir.dir, written to `off` unless it is
// null, and the offset's Euclidean length returned; 0 (and `off` zero) when dir is 0. The one
// geometry of every "line deviation" Settle reports: the plan's (below), the changed commands
// `simulate` samples after a halt or retarget, and the counts `stream` sends and reads back.
[[nodiscard]] double offset_from_line(const double* p, const double* dir, std::size_t n,
                                      double* off = nullptr) noexcept;

// How far the coordinated move leaves the straight line from the start to (D_1, ..., D_N): the
// largest Euclidean distance of the point (p_1(t), ..., p_N(t)) from the line over the move, and in
// `per_axis` each axis's largest |p_i(t) - D_i sigma(t)|, sigma(t) the point's projection on the
// line. Axis units. A dense scan refined at every local maximum (planning time only).
[[nodiscard]] double line_deviation(const MultiAxisPlan& plan, std::array<double, kMaxAxes>& per_axis) noexcept;

}  // namespace settle::core
