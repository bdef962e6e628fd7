// SPDX-License-Identifier: Apache-2.0
// The planner's exact peaks of shaped moves (core/src/shaped_peaks.cpp, per-interval roots of the
// derivatives) and of pseudo-polynomials (core/src/pseudo_poly.cpp, Rolle's ladder), against an
// independent method: the move sampled densely (1e5 points) through Move::at, every local maximum
// refined by golden-section search. Over a seeded grid of every profile x ZV, ZVD, EI and damped
// shapers, and on moves whose peak lies strictly inside an interval between breakpoints, where
// looking at breakpoints only would miss it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "settle/core/planner.hpp"

using namespace settle;
using core::ProfileKind;
using core::ShaperKind;

namespace {

// max |q(t)| over [0, T] for q = v, a or j of Move::at: 1e5 cells, golden section around each
// local maximum of the scan.
template <typename Q>
double sampled_max(const core::Move<double>& m, Q q) {
  constexpr std::size_t kCells = 100000;
  const double t1 = m.duration();
  const auto f = [&](double t) { return std::fabs(q(m.at(t))); };
  const auto x = [&](std::size_t i) { return t1 * static_cast<double>(i) / static_cast<double>(kCells); };
  std::vector<double> y(kCells + 1);
  for (std::size_t i = 0; i <= kCells; ++i) y[i] = f(x(i));
  double best = *std::max_element(y.begin(), y.end());
  for (std::size_t i = 1; i < kCells; ++i) {
    if (!(y[i] > y[i - 1] && y[i] >= y[i + 1])) continue;  // plateaus need no refining
    double lo = x(i - 1), hi = x(i + 1);
    constexpr double g = 0.6180339887498948482;
    for (int it = 0; it < 80; ++it) {
      const double c = hi - g * (hi - lo), d = lo + g * (hi - lo);
      const double fc = f(c), fd = f(d);
      best = std::max({best, fc, fd});
      if (fc > fd) {
        hi = d;
      } else {
        lo = c;
      }
    }
  }
  return best;
}

struct Sampled {
  double v, a, j;
};
Sampled sampled_peaks(const core::Move<double>& m) {
  return {sampled_max(m, [](const core::Sample<double>& s) { return s.v; }),
          sampled_max(m, [](const core::Sample<double>& s) { return s.a; }),
          sampled_max(m, [](const core::Sample<double>& s) { return s.j; })};
}

void expect_close(double exact, double sampled, const char* what, const char* where) {
  if (!std::isfinite(exact)) return;  // a Dirac: reported as such, not sampled
  EXPECT_NEAR(exact, sampled, 1e-9 * std::max(sampled, 1e-300)) << what << " " << where;
}

struct ShaperCase {
  ShaperKind kind;
  double zeta;
  const char* name;
};

}  // namespace

TEST(ExactPeaks, ShapedPeaksEqualDenseSamplingForEveryProfileAndShaper) {
  std::mt19937 rng{16};
  std::uniform_real_distribution<double> scale(0.5, 2.0), omega(6.0, 60.0);
  const ShaperCase shapers[] = {{ShaperKind::zv, 0.0, "zv"},
                                {ShaperKind::zvd, 0.0, "zvd"},
                                {ShaperKind::ei, 0.0, "ei"},
                                {ShaperKind::zvd, 0.12, "zvd damped"},
                                {ShaperKind::ei, 0.08, "ei damped"}};
  int checked = 0;
  core::for_each_profile([&](auto kind) {
    using P = core::profile_t<kind.value>;
    if (kind.value != ProfileKind::scurve && kind.value != ProfileKind::scurve_damped &&
        kind.value != ProfileKind::ramp_versine && kind.value != ProfileKind::poly345 &&
        kind.value != ProfileKind::pseudopoly && kind.value != ProfileKind::trapezoid &&
        kind.value != ProfileKind::jerk_limited) {
      return;  // fastest: planned in milliseconds, covered by its own suite
    }
    for (const ShaperCase& sc : shapers) {
      for (int rep = 0; rep < 3; ++rep) {
        core::MoveRequest r = P::example();
        r.profile = kind.value;
        r.distance *= scale(rng);
        if (r.time) *r.time *= scale(rng);
        r.set_mode(omega(rng), std::max(r.zeta(), sc.zeta));
        r.shaper = sc.kind;
        if (rep == 2 && kind.value == ProfileKind::pseudopoly) {
          r.gammas = {3.0, 4.0, 5.0, 6.0};  // integer exponents: the exact polynomial path
        }
        core::Move<double> m{};
        ASSERT_EQ(core::plan(r, m), core::Status::ok) << P::name << " " << sc.name;
        const Sampled s = sampled_peaks(m);
        expect_close(m.peaks().v, s.v, "v", P::name);
        expect_close(m.peaks().a, s.a, "a", P::name);
        expect_close(m.peaks().j, s.j, "j", P::name);
        ++checked;
      }
    }
  });
  EXPECT_EQ(checked, 7 * 5 * 3);
}

TEST(ExactPeaks, PseudoPolynomialPeaksEqualDenseSampling) {
  std::mt19937 rng{4};
  std::uniform_real_distribution<double> gap(0.3, 2.5);
  for (int rep = 0; rep < 12; ++rep) {
    core::MoveRequest r{};
    r.profile = ProfileKind::pseudopoly;
    r.distance = 0.7;
    r.time = 0.9;
    r.gamma_count = 3 + static_cast<std::size_t>(rep % 4);
    double g = 3.0 + 0.5 * gap(rng);
    for (std::size_t i = 0; i < r.gamma_count; ++i, g += gap(rng)) r.gammas[i] = g;
    core::Move<double> m{};
    ASSERT_EQ(core::plan(r, m), core::Status::ok) << rep;
    const Sampled s = sampled_peaks(m);
    expect_close(m.peaks().v, s.v, "v", "pseudopoly");
    expect_close(m.peaks().a, s.a, "a", "pseudopoly");
    expect_close(m.peaks().j, s.j, "j", "pseudopoly");
  }
}

// The peak is inside an interval between breakpoints: every merged breakpoint (profile pieces
// shifted by every impulse) is at least 1 % below it, so a breakpoints-only method would fail:
// poly345 through ZV (velocity; one polynomial piece, 4.4 % above its breakpoints) and the
// ramp-cycloid S-curve through ZV (acceleration; polynomial + phasor pieces, 30 % above).
TEST(ExactPeaks, FindsAPeakStrictlyInsideAnInterval) {
  core::MoveRequest poly = core::Poly345Profile::example();
  poly.shaper = ShaperKind::zv;
  poly.set_mode(20.0);
  core::MoveRequest cyc = core::ScurveProfile::example();
  cyc.shaper = ShaperKind::zv;
  for (const auto& [r, which] : {std::pair{poly, 0}, std::pair{cyc, 1}}) {
    core::Move<double> m{};
    ASSERT_EQ(core::plan(r, m), core::Status::ok);
    const auto q = [which](const core::Sample<double>& s) { return which == 0 ? s.v : which == 1 ? s.a : s.j; };
    const double exact = which == 0 ? m.peaks().v : which == 1 ? m.peaks().a : m.peaks().j;
    EXPECT_NEAR(exact, sampled_max(m, q), 1e-9 * exact);
    // The breakpoints: each piece boundary of the profile, shifted by each impulse, both sides.
    std::vector<double> bounds;
    m.profile().visit([&](const auto& shape) {
      if constexpr (requires { shape.piece_count(); }) {
        for (int k = 0; k < shape.piece_count(); ++k) bounds.push_back(shape.piece(k).start);
      } else {
        bounds.push_back(0.0);
      }
    });
    bounds.push_back(m.profile().duration());
    double at_breaks = 0.0;
    for (std::size_t i = 0; i < m.shaper().count; ++i) {
      for (double b : bounds) {
        for (double eps : {-1e-12, 0.0, 1e-12}) {
          at_breaks = std::max(at_breaks, std::fabs(q(m.at(m.shaper().time[i] + b + eps))));
        }
      }
    }
    EXPECT_LT(at_breaks, 0.99 * exact) << which;
  }
}
