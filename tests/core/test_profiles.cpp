// SPDX-License-Identifier: Apache-2.0
// Boundary conditions, continuity and internal consistency of every profile: the closed-form
// velocity and position must be the integrals of the closed-form acceleration (checked by
// quadrature here), and each profile must be continuous in the derivatives it is designed for.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "residual.hpp"
#include "settle/core/planner.hpp"
#include "test_helpers.hpp"

using namespace settle;
using core::ProfileKind;

namespace {

struct Case {
  const char* name;
  core::MoveRequest req;
  int continuous;  // highest derivative designed to be continuous (0 = p, 1 = v, 2 = a)
};

std::vector<Case> cases() {
  std::vector<Case> c;
  c.push_back({"scurve_4seg", test::timed(ProfileKind::scurve, 0.1, 0.3, 22.0), 2});
  auto cruise = test::timed(ProfileKind::scurve, 0.1, 0.5, 22.0);
  cruise.limits.vmax = 0.3;
  c.push_back({"scurve_cruise", cruise, 2});
  c.push_back({"scurve_overshoot", test::timed(ProfileKind::scurve, 0.1, 0.8 * 2 * M_PI / 22.0, 22.0), 2});
  c.push_back({"scurve_damped", test::timed(ProfileKind::scurve_damped, -0.2, 0.7, 15.0, 0.2), 2});
  c.push_back({"ramp_versine", test::timed(ProfileKind::ramp_versine, 1.0, 0.167, 28.2843, 0.159), 0});
  c.push_back({"poly345", test::timed(ProfileKind::poly345, 2.0, 1.0), 2});
  auto pp = test::timed(ProfileKind::pseudopoly, 15.0, 1.0);
  pp.gammas = {3.024, 4.565, 5.874};
  pp.gamma_count = 3;
  c.push_back({"pseudopoly", pp, 2});
  c.push_back({"trapezoid", test::timed(ProfileKind::trapezoid, 0.5, 1.2), 1});
  core::MoveRequest jl{};
  jl.profile = ProfileKind::jerk_limited;
  jl.distance = 0.4;
  jl.limits.vmax = 0.5;
  jl.limits.amax = 3.0;
  jl.limits.jmax = 40.0;
  c.push_back({"jerk_limited", jl, 2});
  auto shaped = test::timed(ProfileKind::jerk_limited, 0.4, 1.5, 20.0, 0.05);
  shaped.limits.vmax = 0.5;
  shaped.limits.amax = 3.0;
  shaped.limits.jmax = 40.0;
  shaped.shaper = core::ShaperKind::zvd;
  c.push_back({"jerk_limited_zvd", shaped, 2});
  return c;
}

class EveryProfile : public ::testing::TestWithParam<Case> {};

TEST_P(EveryProfile, RestsBeforeStartAndAfterEnd) {
  const auto m = test::must_plan(GetParam().req);
  const double d = GetParam().req.distance;
  for (double t : {-1.0, -1e-9, 0.0}) {
    const auto s = m.at(t);
    EXPECT_EQ(s.p, 0.0);
    if (t < 0.0 || GetParam().continuous >= 1) {
      EXPECT_EQ(s.v, 0.0) << t;
    }
  }
  for (double t : {m.duration(), m.duration() + 1e-9, m.duration() + 10.0}) {
    const auto s = m.at(t);
    EXPECT_EQ(s.p, d);
    EXPECT_EQ(s.v, 0.0);
    EXPECT_EQ(s.a, 0.0);
    EXPECT_EQ(s.j, 0.0);
  }
  // The limits from inside agree with the rest states.
  const double eps = 1e-9 * m.duration();
  // (a velocity step, as in seed 001, moves the command by v * eps within eps)
  const double tol = 1e-9 * std::fabs(d) + m.peaks().v * eps;
  EXPECT_NEAR(m.at(eps).p, 0.0, tol);
  EXPECT_NEAR(m.at(m.duration() - eps).p, d, tol);
  if (GetParam().continuous >= 1) {
    EXPECT_NEAR(m.at(m.duration() - eps).v, 0.0, 1e-6 * m.peaks().v);
  }
}

TEST_P(EveryProfile, VelocityAndPositionAreIntegralsOfAcceleration) {
  // Gauss-Legendre on panels aligned with the breakpoints integrates a (and v) accurately.
  const auto m = test::must_plan(GetParam().req);
  const test::GaussLegendre gl{10};
  const auto b = test::move_breakpoints(m);
  double v = m.at(0.0).v, p = 0.0;  // ramp-versine starts with its velocity step
  const double vscale = std::max(m.peaks().v, 1e-12);
  for (std::size_t i = 0; i + 1 < b.size(); ++i) {
    // Uniform panels, then the last one graded geometrically towards the piece's end, where a
    // pseudo-polynomial with an exponent near 3 has a weak singularity (a ~ (T - t)^(gamma - 2)).
    std::vector<double> edges;
    const int panels = 16;
    for (int k = 0; k < panels; ++k) edges.push_back(b[i] + (b[i + 1] - b[i]) * k / panels);
    double last = (b[i + 1] - b[i]) / panels;
    for (int k = 0; k < 40; ++k) edges.push_back(b[i + 1] - (last *= 0.5));
    edges.push_back(b[i + 1]);
    for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
      const double lo = edges[k], h = edges[k + 1] - edges[k];
      for (std::size_t q = 0; q < gl.x.size(); ++q) {
        const double t = lo + 0.5 * h * (gl.x[q] + 1.0);
        const auto s = m.at(t);
        v += 0.5 * h * gl.w[q] * s.a;
        p += 0.5 * h * gl.w[q] * s.v;
      }
    }
    const double te = b[i + 1];
    const auto s = m.at(te - 1e-12 * (b[i + 1] - b[i]));
    ASSERT_NEAR(v, s.v, 1e-8 * vscale) << "at t=" << te;
    ASSERT_NEAR(p, s.p, 1e-8 * std::fabs(GetParam().req.distance)) << "at t=" << te;
  }
}

TEST_P(EveryProfile, ContinuousInTheDerivativesItIsDesignedFor) {
  const auto m = test::must_plan(GetParam().req);
  const auto b = test::move_breakpoints(m);
  const double h = 1e-9 * m.duration();
  for (double t : b) {
    if (t <= 0.0 || t >= m.duration()) continue;
    const auto l = m.at(t - h), r = m.at(t + h);
    EXPECT_NEAR(l.p, r.p, 1e-7 * std::fabs(m.distance())) << "p at " << t;
    if (GetParam().continuous >= 1) {
      EXPECT_NEAR(l.v, r.v, 1e-6 * m.peaks().v) << "v at " << t;
    }
    if (GetParam().continuous >= 2) {
      EXPECT_NEAR(l.a, r.a, 1e-6 * m.peaks().a) << "a at " << t;
    }
  }
}

TEST_P(EveryProfile, ReportedPeaksAreTheTruePeaks) {
  const auto m = test::must_plan(GetParam().req);
  const core::Peaks<double> sampled = test::sampled_peaks(m, 200000);
  const double v = sampled.v, a = sampled.a, j = sampled.j;
  const auto& pk = m.peaks();
  EXPECT_LE(v, pk.v * (1 + 1e-9));
  EXPECT_GE(v, pk.v * (1 - 1e-4));  // a dense sample gets close to the true maximum
  if (std::isfinite(pk.a)) {
    EXPECT_LE(a, pk.a * (1 + 1e-9));
    EXPECT_GE(a, pk.a * (1 - 1e-4));
  }
  if (std::isfinite(pk.j)) {
    EXPECT_LE(j, pk.j * (1 + 1e-9));
    EXPECT_GE(j, pk.j * (1 - 1e-3));
  }
}

TEST_P(EveryProfile, FloatEvaluationTracksDouble) {
  const auto m = test::must_plan(GetParam().req);
  const core::Move<float> f{m};
  for (int i = 0; i <= 1000; ++i) {
    const double t = m.duration() * i / 1000.0;
    const auto sd = m.at(t);
    const auto sf = f.at(static_cast<float>(t));
    EXPECT_NEAR(sf.p, sd.p, 2e-5 * std::fabs(m.distance()) + 1e-6 * m.peaks().v) << t;
  }
}

INSTANTIATE_TEST_SUITE_P(Core, EveryProfile, ::testing::ValuesIn(cases()),
                         [](const auto& tp) { return std::string{tp.param.name}; });

TEST(ScurveClosedForms, SegmentEndValuesOfSeed000) {
  // SEEDS.md: v(t1) = A tau/2, v(t2) = A tau, d(t1) = A tau^2/6 - A2 tau^2/(4 pi^2), d(t2) = A tau^2,
  // d(t5) = A tau (T3 + 2 tau), for the undamped profile.
  auto r = test::timed(ProfileKind::scurve, 0.3, 1.0, 9.0);
  r.limits.vmax = 0.45;
  const auto m = test::must_plan(r);
  const auto* rc = std::get_if<core::RampCycloid<double>>(&m.profile().variant());
  ASSERT_NE(rc, nullptr);
  const auto& p = rc->params();
  const double a = p.amplitude, tau = p.tau, a2 = a * p.c2;
  EXPECT_NEAR(m.at(tau).v, a * tau / 2, 1e-12);
  EXPECT_NEAR(m.at(2 * tau).v, a * tau, 1e-12);
  EXPECT_NEAR(m.at(tau).p, a * tau * tau / 6 - a2 * tau * tau / (4 * M_PI * M_PI), 1e-12);
  EXPECT_NEAR(m.at(2 * tau).p, a * tau * tau, 1e-12);
  EXPECT_NEAR(a * tau * (p.cruise + 2 * tau), 0.3, 1e-12);
  EXPECT_NEAR(a * tau, 0.45, 1e-12);  // cruises at vmax
}

}  // namespace
