// SPDX-License-Identifier: Apache-2.0
#pragma once
// Ramp-cycloid S-curve of seed 000 and Settle's damped extension of it (see
// docs/scurve-damped.md). Five acceleration segments tau, tau, T3, tau, tau; every transition is
//   rise(u) = A [u/tau - (c2/2pi) sin(2pi u/tau) + (c3/2pi)(1 - cos(2pi u/tau))]
// with c3 = 0 for the undamped profile of the paper.
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "settle/core/kinematics.hpp"
#include "settle/core/piece.hpp"
#include "settle/core/status.hpp"
#include "settle/core/trig.hpp"

namespace settle::core {

// The plan in double: what a planner decides and what the CLI prints.
struct RampCycloidParams {
  double distance{0.0};   // signed D
  double tau{0.0};        // transition length (s)
  double cruise{0.0};     // T3 (s), 0 for the 4-segment profile
  double amplitude{0.0};  // signed A, the plateau acceleration
  double c2{0.0};         // sine weight; 1 - (2pi/tau)^2 / wn^2
  double c3{0.0};         // versine weight; 2 zeta (2pi/tau) / wn; 0 when undamped
};

// Transition weights that leave the mode (omega, zeta) at rest after each transition.
struct CycloidWeights {
  double c2;
  double c3;
};
[[nodiscard]] CycloidWeights cycloid_weights(double tau, double omega, double zeta) noexcept;

// Shape of one normalised transition (A = 1, tau = 1) at s in [0, 1], given sin and cos of 2 pi s.
// Shared by random access and the stepping evaluator so both compute the same numbers.
template <typename T>
struct CycloidShape {
  T c2{}, c3{};
  T k2{}, k3{};  // c/(2pi)
  T m2{}, m3{};  // c/(4pi^2)
  T q2{}, q3{};  // c/(8pi^3)
  T rv1{};       // r_v(1) = 1/2 + c3/(2pi)
  T rp1{};       // r_p(1) = 1/6 - c2/(4pi^2) + c3/(4pi)

  CycloidShape() = default;
  CycloidShape(double c2d, double c3d) noexcept {
    const double tp = 6.283185307179586476925286766559;
    c2 = static_cast<T>(c2d);
    c3 = static_cast<T>(c3d);
    k2 = static_cast<T>(c2d / tp);
    k3 = static_cast<T>(c3d / tp);
    m2 = static_cast<T>(c2d / (tp * tp));
    m3 = static_cast<T>(c3d / (tp * tp));
    q2 = static_cast<T>(c2d / (tp * tp * tp));
    q3 = static_cast<T>(c3d / (tp * tp * tp));
    rv1 = static_cast<T>(0.5 + c3d / tp);
    rp1 = static_cast<T>(1.0 / 6.0 - c2d / (tp * tp) + c3d / (2.0 * tp));
  }
  // The double shape rounded to T: each value is what the constructor above rounds, so the two
  // are the same shape (RampCycloid's conversion from double, below).
  template <typename U>
    requires std::is_same_v<U, double>
  explicit CycloidShape(const CycloidShape<U>& o) noexcept
      : c2{static_cast<T>(o.c2)}, c3{static_cast<T>(o.c3)}, k2{static_cast<T>(o.k2)}, k3{static_cast<T>(o.k3)},
        m2{static_cast<T>(o.m2)}, m3{static_cast<T>(o.m3)}, q2{static_cast<T>(o.q2)}, q3{static_cast<T>(o.q3)},
        rv1{static_cast<T>(o.rv1)}, rp1{static_cast<T>(o.rp1)} {}
  // Normalised jerk, acceleration, velocity, position of a rise.
  [[nodiscard]] T rj(T sn, T cs) const noexcept { return T(1) - c2 * cs + c3 * sn; }
  [[nodiscard]] T ra(T s, T sn, T cs) const noexcept { return s - k2 * sn + k3 * (T(1) - cs); }
  [[nodiscard]] T rv(T s, T sn, T cs) const noexcept {
    return s * s / T(2) - m2 * (T(1) - cs) + k3 * s - m3 * sn;
  }
  [[nodiscard]] T rp(T s, T sn, T cs) const noexcept {
    return s * s * (s * T(1.0 / 6.0) + k3 * T(0.5)) - m2 * s + q2 * sn - q3 * (T(1) - cs);
  }
};

template <typename T>
class RampCycloid {
 public:
  using Params = RampCycloidParams;
  // One transition or the cruise. A transition either rises (0 -> sign*A) or falls
  // (sign*A -> 0); fall(u) = A - rise(u).
  struct Segment {
    T start{};     // time at which it begins
    T p0{}, v0{};  // state at its beginning
    T sign{};      // +1 accelerating half, -1 decelerating half
    bool fall{};
    bool cruise{};
  };

  RampCycloid() = default;
  explicit RampCycloid(const RampCycloidParams& p) noexcept : params_{p}, shape_{p.c2, p.c3} {
    const double tau = p.tau;
    const double a = p.amplitude;
    // The transition's end values, in double whatever T is (the shape has them).
    const CycloidShape<double> unit{p.c2, p.c3};
    const double rv1 = unit.rv1;
    const double rp1 = unit.rp1;
    const double vpk = a * tau;
    // Segment start states in double; closed forms from docs/scurve-damped.md.
    const double v1 = vpk * rv1;
    const double p1 = a * tau * tau * rp1;
    const double p2 = a * tau * tau * (rv1 + 0.5);
    const double p3 = p2 + vpk * p.cruise;
    const double p4 = p3 + vpk * tau - a * tau * tau * rp1;
    const double v4 = vpk - v1;
    const double t2 = 2.0 * tau;
    const double t3 = t2 + p.cruise;
    struct Row {
      double start, p0, v0, sign;
      bool fall, cruise;
    };
    const Row rows[5] = {{0.0, 0.0, 0.0, 1.0, false, false},
                         {tau, p1, v1, 1.0, true, false},
                         {t2, p2, vpk, 1.0, false, true},
                         {t3, p3, vpk, -1.0, false, false},
                         {t3 + tau, p4, v4, -1.0, true, false}};
    for (int i = 0; i < 5; ++i) {
      seg_[i] = Segment{static_cast<T>(rows[i].start), static_cast<T>(rows[i].p0),
                        static_cast<T>(rows[i].v0),    static_cast<T>(rows[i].sign),
                        rows[i].fall,                  rows[i].cruise};
    }
    duration_ = static_cast<T>(t3 + t2);
    tau_ = static_cast<T>(tau);
    inv_tau_ = static_cast<T>(tau > 0.0 ? 1.0 / tau : 0.0);
    amp_ = static_cast<T>(a);
    vpk_ = static_cast<T>(vpk);
    dist_ = static_cast<T>(p.distance);
  }
  // From another scalar's evaluator. From double it is the double evaluator's values rounded to T:
  // the Params constructor computes every value in double and rounds it once, so the result is the
  // same evaluator, without any double arithmetic (soft double on a Cortex-M4F, where the loop
  // converts each submitted Move<double> to float: casts only, a smaller image).
  template <typename U>
  explicit RampCycloid(const RampCycloid<U>& other) noexcept : RampCycloid(other.params()) {}
  template <typename U>
    requires std::is_same_v<U, double>
  explicit RampCycloid(const RampCycloid<U>& o) noexcept
      : params_{o.params_}, shape_{o.shape_}, duration_{static_cast<T>(o.duration_)}, tau_{static_cast<T>(o.tau_)},
        inv_tau_{static_cast<T>(o.inv_tau_)}, amp_{static_cast<T>(o.amp_)}, vpk_{static_cast<T>(o.vpk_)},
        dist_{static_cast<T>(o.dist_)} {
    for (int i = 0; i < 5; ++i) {
      const auto& g = o.seg_[i];
      seg_[i] = Segment{static_cast<T>(g.start), static_cast<T>(g.p0), static_cast<T>(g.v0), static_cast<T>(g.sign),
                        g.fall, g.cruise};
    }
  }

  [[nodiscard]] const RampCycloidParams& params() const noexcept { return params_; }
  [[nodiscard]] T duration() const noexcept { return duration_; }
  [[nodiscard]] T distance() const noexcept { return dist_; }
  [[nodiscard]] const Segment& segment(int i) const noexcept { return seg_[i]; }
  [[nodiscard]] const CycloidShape<T>& shape() const noexcept { return shape_; }
  [[nodiscard]] T tau() const noexcept { return tau_; }
  [[nodiscard]] T amplitude() const noexcept { return amp_; }
  [[nodiscard]] T peak_velocity_nominal() const noexcept { return vpk_; }

  // Index of the segment that holds time t (0 < t < duration()).
  [[nodiscard]] int segment_at(T t) const noexcept {
    int k = 4;
    while (k > 0 && t < seg_[k].start) --k;
    return k;
  }

  // State inside segment k at local time u, with sin/cos of 2 pi u / tau supplied by the caller.
  [[nodiscard]] Sample<T> in_segment(int k, T u, T sn, T cs) const noexcept {
    const Segment& g = seg_[k];
    if (g.cruise) return {g.p0 + vpk_ * u, vpk_, T(0), T(0)};
    const T s = u * inv_tau_;
    const T sa = g.sign * amp_;
    const T ra = shape_.ra(s, sn, cs);
    const T rv = shape_.rv(s, sn, cs);
    const T rp = shape_.rp(s, sn, cs);
    const T rj = shape_.rj(sn, cs);
    if (!g.fall) {
      return {g.p0 + g.v0 * u + sa * tau_ * tau_ * rp, g.v0 + sa * tau_ * rv, sa * ra, sa * inv_tau_ * rj};
    }
    return {g.p0 + g.v0 * u + sa * tau_ * tau_ * (s * s / T(2) - rp), g.v0 + sa * tau_ * (s - rv),
            sa * (T(1) - ra), -sa * inv_tau_ * rj};
  }

  // Its parameters as named numbers, as `settle plan` and Python's plan() report them: f(name, i, value)
  // per number, where a '#' in the name stands for i (a per-segment or per-exponent number).
  template <typename F>
  void for_each_param(F&& f) const {
    f("tau", 0, params_.tau);
    f("cruise", 0, params_.cruise);
    f("A", 0, params_.amplitude);
    f("A2", 0, params_.amplitude * params_.c2);
    f("c2", 0, params_.c2);
    f("c3", 0, params_.c3);
  }

  // The exact decomposition (piece.hpp) read off this evaluator's own segment table: 4 pieces,
  // or 5 with a cruise. Meant for RampCycloid<double> (the fixed-point builder's input).
  [[nodiscard]] int piece_count() const noexcept { return params_.cruise > 0.0 ? 5 : 4; }
  [[nodiscard]] Piece piece(int i) const noexcept {
    const int k = (params_.cruise > 0.0 || i < 2) ? i : i + 1;  // skip an empty cruise
    const Segment& g = seg_[k];
    const double tau = static_cast<double>(tau_);
    Piece pc{};
    pc.start = static_cast<double>(g.start);
    if (g.cruise) {
      pc.length = params_.cruise;
      pc.c = {static_cast<double>(g.p0), static_cast<double>(vpk_) * pc.length};
      return pc;
    }
    // rise: p0 + v0 u + K r_p(s); fall: p0 + v0 u + K (s^2/2 - r_p(s)); K = sign A tau^2 and
    // r_p = s^3/6 + (k3/2) s^2 - m2 s - q3 + (q2 sin + q3 cos) (docs/scurve-damped.md).
    const double kk = static_cast<double>(g.sign) * static_cast<double>(amp_) * tau * tau;
    const double sg = g.fall ? -1.0 : 1.0;
    const double p0 = static_cast<double>(g.p0), v0 = static_cast<double>(g.v0);
    const double k3 = static_cast<double>(shape_.k3), m2 = static_cast<double>(shape_.m2);
    const double q2 = static_cast<double>(shape_.q2), q3 = static_cast<double>(shape_.q3);
    pc.length = tau;
    pc.c = {p0 - sg * kk * q3, v0 * tau - sg * kk * m2, sg * kk * k3 / 2.0 + (g.fall ? kk / 2.0 : 0.0), sg * kk / 6.0};
    pc.zr = sg * kk * q2;
    pc.zi = sg * kk * q3;
    pc.trig = true;
    return pc;
  }

  [[nodiscard]] Sample<T> at(T t) const noexcept {
    if (!(t > T(0))) return {};
    if (t >= duration_) return {dist_, T(0), T(0), T(0)};
    const int k = segment_at(t);
    const T u = t - seg_[k].start;
    if (seg_[k].cruise) return in_segment(k, u, T(0), T(1));
    const SinCos<T> sc = sin_cos(two_pi_v<T>() * u * inv_tau_);
    return in_segment(k, u, sc.sin, sc.cos);
  }

 private:
  template <typename>
  friend class RampCycloid;
  RampCycloidParams params_{};
  CycloidShape<T> shape_{0.0, 0.0};
  Segment seg_[5]{};
  T duration_{}, tau_{}, inv_tau_{}, amp_{}, vpk_{}, dist_{};
};

// True peaks (|v|, |a|, |j|) of a ramp-cycloid plan, computed from the closed forms: jerk and
// acceleration extrema analytically, velocity extrema by root finding where they overshoot.
[[nodiscard]] Peaks<double> ramp_cycloid_peaks(const RampCycloidParams& p) noexcept;

// Peak |a| / |A| and peak |j| * tau / |A| of one transition with weights (c2, c3).
struct TransitionPeaks {
  double accel;  // >= 1; > 1 when the transition overshoots
  double jerk;   // 1 + sqrt(c2^2 + c3^2)
};
[[nodiscard]] TransitionPeaks transition_peaks(double c2, double c3) noexcept;
// Peak |v| of the whole profile in units of A*tau (>= 1; > 1 when the acceleration overshoots).
// Never more than 2 * TransitionPeaks::accel, which lets a planner skip it when v cannot bind.
[[nodiscard]] double transition_velocity_peak(double c2, double c3) noexcept;

// The S-curve of move time `time` (seed 000's rule): 4 segments, or a cruise at vmax when vmax
// (0: none) binds. Undamped when zeta = 0.
[[nodiscard]] Status scurve_timed(double distance, double time, double vmax, double omega, double zeta,
                                  RampCycloidParams& out) noexcept;
// The shortest ramp-cycloid S-curve (undamped or damped variant per `damped`) that leaves the
// mode at rest and whose true peaks respect vmax, amax and jmax (jmax may be +infinity).
[[nodiscard]] Status plan_fastest_scurve(double distance, double vmax, double amax, double jmax, double omega,
                                         double zeta, bool damped, RampCycloidParams& out) noexcept;

}  // namespace settle::core
