// SPDX-License-Identifier: Apache-2.0
#pragma once
// Test-side reference for online changes: the mode  e'' + 2 zeta w e' + w^2 e = -x''(t)  driven by a
// whole command (the running move up to the switch, then the blend), integrated by classic RK4 on
// steps aligned with every breakpoint of both. Independent of core's closed forms (docs/online.md):
// it only evaluates the command's acceleration.
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "residual.hpp"
#include "settle/core/online.hpp"

namespace settle::test {

struct ModeState {
  double e{0.0}, de{0.0};
};

// Integrates the mode over [t0, t1] of a command whose acceleration acc(t) is smooth inside it,
// with steps of at most w*dt = 0.002 and at least 400 per interval (a cycloid piece's own frequency
// can be far above the mode's). acc is sampled strictly inside the interval (by a relative
// 1e-10 of it, more than the rounding of a breakpoint shifted by a shaper's delay) so that a step in
// acceleration at either end is seen from the right side.
template <typename Acc>
void integrate(ModeState& s, double omega, double zeta, double t0, double t1, Acc&& acc) {
  if (!(t1 > t0)) return;
  const int n = std::max(400, static_cast<int>(std::ceil((t1 - t0) * omega / 0.002)));
  const double h = (t1 - t0) / n;
  const double lo = t0 + 1e-10 * (t1 - t0), hi = t1 - 1e-10 * (t1 - t0);
  auto a = [&](double t) { return acc(std::clamp(t, lo, hi)); };
  auto f = [&](double t, double e, double de, double& d1, double& d2) {
    d1 = de;
    d2 = -2.0 * zeta * omega * de - omega * omega * e - a(t);
  };
  for (int i = 0; i < n; ++i) {
    const double t = t0 + i * h;
    double k1e, k1v, k2e, k2v, k3e, k3v, k4e, k4v;
    f(t, s.e, s.de, k1e, k1v);
    f(t + h / 2, s.e + h / 2 * k1e, s.de + h / 2 * k1v, k2e, k2v);
    f(t + h / 2, s.e + h / 2 * k2e, s.de + h / 2 * k2v, k3e, k3v);
    f(t + h, s.e + h * k3e, s.de + h * k3v, k4e, k4v);
    s.e += h / 6 * (k1e + 2 * k2e + 2 * k3e + k4e);
    s.de += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
  }
}

// The mode's state at t_switch under the running move alone (from rest at 0).
inline ModeState state_at_switch(const core::Move<double>& m, double t_switch, double omega, double zeta) {
  std::vector<double> b = move_breakpoints(m);
  b.push_back(t_switch);
  std::sort(b.begin(), b.end());
  ModeState s{};
  for (std::size_t i = 0; i + 1 < b.size() && b[i] < t_switch; ++i) {
    integrate(s, omega, zeta, b[i], std::min(b[i + 1], t_switch), [&](double t) { return m.at(t).a; });
  }
  return s;
}

// Continues `s` along blend b from its start (at t0 on the command's clock) to u_end on its clock,
// segment by segment.
inline void along_blend(ModeState& s, const core::Blend& b, double t0, double u_end, double omega, double zeta) {
  const double h = b.segment_length();
  for (std::size_t k = 0; k < core::kBlendSegments; ++k) {
    const double u0 = static_cast<double>(k) * h;
    if (!(u0 < u_end)) break;
    const double u1 = std::min(u0 + h, u_end);
    integrate(s, omega, zeta, t0 + u0, t0 + u1, [&](double t) { return b.at(std::clamp(t - t0, u0, u1)).a; });
  }
}

inline double amplitude(const ModeState& s, double omega, double zeta) {
  const double wd = omega * std::sqrt(1.0 - zeta * zeta);
  return std::hypot(s.e, (s.de + zeta * omega * s.e) / wd);
}

// The mode's state at u on the blend's clock (move to t_switch, then the blend).
inline ModeState state_in_blend(const core::Move<double>& m, double t_switch, const core::Blend& b, double u,
                                double omega, double zeta) {
  ModeState s = state_at_switch(m, t_switch, omega, zeta);
  along_blend(s, b, t_switch, u, omega, zeta);
  return s;
}

// Residual amplitude of the mode once the whole command (move to t_switch, then the blend) is over.
inline double residual_after_blend(const core::Move<double>& m, double t_switch, const core::Blend& b, double omega,
                                   double zeta) {
  return amplitude(state_in_blend(m, t_switch, b, b.duration(), omega, zeta), omega, zeta);
}

// The same for a command changed twice: the move to t1, blend b1 to u2 on its clock, then b2.
inline double residual_after_blends(const core::Move<double>& m, double t1, const core::Blend& b1, double u2,
                                    const core::Blend& b2, double omega, double zeta) {
  ModeState s = state_in_blend(m, t1, b1, u2, omega, zeta);
  along_blend(s, b2, t1 + u2, b2.duration(), omega, zeta);
  return amplitude(s, omega, zeta);
}

}  // namespace settle::test
