// SPDX-License-Identifier: Apache-2.0
#pragma once
// The base motion a plant sees during one integration step: a polynomial in the local time
// s in [0, dt]. A drive's linear interpolation of setpoints, a cubic, and the quintic Hermite
// used to follow a sampled profile are all polynomials, so LinearPlant::advance is exact for them.
#include <array>

namespace settle::plant {

inline constexpr int kMaxBaseDegree = 7;

// Position, velocity and acceleration of the base at one instant.
struct BaseState {
  double p{0.0};
  double v{0.0};
  double a{0.0};
};

// y(t0 + s) = c[0] + c[1] s + ... + c[degree] s^degree.
struct BasePolynomial {
  std::array<double, kMaxBaseDegree + 1> c{};
  int degree{0};

  // The k-th derivative at local time s.
  [[nodiscard]] double derivative(int k, double s) const noexcept;
  [[nodiscard]] BaseState state(double s) const noexcept;

  // Held still at p.
  [[nodiscard]] static BasePolynomial constant(double p) noexcept;
  // From p0 to p1 at constant velocity: what a CSP drive does between two setpoints.
  [[nodiscard]] static BasePolynomial linear(double p0, double p1, double dt) noexcept;
  // Matches position and velocity at both ends.
  [[nodiscard]] static BasePolynomial cubic_hermite(double p0, double v0, double p1, double v1, double dt) noexcept;
  // Matches position, velocity and acceleration at both ends: the interpolant for sampled profiles,
  // whose error is O(dt^6) times the profile's sixth derivative.
  [[nodiscard]] static BasePolynomial quintic_hermite(const BaseState& s0, const BaseState& s1, double dt) noexcept;
};

}  // namespace settle::plant
