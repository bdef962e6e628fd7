// SPDX-License-Identifier: Apache-2.0
#pragma once
// Piecewise constant-jerk profiles: the baselines users compare against. The trapezoidal
// velocity profile (jerk 0, acceleration steps) and the classic 7-phase jerk-limited S-curve
// are both a short list of segments with constant jerk, so one evaluator serves both.
#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "settle/core/kinematics.hpp"
#include "settle/core/piece.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

inline constexpr std::size_t kMaxJerkSegments = 7;

// Up to N segments of constant jerk from rest. The baselines hold kMaxJerkSegments; profile
// `fastest` holds longer tables (profiles/fastest.hpp) in the same form.
// Only the first `count` entries are the table's. `PiecewiseJerkTable t{}` zeroes the rest;
// `PiecewiseJerkTable t;` leaves them unwritten, which the planner's hot path relies on: plan()
// is timed in ns, and zeroing and copying entries nobody reads cost it a third of its time.
template <std::size_t N>
struct PiecewiseJerkTable {
  double distance{0.0};
  std::size_t count{0};
  std::array<double, N> durations;
  std::array<double, N> accel0;  // acceleration at the start of each segment
  std::array<double, N> jerk;
};
using PiecewiseJerkParams = PiecewiseJerkTable<kMaxJerkSegments>;

// Time-optimal trapezoid under vmax/amax (a triangle when vmax is not reached).
[[nodiscard]] PiecewiseJerkParams trapezoid_time_optimal(double distance, double vmax, double amax) noexcept;
// Trapezoid of duration T whose cruise is at v (D/T < |v| <= 2D/T): ta = T - D/v.
[[nodiscard]] PiecewiseJerkParams trapezoid_timed(double distance, double duration, double v) noexcept;
// Time-optimal rest-to-rest 7-phase S-curve under vmax/amax/jmax. With `peaks`, also its true
// peaks, from the phases (the cruise velocity, the plateau acceleration, jmax): what
// piecewise_peaks finds in the table, without walking it (plan() is timed in ns).
[[nodiscard]] PiecewiseJerkParams jerk_limited_time_optimal(double distance, double vmax, double amax, double jmax,
                                                           Peaks<double>* peaks = nullptr) noexcept;
// The same, written into `out` in place: the planner's hot path, which copies no table.
void jerk_limited_time_optimal(double distance, double vmax, double amax, double jmax, PiecewiseJerkParams& out,
                               Peaks<double>* peaks = nullptr) noexcept;
[[nodiscard]] double piecewise_duration(const PiecewiseJerkParams& p) noexcept;
[[nodiscard]] Peaks<double> piecewise_peaks(const PiecewiseJerkParams& p) noexcept;

template <typename T, std::size_t N = kMaxJerkSegments>
class PiecewiseJerk {
 public:
  using Params = PiecewiseJerkTable<N>;
  // A few multiply-adds and a short search: Profile::at evaluates it inline (profile.hpp).
  static constexpr bool kInlineEvaluation = true;
  PiecewiseJerk() = default;
  // The table is taken entry by entry, its `count` entries only (PiecewiseJerkTable). A
  // whole-table copy right after the planner wrote the table entry by entry stalls on store
  // forwarding, and a loop bounded by the count alone is compiled into three memmove calls; the
  // second exit keeps it one loop of scalar copies (plan() is timed in ns: bench_core BM_Plan).
  explicit PiecewiseJerk(const Params& p) noexcept : n_{p.count < N ? p.count : N} {
    params_.distance = p.distance;
    params_.count = n_;
    double t = 0.0, pos = 0.0, v = 0.0;
    for (std::size_t i = 0; i < N; ++i) {
      if (i == n_) break;
      const double d = p.durations[i], a = p.accel0[i], j = p.jerk[i];
      params_.durations[i] = d;
      params_.accel0[i] = a;
      params_.jerk[i] = j;
      start_[i] = static_cast<T>(t);
      p0_[i] = static_cast<T>(pos);
      v0_[i] = static_cast<T>(v);
      if constexpr (!kEvaluatesTable) {
        a0_[i] = static_cast<T>(a);
        j_[i] = static_cast<T>(j);
      }
      pos += v * d + a * d * d / 2.0 + j * d * d * d / 6.0;
      v += a * d + j * d * d / 2.0;
      t += d;
    }
    dur_ = static_cast<T>(t);
    dist_ = static_cast<T>(p.distance);
  }
  template <typename U>
  explicit PiecewiseJerk(const PiecewiseJerk<U, N>& o) noexcept : PiecewiseJerk(o.params()) {}
  // From double: the double evaluator's segment states rounded to T, which is what the table
  // constructor computes (in double, rounded once), without integrating the table again in double
  // (soft double on a Cortex-M4F, where the loop converts each submitted move to float).
  template <typename U>
    requires std::is_same_v<U, double>
  explicit PiecewiseJerk(const PiecewiseJerk<U, N>& o) noexcept
      : n_{o.n_} {
    params_.distance = o.params_.distance;
    params_.count = n_;
    for (std::size_t i = 0; i < N; ++i) {
      if (i == n_) break;
      params_.durations[i] = o.params_.durations[i];
      params_.accel0[i] = o.params_.accel0[i];
      params_.jerk[i] = o.params_.jerk[i];
      start_[i] = static_cast<T>(o.start_[i]);
      p0_[i] = static_cast<T>(o.p0_[i]);
      v0_[i] = static_cast<T>(o.v0_[i]);
      a0_[i] = static_cast<T>(o.params_.accel0[i]);
      j_[i] = static_cast<T>(o.params_.jerk[i]);
    }
    dur_ = static_cast<T>(o.dur_);
    dist_ = static_cast<T>(o.dist_);
  }

  [[nodiscard]] const Params& params() const noexcept { return params_; }
  [[nodiscard]] T duration() const noexcept { return dur_; }
  [[nodiscard]] T distance() const noexcept { return dist_; }

  // Its parameters as named numbers, as `settle plan` and Python's plan() report them: f(name, i, value)
  // per number, where a '#' in the name stands for i (a per-segment or per-exponent number).
  template <typename F>
  void for_each_param(F&& f) const {
    for (std::size_t i = 0; i < n_; ++i) {
      f("segment#_duration", i, params_.durations[i]);
      f("segment#_jerk", i, params_.jerk[i]);
    }
  }

  // The exact decomposition (piece.hpp): one cubic per segment, from this evaluator's own segment
  // states. Meant for PiecewiseJerk<double> (the fixed-point builder's input).
  [[nodiscard]] int piece_count() const noexcept { return static_cast<int>(n_); }
  [[nodiscard]] Piece piece(int i) const noexcept {
    const auto k = static_cast<std::size_t>(i);
    const double d = params_.durations[k];
    Piece pc{};
    pc.start = static_cast<double>(start_[k]);
    pc.length = d;
    pc.c = {static_cast<double>(p0_[k]), static_cast<double>(v0_[k]) * d, params_.accel0[k] * d * d / 2.0,
            params_.jerk[k] * d * d * d / 6.0};
    return pc;
  }

  [[nodiscard]] Sample<T> at(T t) const noexcept {
    if (!(t > T(0))) return {};
    if (t >= dur_ || n_ == 0) return {dist_, T(0), T(0), T(0)};
    std::size_t k = n_ - 1;
    while (k > 0 && t < start_[k]) --k;
    return in_segment(k, t);
  }
  // at(t) for a caller whose t never decreases from one call to the next (a stepper), keeping the
  // segment in `k` (0 before the first call): the segment is found forward from the last one, one
  // comparison a tick, where at() searches from the end. The same segment, so the same result:
  // the last one starting at or before t.
  [[nodiscard]] Sample<T> at_forward(T t, std::size_t& k) const noexcept {
    if (!(t > T(0))) return {};
    if (t >= dur_ || n_ == 0) return {dist_, T(0), T(0), T(0)};
    while (k + 1 < n_ && !(t < start_[k + 1])) ++k;
    return in_segment(k, t);
  }

 private:
  template <typename, std::size_t>
  friend class PiecewiseJerk;
  [[nodiscard]] Sample<T> in_segment(std::size_t k, T t) const noexcept {
    const T u = t - start_[k];
    const T j = jerk(k), a0 = accel0(k);
    const T a = a0 + j * u;
    const T v = v0_[k] + u * (a0 + j * u / T(2));
    const T p = p0_[k] + u * (v0_[k] + u * (a0 / T(2) + j * u / T(6)));
    return {p, v, a, j};
  }
  // In double the table's own accelerations and jerks are the evaluation's: not stored twice
  // (seven stores fewer per plan).
  static constexpr bool kEvaluatesTable = std::is_same_v<T, double>;
  static constexpr std::size_t kOwnCopies = kEvaluatesTable ? 0 : N;
  [[nodiscard]] T accel0(std::size_t k) const noexcept {
    if constexpr (kEvaluatesTable) {
      return params_.accel0[k];
    } else {
      return a0_[k];
    }
  }
  [[nodiscard]] T jerk(std::size_t k) const noexcept {
    if constexpr (kEvaluatesTable) {
      return params_.jerk[k];
    } else {
      return j_[k];
    }
  }

  // Entries from n_ on are left unwritten by the table constructor, and never read.
  Params params_;
  std::size_t n_{0};
  std::array<T, N> start_, p0_, v0_;
  std::array<T, kOwnCopies> a0_, j_;
  T dur_{}, dist_{};
};

}  // namespace settle::core
