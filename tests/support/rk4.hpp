// SPDX-License-Identifier: Apache-2.0
#pragma once
// Test-side reference integrator: classical RK4 for one second-order equation x'' = f(t, x, x')
// from rest. Deliberately unlike the simulator (no exponentials, no polynomial pieces), so that
// agreement between the two means something.
#include <array>

namespace settle::test {

// Calls observe(t, x, v) after every step.
template <typename F, typename Observe>
std::array<double, 2> rk4_observed(F f, double t_end, int steps, Observe observe) {
  double x = 0.0, v = 0.0;
  const double h = t_end / steps;
  for (int i = 0; i < steps; ++i) {
    const double t = i * h;
    const double k1x = v, k1v = f(t, x, v);
    const double k2x = v + 0.5 * h * k1v, k2v = f(t + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v);
    const double k3x = v + 0.5 * h * k2v, k3v = f(t + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v);
    const double k4x = v + h * k3v, k4v = f(t + h, x + h * k3x, v + h * k3v);
    x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    observe((i + 1) * h, x, v);
  }
  return {x, v};
}

template <typename F>
std::array<double, 2> rk4(F f, double t_end, int steps) {
  return rk4_observed(f, t_end, steps, [](double, double, double) {});
}

}  // namespace settle::test
