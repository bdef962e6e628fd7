// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/base_motion.hpp"

namespace settle::plant {

double BasePolynomial::derivative(int k, double s) const noexcept {
  // Horner on the k-th derivative's coefficients c[i] * i!/(i-k)!.
  double acc = 0.0;
  for (int i = degree; i >= k; --i) {
    double f = 1.0;
    for (int r = 0; r < k; ++r) f *= static_cast<double>(i - r);
    acc = acc * s + f * c[static_cast<std::size_t>(i)];
  }
  return acc;
}

BaseState BasePolynomial::state(double s) const noexcept {
  // One Horner pass for all three: the per-step cost of a simulated drive.
  double p = 0.0, v = 0.0, a = 0.0;
  for (int i = degree; i >= 0; --i) {
    const double ci = c[static_cast<std::size_t>(i)];
    a = a * s + 2.0 * v;
    v = v * s + p;
    p = p * s + ci;
  }
  return {p, v, a};
}

BasePolynomial BasePolynomial::constant(double p) noexcept {
  BasePolynomial b{};
  b.c[0] = p;
  return b;
}

BasePolynomial BasePolynomial::linear(double p0, double p1, double dt) noexcept {
  BasePolynomial b{};
  b.c[0] = p0;
  b.c[1] = (p1 - p0) / dt;
  b.degree = 1;
  return b;
}

BasePolynomial BasePolynomial::cubic_hermite(double p0, double v0, double p1, double v1, double dt) noexcept {
  BasePolynomial b{};
  const double r0 = p1 - p0 - v0 * dt;
  const double r1 = (v1 - v0) * dt;
  b.c[0] = p0;
  b.c[1] = v0;
  b.c[2] = (3.0 * r0 - r1) / (dt * dt);
  b.c[3] = (r1 - 2.0 * r0) / (dt * dt * dt);
  b.degree = 3;
  return b;
}

BasePolynomial BasePolynomial::quintic_hermite(const BaseState& s0, const BaseState& s1, double dt) noexcept {
  BasePolynomial b{};
  const double h2 = dt * dt;
  const double h3 = h2 * dt;
  // Residuals at s = dt of the quadratic Taylor part, then the 3x3 solve in closed form
  // (unknowns c3 h^3, c4 h^4, c5 h^5).
  const double r0 = s1.p - (s0.p + s0.v * dt + 0.5 * s0.a * h2);
  const double r1 = (s1.v - (s0.v + s0.a * dt)) * dt;
  const double r2 = (s1.a - s0.a) * h2;
  b.c[0] = s0.p;
  b.c[1] = s0.v;
  b.c[2] = 0.5 * s0.a;
  b.c[3] = (10.0 * r0 - 4.0 * r1 + 0.5 * r2) / h3;
  b.c[4] = (-15.0 * r0 + 7.0 * r1 - r2) / (h3 * dt);
  b.c[5] = (6.0 * r0 - 3.0 * r1 + 0.5 * r2) / (h3 * h2);
  b.degree = 5;
  return b;
}

}  // namespace settle::plant
