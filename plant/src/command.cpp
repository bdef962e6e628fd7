// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/command.hpp"

#include <cmath>
#include <limits>
#include <type_traits>

namespace settle::plant {

namespace {

// t is inside (lo, hi] for a left sample and inside [lo, hi) for a right one.
bool inside(double t, double lo, double hi, bool left) { return left ? (t > lo && t <= hi) : (t >= lo && t < hi); }

// A closed-form shape at t, from its exact pieces (settle/core/piece.hpp): on a breakpoint the
// piece ending there for a left sample, the one starting there for a right one.
template <typename S>
BaseState piece_sample(const S& shape, double t, bool left) {
  const double dur = shape.duration();
  const int n = shape.piece_count();
  if (n == 0 || !inside(t, 0.0, dur, left)) {
    return (left ? t > dur : t >= dur) ? BaseState{shape.distance(), 0.0, 0.0} : BaseState{};
  }
  core::Piece pc{};
  for (int k = 0; k < n; ++k) {
    pc = shape.piece(k);
    if (inside(t, pc.start, pc.start + pc.length, left)) break;
  }
  const core::Sample<double> s = core::piece_at(pc, t);
  return {s.p, s.v, s.a};
}

BaseState pseudo_poly_sample(const core::PseudoPoly<double>& pp, double t, bool left) {
  const auto& q = pp.params();
  if (!inside(t, 0.0, q.duration, left)) {
    return (left ? t > q.duration : t >= q.duration) ? BaseState{q.distance, 0.0, 0.0} : BaseState{};
  }
  // phi = D [1 - sum C w^g], w = 1 - t/T; evaluated here rather than with at() so that the
  // one-sided value at t = 0 is right also for two exponents (an acceleration step there).
  const double w = 1.0 - t / q.duration;
  double p = 0.0, v = 0.0, a = 0.0;
  for (std::size_t i = 0; i < q.count; ++i) {
    const double g = q.gammas[i];
    const double c = q.coeffs[i];
    p += c * std::pow(w, g);
    v += c * g * std::pow(w, g - 1.0);
    a += c * g * (g - 1.0) * std::pow(w, g - 2.0);
  }
  const double d = q.distance;
  const double it = 1.0 / q.duration;
  return {d - d * p, d * it * v, -d * it * it * a};
}

}  // namespace

BaseState profile_sample(const core::Profile<double>& prof, double t, bool left) {
  return prof.visit([&](const auto& p) -> BaseState {
    using P = std::decay_t<decltype(p)>;
    if constexpr (std::is_same_v<P, core::PseudoPoly<double>>) {
      return pseudo_poly_sample(p, t, left);
    } else {
      return piece_sample(p, t, left);
    }
  });
}

void profile_breakpoints(const core::Profile<double>& prof, std::vector<double>& out) {
  out.push_back(0.0);
  prof.visit([&](const auto& p) {
    using P = std::decay_t<decltype(p)>;
    if constexpr (!std::is_same_v<P, core::PseudoPoly<double>>) {
      for (int k = 1; k < p.piece_count(); ++k) out.push_back(p.piece(k).start);
    }
    out.push_back(p.duration());
  });
}

MoveCommand::MoveCommand(const core::Move<double>& m) : move_{m} { profile_breakpoints(move_.profile(), profile_breaks_); }

BaseState MoveCommand::sample(double t, bool left) const {
  const auto& sh = move_.shaper();
  const double end = move_.duration();
  // Past the end the move rests exactly on its target, as core's Move::at does.
  if (left ? t > end : t >= end) return {move_.distance(), 0.0, 0.0};
  // A breakpoint of a shaped move is t_i + b, rounded: t - t_i can miss the profile's breakpoint b
  // by an ulp and give the wrong one-sided limit (a velocity step lost on one side). Within
  // rounding, t - t_i is taken to be b.
  const double tol = 16.0 * std::numeric_limits<double>::epsilon() * (std::fabs(t) + end);
  BaseState acc{};
  for (std::size_t i = 0; i < sh.count; ++i) {
    double u = t - sh.time[i];
    for (double b : profile_breaks_) {
      if (std::fabs(u - b) <= tol) {
        u = b;
        break;
      }
    }
    const BaseState s = profile_sample(move_.profile(), u, left);
    acc.p += sh.amp[i] * s.p;
    acc.v += sh.amp[i] * s.v;
    acc.a += sh.amp[i] * s.a;
  }
  return acc;
}

void MoveCommand::breakpoints(std::vector<double>& out) const {
  std::vector<double> pb;
  profile_breakpoints(move_.profile(), pb);
  const auto& sh = move_.shaper();
  for (std::size_t i = 0; i < sh.count; ++i) {
    for (double t : pb) out.push_back(t + sh.time[i]);
  }
  out.push_back(move_.duration());
}

double StepsCommand::final_position() const {
  double s = 0.0;
  for (std::size_t i = 0; i < shaper_.count; ++i) s += shaper_.amp[i];
  return distance_ * s;
}

BaseState StepsCommand::at(double t) const {
  double s = 0.0;
  for (std::size_t i = 0; i < shaper_.count; ++i) {
    if (shaper_.time[i] <= t) s += shaper_.amp[i];
  }
  return {distance_ * s, 0.0, 0.0};
}

BaseState StepsCommand::at_left(double t) const {
  double s = 0.0;
  for (std::size_t i = 0; i < shaper_.count; ++i) {
    if (shaper_.time[i] < t) s += shaper_.amp[i];
  }
  return {distance_ * s, 0.0, 0.0};
}

void StepsCommand::breakpoints(std::vector<double>& out) const {
  out.push_back(0.0);
  for (std::size_t i = 0; i < shaper_.count; ++i) out.push_back(shaper_.time[i]);
}

InverseDynamicsCommand::InverseDynamicsCommand(double distance, double time, double omega, double zeta, int degree,
                                               double tail_cutoff)
    : d_{distance}, t_{time}, omega_{omega}, kappa_{2.0 * zeta / omega}, degree_{degree == 3 ? 3 : 5} {
  end_ = t_;
  if (kappa_ > 0.0) {
    wp0_ = wp_derivative(0, 0.0);
    w_end_ = wp_derivative(0, t_) - wp0_ * std::exp(-t_ / kappa_);
    // The tail lasts until w is below tail_cutoff of the distance; then the command rests exactly.
    const double cut = tail_cutoff > 0.0 && tail_cutoff < 1.0 ? tail_cutoff : kDefaultTailCutoff;
    const double ratio = std::fabs(w_end_) / (cut * std::fabs(d_));
    if (ratio > 1.0) end_ = t_ + kappa_ * std::log(ratio);
  }
}

double InverseDynamicsCommand::x_derivative(int k, double t) const {
  const double s = t / t_;
  double v = 0.0;
  if (degree_ == 3) {
    // x = D (3 s^2 - 2 s^3)
    switch (k) {
      case 0: v = s * s * (3.0 - 2.0 * s); break;
      case 1: v = 6.0 * s * (1.0 - s); break;
      case 2: v = 6.0 - 12.0 * s; break;
      case 3: v = -12.0; break;
      default: v = 0.0;
    }
    return d_ * v / std::pow(t_, k);
  }
  // x = D (10 s^3 - 15 s^4 + 6 s^5)
  switch (k) {
    case 0: v = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s); break;
    case 1: v = s * s * (30.0 - 60.0 * s + 30.0 * s * s); break;
    case 2: v = s * (60.0 - 180.0 * s + 120.0 * s * s); break;
    case 3: v = 60.0 - 360.0 * s + 360.0 * s * s; break;
    case 4: v = -360.0 + 720.0 * s; break;
    case 5: v = 720.0; break;
    default: v = 0.0;
  }
  return d_ * v / std::pow(t_, k);
}

double InverseDynamicsCommand::wp_derivative(int k, double t) const {
  // A polynomial particular solution: w_p = (1/w^2) sum_i (-kappa)^i x^(i+2), which telescopes
  // through kappa w_p' + w_p = x'' / w^2 because x is a polynomial.
  double acc = 0.0, f = 1.0;
  for (int i = 0; i + 2 + k <= degree_; ++i) {
    acc += f * x_derivative(i + 2 + k, t);
    f *= -kappa_;
  }
  return acc / (omega_ * omega_);
}

BaseState InverseDynamicsCommand::sample(double t, bool left) const {
  if (left ? t <= 0.0 : t < 0.0) return {};
  if (left ? t > end_ : t >= end_) return {d_, 0.0, 0.0};
  if (left ? t <= t_ : t < t_) {
    BaseState s{x_derivative(0, t), x_derivative(1, t), x_derivative(2, t)};
    if (kappa_ > 0.0) {
      const double e = std::exp(-t / kappa_);
      s.p += wp_derivative(0, t) - wp0_ * e;
      s.v += wp_derivative(1, t) + wp0_ * e / kappa_;
      s.a += wp_derivative(2, t) - wp0_ * e / (kappa_ * kappa_);
    } else {
      // Undamped model: w = x'' / w^2 exactly, no tail.
      s.p += wp_derivative(0, t);
      s.v += wp_derivative(1, t);
      s.a += wp_derivative(2, t);
    }
    return s;
  }
  const double w = w_end_ * std::exp(-(t - t_) / kappa_);
  return {d_ + w, -w / kappa_, w / (kappa_ * kappa_)};
}

void InverseDynamicsCommand::breakpoints(std::vector<double>& out) const {
  out.push_back(0.0);
  out.push_back(t_);
  out.push_back(end_);
}

}  // namespace settle::plant
