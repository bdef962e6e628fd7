// SPDX-License-Identifier: Apache-2.0
#pragma once
// Test-side reference for "does this move leave a mode at rest": the Duhamel integral of the
// move's acceleration against the mode's impulse response, by composite Gauss-Legendre
// quadrature on panels aligned with the profile's own breakpoints. Written independently of the
// closed forms in core so that it can catch mistakes in them.
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "settle/core/move.hpp"

namespace settle::test {

// Gauss-Legendre nodes and weights on [-1, 1], computed by Newton's method on P_n.
struct GaussLegendre {
  std::vector<double> x, w;
  explicit GaussLegendre(int n) {
    for (int i = 1; i <= n; ++i) {
      double z = std::cos(M_PI * (i - 0.25) / (n + 0.5));
      double dp = 0.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::fabs(dz) < 1e-16) break;
      }
      x.push_back(z);
      w.push_back(2.0 / ((1.0 - z * z) * dp * dp));
    }
  }
};

inline std::vector<double> profile_breakpoints(const core::Profile<double>& prof) {
  std::vector<double> b{0.0};
  prof.visit([&](const auto& p) {
    using P = std::decay_t<decltype(p)>;
    if constexpr (std::is_same_v<P, core::RampCycloid<double>>) {
      for (int k = 1; k < 5; ++k) b.push_back(p.segment(k).start);
    } else if constexpr (std::is_same_v<P, core::PiecewiseJerk<double>>) {
      double t = 0.0;
      for (std::size_t i = 0; i < p.params().count; ++i) b.push_back(t += p.params().durations[i]);
    } else if constexpr (requires { p.piece_count(); }) {
      for (int i = 1; i < p.piece_count(); ++i) b.push_back(p.piece(i).start);
    }
    b.push_back(p.duration());
  });
  return b;
}

inline std::vector<double> move_breakpoints(const core::Move<double>& m) {
  const std::vector<double> pb = profile_breakpoints(m.profile());
  std::vector<double> b;
  for (std::size_t i = 0; i < m.shaper().count; ++i) {
    for (double t : pb) b.push_back(t + m.shaper().time[i]);
  }
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end(), [](double x, double y) { return std::fabs(x - y) < 1e-13; }), b.end());
  return b;
}

// Residual vibration amplitude of the mode e'' + 2 zeta w e' + w^2 e = -(base acceleration)
// once the move is over: |I| / wd, I = int a(s) e^{(zeta w - i wd)(s - T)} ds, plus the
// Dirac terms of any velocity step at the profile's ends.
inline double residual_amplitude(const core::Move<double>& m, double omega, double zeta, int panels_per_piece = 24) {
  static const GaussLegendre gl{12};
  const double wd = omega * std::sqrt(1.0 - zeta * zeta);
  const std::complex<double> k{zeta * omega, -wd};
  const std::vector<double> b = move_breakpoints(m);
  // The kernel is referred to the end (e^{k (s - t_end)}, magnitude <= 1), so that long moves on
  // damped modes do not overflow; the amplitude is then |I| / wd with no decay factor left.
  const double t_end = b.back();
  std::complex<double> acc{0.0, 0.0};
  for (std::size_t i = 0; i + 1 < b.size(); ++i) {
    const double h = (b[i + 1] - b[i]) / panels_per_piece;
    for (int p = 0; p < panels_per_piece; ++p) {
      const double lo = b[i] + p * h;
      for (std::size_t q = 0; q < gl.x.size(); ++q) {
        const double s = lo + 0.5 * h * (gl.x[q] + 1.0);
        acc += 0.5 * h * gl.w[q] * m.at(s).a * std::exp(k * (s - t_end));
      }
    }
  }
  // Velocity steps (seed 001) are acceleration impulses: dv * K(t) at each.
  if (m.peaks().velocity_step) {
    for (std::size_t i = 0; i < m.shaper().count; ++i) {
      const double t0 = m.shaper().time[i];
      const double t1 = t0 + m.profile().duration();
      const double w = m.shaper().amp[i];
      acc += w * m.profile().at(t0 - t0).v * std::exp(k * (t0 - t_end));
      acc -= w * m.profile().at(std::nextafter(m.profile().duration(), 0.0)).v * std::exp(k * (t1 - t_end));
    }
  }
  return std::abs(acc) / wd;
}

}  // namespace settle::test
