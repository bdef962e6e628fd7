#pragma once
// Profile `fastest`: the shortest rest-to-rest move under vmax, amax and jmax that leaves every
// design mode (omega, zeta and the request's extra modes) exactly at rest, or, with `robust`,
// keeps their residual within 5 % of a step's over omega (1 +- robust/100). It plans several
// families and keeps the shortest feasible one (docs/fastest.md):
//   bang_coast  jerk in {+J, 0, -J}, switch times solved under the zero-residual conditions
//   scurve / scurve_damped   the ramp-cycloid S-curves (single mode)
//   shaped_zv / _zvd / _zvdd / _ei   the time-optimal jerk-limited move convolved with shapers
//   shaped_spread   (--robust) convolved with ZV shapers at frequencies spread over the band
// Every family but the S-curves is a piecewise-constant-jerk move (the shaped ones flattened:
// the sum of delayed copies is again piecewise constant in jerk), so the shape stores either a
// ramp-cycloid or a constant-jerk segment table.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "settle/core/kinematics.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/piece.hpp"
#include "settle/core/ramp_cycloid.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

// Room for the flattened time-optimal move convolved with four impulses (8 breakpoints each),
// and within the fixed-point PolyMotion's 32 segments.
inline constexpr std::size_t kFastestSegments = 31;

enum class FastestFamily : std::uint8_t {
  none,
  bang_coast,
  scurve,
  scurve_damped,
  shaped_zv,
  shaped_zvd,
  shaped_zvdd,
  shaped_ei,
  shaped_spread,  // ZV at omega (1 +- spread) for --robust, composed
};
inline constexpr std::size_t kFastestFamilies = 9;
[[nodiscard]] constexpr const char* to_string(FastestFamily f) noexcept {
  constexpr const char* names[kFastestFamilies] = {"none",          "bang-coast", "scurve",         "scurve-damped",
                                                   "time-optimal*ZV", "time-optimal*ZVD", "time-optimal*ZVDD",
                                                   "time-optimal*EI", "time-optimal*spread-ZV"};
  const auto i = static_cast<std::size_t>(f);
  return i < kFastestFamilies ? names[i] : "unknown";
}

struct FastestParams {
  FastestFamily family{FastestFamily::none};
  double distance{0.0};
  RampCycloidParams curve{};  // family scurve / scurve_damped
  std::size_t count{0};       // otherwise: constant-jerk segments
  std::array<double, kFastestSegments> durations{};
  std::array<double, kFastestSegments> jerk{};
  // The duration each family reached for this request (0: infeasible or not tried), reported by
  // `settle plan` so that the choice can be checked.
  std::array<double, kFastestFamilies> family_time{};
};

// A move whose jerk is piecewise constant (durations[i], jerk[i]) from rest: its state at the end
// of each segment follows by exact cubic integration.
template <typename T>
class Fastest {
 public:
  using Params = FastestParams;
  Fastest() = default;
  explicit Fastest(const FastestParams& p) noexcept : params_{p}, curve_{p.curve} {
    if (is_curve()) {
      dur_ = curve_.duration();
      dist_ = curve_.distance();
      return;
    }
    n_ = p.count < kFastestSegments ? p.count : kFastestSegments;
    double t = 0.0, pos = 0.0, v = 0.0, a = 0.0;
    for (std::size_t i = 0; i < n_; ++i) {
      const double d = p.durations[i], j = p.jerk[i];
      start_[i] = static_cast<T>(t);
      p0_[i] = static_cast<T>(pos);
      v0_[i] = static_cast<T>(v);
      a0_[i] = static_cast<T>(a);
      j_[i] = static_cast<T>(j);
      pos += d * (v + d * (a / 2.0 + j * d / 6.0));
      v += d * (a + j * d / 2.0);
      a += j * d;
      t += d;
    }
    dur_ = static_cast<T>(t);
    dist_ = static_cast<T>(p.distance);
  }
  template <typename U>
  explicit Fastest(const Fastest<U>& o) noexcept : Fastest(o.params()) {}

  [[nodiscard]] const FastestParams& params() const noexcept { return params_; }
  [[nodiscard]] T duration() const noexcept { return dur_; }
  [[nodiscard]] T distance() const noexcept { return dist_; }
  [[nodiscard]] FastestFamily family() const noexcept { return params_.family; }

  template <typename F>
  void for_each_param(F&& f) const {
    f("family_code", 0, static_cast<double>(params_.family));
    for (std::size_t k = 1; k < kFastestFamilies; ++k) {
      if (params_.family_time[k] > 0.0) f(family_param_name(k), 0, params_.family_time[k]);
    }
    if (is_curve()) {
      curve_.for_each_param(f);
      return;
    }
    for (std::size_t i = 0; i < params_.count; ++i) {
      f("segment#_duration", i, params_.durations[i]);
      f("segment#_jerk", i, params_.jerk[i]);
    }
  }

  [[nodiscard]] int piece_count() const noexcept { return is_curve() ? curve_.piece_count() : static_cast<int>(n_); }
  [[nodiscard]] Piece piece(int i) const noexcept {
    if (is_curve()) return curve_.piece(i);
    const auto k = static_cast<std::size_t>(i);
    const double d = params_.durations[k];
    Piece pc{};
    pc.start = static_cast<double>(start_[k]);
    pc.length = d;
    pc.c = {static_cast<double>(p0_[k]), static_cast<double>(v0_[k]) * d,
            static_cast<double>(a0_[k]) * d * d / 2.0, params_.jerk[k] * d * d * d / 6.0};
    return pc;
  }

  [[nodiscard]] Sample<T> at(T t) const noexcept {
    if (is_curve()) return curve_.at(t);
    if (!(t > T(0))) return {};
    if (t >= dur_ || n_ == 0) return {dist_, T(0), T(0), T(0)};
    std::size_t k = n_ - 1;
    while (k > 0 && t < start_[k]) --k;
    const T u = t - start_[k];
    const T j = j_[k];
    const T a = a0_[k] + j * u;
    const T v = v0_[k] + u * (a0_[k] + j * u / T(2));
    const T p = p0_[k] + u * (v0_[k] + u * (a0_[k] / T(2) + j * u / T(6)));
    return {p, v, a, j};
  }

 private:
  [[nodiscard]] bool is_curve() const noexcept {
    return params_.family == FastestFamily::scurve || params_.family == FastestFamily::scurve_damped;
  }
  [[nodiscard]] static const char* family_param_name(std::size_t k) noexcept {
    constexpr const char* names[kFastestFamilies] = {"",         "time_bang_coast", "time_scurve", "time_scurve_damped",
                                                     "time_zv",  "time_zvd",        "time_zvdd",   "time_ei",
                                                     "time_spread_zv"};
    return names[k];
  }

  FastestParams params_{};
  RampCycloid<T> curve_{};
  std::size_t n_{0};
  std::array<T, kFastestSegments> start_{}, p0_{}, v0_{}, a0_{}, j_{};
  T dur_{}, dist_{};
};

// The planner (core/src/fastest.cpp): every family, the shortest feasible one.
[[nodiscard]] Status plan_fastest(const MoveRequest& r, FastestParams& out, Peaks<double>& pk) noexcept;

// Exact peaks of a piecewise-constant-jerk table (jerk and acceleration at breakpoints, velocity
// also where the acceleration crosses zero inside a segment).
[[nodiscard]] Peaks<double> jerk_table_peaks(const FastestParams& p) noexcept;

// The residual vibration a jerk-table move leaves on mode (omega, zeta): its amplitude when the
// move ends (move units), and that amplitude relative to the one a step of the same distance
// leaves right after it, |D| omega / wd (a step has 1; undamped this is the V(omega) of the
// input-shaping literature, |A(p)| / (|D| omega), A the Laplace transform of the acceleration at
// the pole p). Measured at the move's end, the damping during the move counts, as it does for
// the machine. Not for the ramp-cycloid families.
[[nodiscard]] double fastest_residual_amplitude(const FastestParams& p, double omega, double zeta) noexcept;
[[nodiscard]] double fastest_residual_ratio(const FastestParams& p, double omega, double zeta) noexcept;

struct FastestProfile {
  static constexpr const char* name = "fastest";
  static constexpr const char* summary =
      "shortest move under vmax/amax/jmax leaving every given mode at rest (several families searched)";
  template <typename T>
  using Shape = Fastest<T>;
  [[nodiscard]] static bool needs_mode(const MoveRequest&) noexcept { return true; }
  [[nodiscard]] static Status plan(const MoveRequest& r, FastestParams& out, Peaks<double>& pk) noexcept {
    return plan_fastest(r, out, pk);
  }
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = 0.1;
    r.vmax = 1.0;
    r.amax = 20.0;
    r.jmax = 800.0;
    r.omega = 22.0;
    return r;
  }
};

}  // namespace settle::core
