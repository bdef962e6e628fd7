// SPDX-License-Identifier: Apache-2.0
#pragma once
// Ramp + cycloid + versine position command of seeds 001/002 (Kapucu & Kaplan):
//   y(t) = L R t / 2pi - (Y2/2pi) sin Rt + (Y3/2pi)(1 - cos Rt),  R = 2pi/tau,  Y1 + Y2 + Y3 = L.
// It starts and ends with a velocity step; Peaks reports that with velocity_step = true.
#include <cmath>
#include <type_traits>

#include "settle/core/kinematics.hpp"
#include "settle/core/piece.hpp"
#include "settle/core/trig.hpp"

namespace settle::core {

struct RampVersineParams {
  double distance{0.0};  // L (signed)
  double tau{0.0};       // move time
  double y1{0.0}, y2{0.0}, y3{0.0};
};

// Y1..Y3 (for distance L) that leave the mode (omega, zeta) at rest for any tau.
[[nodiscard]] RampVersineParams ramp_versine_zero_vibration(double distance, double tau, double omega,
                                                            double zeta) noexcept;
[[nodiscard]] Peaks<double> ramp_versine_peaks(const RampVersineParams& p) noexcept;
// The command of duration tau: Y = fractions[0..3) * L when fractions is given, else the
// zero-vibration Y for (omega, zeta).
[[nodiscard]] RampVersineParams ramp_versine_make(double distance, double tau, const double* fractions, double omega,
                                                  double zeta) noexcept;
// The shortest tau whose peak velocity stays within vmax (searched up to 1e4 |D|/vmax); false if none.
[[nodiscard]] bool ramp_versine_shortest(double distance, double vmax, const double* fractions, double omega,
                                         double zeta, double& tau) noexcept;

template <typename T>
class RampVersine {
 public:
  using Params = RampVersineParams;
  RampVersine() = default;
  explicit RampVersine(const RampVersineParams& p) noexcept
      : params_{p},
        l_{static_cast<T>(p.distance)},
        tau_{static_cast<T>(p.tau)},
        r_{static_cast<T>(6.283185307179586476925286766559 / p.tau)},
        y2_{static_cast<T>(p.y2 / 6.283185307179586476925286766559)},
        y3_{static_cast<T>(p.y3 / 6.283185307179586476925286766559)},
        l2pi_{static_cast<T>(p.distance / 6.283185307179586476925286766559)} {}
  template <typename U>
  explicit RampVersine(const RampVersine<U>& o) noexcept : RampVersine(o.params()) {}
  // From double: the double evaluator's values rounded to T, which is what the Params constructor
  // computes (each value in double, rounded once), without double arithmetic.
  template <typename U>
    requires std::is_same_v<U, double>
  explicit RampVersine(const RampVersine<U>& o) noexcept
      : params_{o.params_}, l_{static_cast<T>(o.l_)}, tau_{static_cast<T>(o.tau_)}, r_{static_cast<T>(o.r_)},
        y2_{static_cast<T>(o.y2_)}, y3_{static_cast<T>(o.y3_)}, l2pi_{static_cast<T>(o.l2pi_)} {}

  [[nodiscard]] const RampVersineParams& params() const noexcept { return params_; }
  [[nodiscard]] T duration() const noexcept { return tau_; }
  [[nodiscard]] T distance() const noexcept { return l_; }

  // Uses the half-open interval [0, tau): at t = 0 the command already moves (the step).
  [[nodiscard]] Sample<T> at(T t) const noexcept {
    if (!(t >= T(0))) return {};
    if (t >= tau_) return {l_, T(0), T(0), T(0)};
    const T th = r_ * t;
    const SinCos<T> sc = sin_cos(th);
    return at_angle(th, sc.sin, sc.cos);
  }
  [[nodiscard]] Sample<T> at_angle(T th, T sn, T cs) const noexcept {
    return {l2pi_ * th - y2_ * sn + y3_ * (T(1) - cs), r_ * (l2pi_ - y2_ * cs + y3_ * sn),
            r_ * r_ * (y2_ * sn + y3_ * cs), r_ * r_ * r_ * (y2_ * cs - y3_ * sn)};
  }
  [[nodiscard]] T rate() const noexcept { return r_; }

  // Its parameters as named numbers, as `settle plan` and Python's plan() report them: f(name, i, value)
  // per number, where a '#' in the name stands for i (a per-segment or per-exponent number).
  template <typename F>
  void for_each_param(F&& f) const {
    f("tau", 0, params_.tau);
    f("Y1", 0, params_.y1);
    f("Y2", 0, params_.y2);
    f("Y3", 0, params_.y3);
  }

  // The exact decomposition (piece.hpp): one piece, a ramp plus the phasor of y above.
  [[nodiscard]] int piece_count() const noexcept { return params_.tau > 0.0 ? 1 : 0; }
  [[nodiscard]] Piece piece(int) const noexcept {
    constexpr double two_pi = 6.283185307179586476925286766559;
    Piece pc{};
    pc.length = params_.tau;
    pc.c = {params_.y3 / two_pi, params_.distance};
    pc.zr = -params_.y2 / two_pi;
    pc.zi = -params_.y3 / two_pi;
    pc.trig = true;
    return pc;
  }

 private:
  template <typename>
  friend class RampVersine;
  RampVersineParams params_{};
  T l_{}, tau_{}, r_{}, y2_{}, y3_{}, l2pi_{};
};

}  // namespace settle::core
