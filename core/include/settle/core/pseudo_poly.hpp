// SPDX-License-Identifier: Apache-2.0
#pragma once
// Pseudo-polynomial motion command of seed 004 (Incerti):
//   phi(t) = D [1 - sum_i C_i (1 - t/T)^gamma_i],  Z c = e0,  Z[k][i] = gamma_i (gamma_i-1)...(gamma_i-k+1)
// n + 1 exponents make position and its first n derivatives vanish at t = 0. The 3-4-5
// polynomial is gamma = (3, 4, 5), C = (10, -15, 6).
#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "settle/core/kinematics.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

inline constexpr std::size_t kMaxGammas = 8;

struct PseudoPolyParams {
  double distance{0.0};
  double duration{0.0};
  std::size_t count{0};
  std::array<double, kMaxGammas> gammas{};
  std::array<double, kMaxGammas> coeffs{};
};

// Solves the Z system for the given exponents. On failure `out` is untouched.
[[nodiscard]] Status pseudo_poly_design(double distance, double duration, const double* gammas,
                                        std::size_t count, PseudoPolyParams& out) noexcept;
// Peaks of the unit shape (D = 1, T = 1): |phi'|, |phi''|, |phi'''| maxima over [0, 1].
[[nodiscard]] Peaks<double> pseudo_poly_unit_peaks(const PseudoPolyParams& p) noexcept;
[[nodiscard]] Peaks<double> pseudo_poly_peaks(const PseudoPolyParams& p) noexcept;

template <typename T>
class PseudoPoly {
 public:
  using Params = PseudoPolyParams;
  PseudoPoly() = default;
  explicit PseudoPoly(const PseudoPolyParams& p) noexcept
      : params_{p}, d_{static_cast<T>(p.distance)}, dur_{static_cast<T>(p.duration)}, n_{p.count} {
    inv_t_ = static_cast<T>(p.duration > 0.0 ? 1.0 / p.duration : 0.0);
    for (std::size_t i = 0; i < n_; ++i) {
      const double g = p.gammas[i];
      const double c = p.coeffs[i];
      g_[i] = static_cast<T>(g);
      c0_[i] = static_cast<T>(c);
      c1_[i] = static_cast<T>(c * g);
      c2_[i] = static_cast<T>(c * g * (g - 1.0));
      c3_[i] = static_cast<T>(c * g * (g - 1.0) * (g - 2.0));
    }
  }
  template <typename U>
  explicit PseudoPoly(const PseudoPoly<U>& o) noexcept : PseudoPoly(o.params()) {}
  // From double: the double evaluator's values rounded to T, which is what the Params constructor
  // computes (each value in double, rounded once), without double arithmetic.
  template <typename U>
    requires std::is_same_v<U, double>
  explicit PseudoPoly(const PseudoPoly<U>& o) noexcept
      : params_{o.params_}, d_{static_cast<T>(o.d_)}, dur_{static_cast<T>(o.dur_)}, inv_t_{static_cast<T>(o.inv_t_)},
        n_{o.n_} {
    for (std::size_t i = 0; i < n_; ++i) {
      g_[i] = static_cast<T>(o.g_[i]);
      c0_[i] = static_cast<T>(o.c0_[i]);
      c1_[i] = static_cast<T>(o.c1_[i]);
      c2_[i] = static_cast<T>(o.c2_[i]);
      c3_[i] = static_cast<T>(o.c3_[i]);
    }
  }

  [[nodiscard]] const PseudoPolyParams& params() const noexcept { return params_; }
  [[nodiscard]] T duration() const noexcept { return dur_; }
  [[nodiscard]] T distance() const noexcept { return d_; }

  // Its parameters as named numbers, as `settle plan` and Python's plan() report them: f(name, i, value)
  // per number, where a '#' in the name stands for i (a per-segment or per-exponent number).
  template <typename F>
  void for_each_param(F&& f) const {
    for (std::size_t i = 0; i < params_.count; ++i) f("gamma#", i, params_.gammas[i]);
    for (std::size_t i = 0; i < params_.count; ++i) f("C#", i, params_.coeffs[i]);
  }

  [[nodiscard]] Sample<T> at(T t) const noexcept {
    if (!(t > T(0))) return {};
    if (t >= dur_) return {d_, T(0), T(0), T(0)};
    const T w = T(1) - t * inv_t_;
    const T iw = T(1) / w;
    T p{}, v{}, a{}, j{};
    for (std::size_t i = 0; i < n_; ++i) {
      const T wg = std::pow(w, g_[i]);
      p += c0_[i] * wg;
      v += c1_[i] * wg;
      a += c2_[i] * wg;
      j += c3_[i] * wg;
    }
    const T k1 = d_ * inv_t_ * iw;
    const T k2 = k1 * inv_t_ * iw;
    return {d_ - d_ * p, k1 * v, -k2 * a, k2 * inv_t_ * iw * j};
  }

 private:
  template <typename>
  friend class PseudoPoly;
  PseudoPolyParams params_{};
  T d_{}, dur_{}, inv_t_{};
  std::size_t n_{0};
  std::array<T, kMaxGammas> g_{}, c0_{}, c1_{}, c2_{}, c3_{};
};

}  // namespace settle::core
