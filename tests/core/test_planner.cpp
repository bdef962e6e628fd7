// SPDX-License-Identifier: Apache-2.0
// Planner contract: specific codes for bad requests, output untouched on failure, limits
// respected, and the fastest vibration-free move compared with its alternatives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <variant>

#include "residual.hpp"
#include "test_helpers.hpp"

using namespace settle;
using core::ProfileKind;
using core::Status;

namespace {

core::MoveRequest good_scurve() { return test::timed(ProfileKind::scurve, 0.1, 0.4, 22.0); }

void expect_rejected(const core::MoveRequest& r, Status expected) {
  core::Move<double> m = test::must_plan(test::timed(ProfileKind::poly345, 3.0, 2.0));
  const double d0 = m.duration(), p0 = m.at(0.7).p;
  EXPECT_EQ(core::plan(r, m), expected) << core::to_string(expected);
  EXPECT_EQ(m.duration(), d0);
  EXPECT_EQ(m.at(0.7).p, p0);
}

TEST(Planner, RejectsEachBadRequestWithItsOwnCode) {
  auto r = good_scurve();
  r.distance = NAN;
  expect_rejected(r, Status::non_finite_input);
  r = good_scurve();
  r.time = INFINITY;
  expect_rejected(r, Status::non_finite_input);
  r = good_scurve();
  r.time = -0.1;
  expect_rejected(r, Status::non_positive_time);
  r = good_scurve();
  r.time = 0.0;
  expect_rejected(r, Status::non_positive_time);
  r = good_scurve();
  r.modes[0].omega = 0.0;
  expect_rejected(r, Status::non_positive_omega);
  r = good_scurve();
  r.mode_count = 0;
  expect_rejected(r, Status::non_positive_omega);
  r = good_scurve();
  r.modes[0].zeta = 1.0;
  expect_rejected(r, Status::zeta_out_of_range);
  r = good_scurve();
  r.modes[0].zeta = -0.01;
  expect_rejected(r, Status::zeta_out_of_range);
  r = good_scurve();
  r.limits.vmax = 0.25;  // D/vmax = 0.4 = T
  expect_rejected(r, Status::time_too_short_for_vmax);
  r = good_scurve();
  r.limits.vmax = -1;
  expect_rejected(r, Status::non_positive_limit);
  r = good_scurve();
  r.limits.amax = 1.0;  // needs ~5 m/s^2
  expect_rejected(r, Status::acceleration_limit_exceeded);
  r = good_scurve();
  r.limits.jmax = 10.0;
  expect_rejected(r, Status::jerk_limit_exceeded);
  r = good_scurve();
  r.limits.vmax = 0.3;
  r.time.reset();
  expect_rejected(r, Status::missing_time_or_limits);

  auto p = test::timed(ProfileKind::pseudopoly, 1.0, 1.0);
  p.gammas = {3.0, 2.0, 5.0};
  p.gamma_count = 3;
  expect_rejected(p, Status::gamma_too_small);
  p.gammas = {3.0, 4.0, 3.0};
  expect_rejected(p, Status::gammas_not_distinct);
  p.gamma_count = 1;
  expect_rejected(p, Status::too_few_gammas);
  p.gamma_count = 9;
  expect_rejected(p, Status::too_many_gammas);

  auto y = test::timed(ProfileKind::ramp_versine, 1.0, 0.5);
  y.y_fractions = std::array<double, 3>{0.5, 0.5, 0.5};
  expect_rejected(y, Status::bad_shape_parameter);
  auto e = good_scurve();
  e.shaper = core::ShaperKind::ei;
  e.vtol = 0.9;
  expect_rejected(e, Status::vtol_out_of_range);
  auto v = test::timed(ProfileKind::ramp_versine, 1.0, 0.5, 28.0, 0.1);
  v.limits.amax = 100.0;  // its velocity steps are acceleration impulses: no finite limit holds
  expect_rejected(v, Status::acceleration_limit_exceeded);
}

// validate() tests every number of a request at once (the sum of x * 0 is NaN when any x is not
// finite): each field, with NaN and with either infinity, and whether or not the profile reads it,
// is refused as non-finite before any other check; numbers past gamma_count are not the request's.
TEST(Planner, EveryNonFiniteNumberIsRefusedBeforeAnythingElse) {
  using Edit = void (*)(core::MoveRequest&, double);
  const std::pair<const char*, Edit> fields[] = {
      {"distance", [](core::MoveRequest& r, double x) { r.distance = x; }},
      {"time", [](core::MoveRequest& r, double x) { r.time = x; }},
      {"vmax", [](core::MoveRequest& r, double x) { r.limits.vmax = x; }},
      {"amax", [](core::MoveRequest& r, double x) { r.limits.amax = x; }},
      {"jmax", [](core::MoveRequest& r, double x) { r.limits.jmax = x; }},
      {"omega", [](core::MoveRequest& r, double x) { r.set_mode(x, r.zeta()); }},
      {"zeta", [](core::MoveRequest& r, double x) { r.set_mode(r.omega(), x); }},
      {"vtol", [](core::MoveRequest& r, double x) { r.vtol = x; }},
      {"y_fractions[2]", [](core::MoveRequest& r, double x) { r.y_fractions = std::array<double, 3>{0.5, 0.25, x}; }},
      {"gammas[2]", [](core::MoveRequest& r, double x) {
         r.gammas = {3.0, 4.0, x};
         r.gamma_count = 3;
       }},
  };
  core::MoveRequest limited{};  // the benchmarks' jerk-limited move (bench_request.hpp)
  limited.profile = ProfileKind::jerk_limited;
  limited.distance = 0.1;
  limited.limits.vmax = 0.5;
  limited.limits.amax = 5.0;
  limited.limits.jmax = 100.0;
  for (const core::MoveRequest& base : {limited, good_scurve()}) {
    for (const auto& [name, edit] : fields) {
      for (const double bad : {NAN, INFINITY, -INFINITY}) {
        core::MoveRequest r = base;
        edit(r, bad);
        SCOPED_TRACE(std::string(core::to_string(base.profile)) + ", " + name + " = " + std::to_string(bad));
        expect_rejected(r, Status::non_finite_input);
        r.limits.vmax = -1.0;  // not positive either: non-finite still comes first
        if (std::string(name) != "vmax") expect_rejected(r, Status::non_finite_input);
      }
    }
  }
  // A gamma past the count is not read.
  auto p = test::timed(ProfileKind::pseudopoly, 1.0, 1.0);
  p.gammas = {3.0, 4.0, 5.0, NAN};
  p.gamma_count = 3;
  core::Move<double> m{};
  EXPECT_EQ(core::plan(p, m), Status::ok);
}

TEST(Planner, ZeroDistanceIsATrivialMove) {
  for (auto k : {ProfileKind::scurve, ProfileKind::poly345, ProfileKind::trapezoid}) {
    auto r = test::timed(k, 0.0, 1.0, 10.0);
    core::Move<double> m{};
    ASSERT_EQ(core::plan(r, m), Status::ok);
    EXPECT_EQ(m.duration(), 0.0);
    EXPECT_EQ(m.at(0.5).p, 0.0);
    EXPECT_EQ(m.peaks().v, 0.0);
  }
}

TEST(Planner, NegativeDistanceMirrorsPositive) {
  for (auto k : {ProfileKind::scurve, ProfileKind::scurve_damped, ProfileKind::ramp_versine, ProfileKind::poly345,
                 ProfileKind::trapezoid}) {
    const auto a = test::must_plan(test::timed(k, 0.3, 0.9, 12.0, 0.1));
    const auto b = test::must_plan(test::timed(k, -0.3, 0.9, 12.0, 0.1));
    for (int i = 0; i <= 20; ++i) {
      const double t = 0.9 * i / 20;
      EXPECT_NEAR(a.at(t).p, -b.at(t).p, 1e-15) << core::to_string(k);
      EXPECT_NEAR(a.at(t).a, -b.at(t).a, 1e-12) << core::to_string(k);
    }
  }
}

TEST(Planner, JerkLimitedIsTimeOptimalAndStretchesToAGivenTime) {
  core::MoveRequest r{};
  r.profile = ProfileKind::jerk_limited;
  r.distance = 1.0;
  r.limits.vmax = 1.0;
  r.limits.amax = 2.0;
  r.limits.jmax = 10.0;
  const auto m = test::must_plan(r);
  // Textbook: tj = a/j = 0.2, ta = tj + v/a = 0.7, tv = D/v - ta = 0.3, T = 2 ta + tv = 1.7.
  EXPECT_NEAR(m.duration(), 1.7, 1e-12);
  EXPECT_NEAR(m.peaks().v, 1.0, 1e-12);
  EXPECT_NEAR(m.peaks().a, 2.0, 1e-12);
  r.time = 2.5;
  const auto s = test::must_plan(r);
  EXPECT_NEAR(s.duration(), 2.5, 1e-9);
  r.time = 1.6;
  core::Move<double> out{};
  EXPECT_EQ(core::plan(r, out), Status::jerk_limit_exceeded);
}

// plan() takes the jerk-limited peaks from the phases (cruise velocity, plateau acceleration,
// jmax) instead of walking the table. Both walks must agree with them in every regime (vmax and
// amax reached or not, stretched to a time, negative distance): the table's own peaks, and the
// move sampled densely (the velocity peak lies on a flat cruise or at a = 0, where sampling is
// accurate to second order).
TEST(Planner, JerkLimitedPeaksFromThePhasesAreTheTablesAndTheSampledOnes) {
  struct Case {
    double d, v, a, j;
    std::optional<double> time;
  };
  const Case cases[] = {
      {1.0, 1.0, 2.0, 10.0, {}},   // vmax and amax reached
      {0.05, 1.0, 2.0, 10.0, {}},  // neither: d = 2 j tj^3
      {0.3, 1.0, 2.0, 10.0, {}},   // amax reached, vmax not
      {1.0, 0.3, 2.0, 10.0, {}},   // vmax reached before amax: v j < a^2
      {-0.7, 0.8, 3.0, 40.0, {}},  // negative distance
      {1.0, 1.0, 2.0, 10.0, 2.5},  // stretched to a time
      {-0.2, 0.5, 1.0, 5.0, 1.9},
  };
  for (const Case& c : cases) {
    core::MoveRequest r{};
    r.profile = ProfileKind::jerk_limited;
    r.distance = c.d;
    r.limits.vmax = c.v;
    r.limits.amax = c.a;
    r.limits.jmax = c.j;
    r.time = c.time;
    const auto m = test::must_plan(r);
    const auto& table = std::get<core::PiecewiseJerk<double>>(m.profile().variant()).params();
    const core::Peaks<double> walked = core::piecewise_peaks(table);
    EXPECT_NEAR(m.peaks().v, walked.v, 1e-12 * c.v) << c.d;
    EXPECT_NEAR(m.peaks().a, walked.a, 1e-12 * c.a) << c.d;
    EXPECT_EQ(m.peaks().j, walked.j) << c.d;
    EXPECT_FALSE(m.peaks().acceleration_step);
    const int n = 200000;
    const core::Peaks<double> sampled = test::sampled_peaks(m, n);
    EXPECT_NEAR(m.peaks().v, sampled.v, 1e-8 * c.v) << c.d;
    EXPECT_NEAR(m.peaks().a, sampled.a, c.j * m.duration() / n) << c.d;  // a peak between two samples
    EXPECT_EQ(m.peaks().j, sampled.j) << c.d;
  }
}

TEST(Planner, FastestScurveRespectsEveryLimitAndLeavesTheModeAtRest) {
  for (double omega : {5.0, 22.04871, 80.0}) {
    for (double zeta : {0.0, 0.1}) {
      core::RampCycloidParams p{};
      ASSERT_EQ(core::plan_fastest_scurve(0.1, 1.0, 20.0, 800.0, omega, zeta, zeta > 0, p), Status::ok);
      const auto pk = core::ramp_cycloid_peaks(p);
      EXPECT_LE(pk.v, 1.0 * (1 + 1e-9));
      EXPECT_LE(pk.a, 20.0 * (1 + 1e-9));
      EXPECT_LE(pk.j, 800.0 * (1 + 1e-9));
      const core::Move<double> m{core::Profile<double>{ProfileKind::scurve_damped, core::RampCycloid<double>{p}},
                                 core::Shaper<double>{}, pk};
      EXPECT_LE(test::residual_amplitude(m, omega, zeta), 1e-9 * 0.1);
      // Optimality: no feasible plan on a grid of (tau, V) is shorter.
      const double t_best = 4 * p.tau + p.cruise;
      for (double tau = 0.002; tau < 0.2; tau *= 1.05) {
        const auto w = core::cycloid_weights(tau, omega, zeta);
        const auto u = core::ramp_cycloid_peaks({1, 1, 0, 1, w.c2, w.c3});
        const double v = std::min({1.0 / u.v, 20.0 * tau / u.a, 800.0 * tau * tau / u.j, 0.1 / (2 * tau)});
        EXPECT_GE(0.1 / v + 2 * tau, t_best * (1 - 1e-6)) << "omega=" << omega << " tau=" << tau;
      }
    }
  }
}

TEST(Planner, FastestVibrationFreeMoveAgainstShapedJerkLimited) {
  // The comparison of the issue: shortest move that is both feasible and vibration-free.
  const double d = 0.1, vmax = 1.0, amax = 20.0, jmax = 800.0;
  std::printf("omega   scurve(s)  jerk-limited(s)  +ZV(s)  +ZVD(s)\n");
  for (double omega : {5.0, 22.04871, 80.0}) {
    core::MoveRequest r{};
    r.profile = ProfileKind::scurve;
    r.distance = d;
    r.limits.vmax = vmax;
    r.limits.amax = amax;
    r.limits.jmax = jmax;
    r.set_mode(omega);
    const auto fast = test::must_plan(r);
    r.profile = ProfileKind::jerk_limited;
    const auto jl = test::must_plan(r);
    r.shaper = core::ShaperKind::zv;
    const auto zv = test::must_plan(r);
    r.shaper = core::ShaperKind::zvd;
    const auto zvd = test::must_plan(r);
    std::printf("%6.2f  %9.4f  %15.4f  %6.4f  %7.4f\n", omega, fast.duration(), jl.duration(), zv.duration(),
                zvd.duration());
    // The ZVD-shaped move is as robust as we want to compare against; ours must never be slower.
    EXPECT_LE(fast.duration(), zvd.duration() * (1 + 1e-9)) << omega;
    EXPECT_GE(fast.duration(), jl.duration() * (1 - 1e-9)) << omega;  // the unshaped time-optimal bound
  }
}

}  // namespace

// plan() writes its Move in place (Move::assign): the same move as the constructor builds from the
// same profile, shaper and peaks, for every profile, shaped or not, over an output that held a
// different move before (entries past the shaper's count are not part of the move).
TEST(Planner, InPlaceMoveEqualsTheConstructedOne) {
  core::for_each_profile([&](auto kind) {
    using P = core::profile_t<kind.value>;
    if (kind.value == ProfileKind::fastest) return;  // planned in milliseconds; its own suite
    for (auto s : {core::ShaperKind::none, core::ShaperKind::zvd}) {
      core::MoveRequest r = P::example();
      r.profile = kind.value;
      r.shaper = s;
      if (!r.has_mode()) r.set_mode(25.0);
      core::Move<double> m = test::must_plan(test::timed(ProfileKind::scurve, 0.2, 0.6, 20.0));
      {
        core::MoveRequest ei = core::ScurveProfile::example();
        ei.shaper = core::ShaperKind::ei;  // leaves 3+ impulses behind in m
        ASSERT_EQ(core::plan(ei, m), Status::ok);
      }
      ASSERT_EQ(core::plan(r, m), Status::ok) << P::name;
      // The same move built the old way: a Profile from the shape's parameters, then the Move's
      // constructor; and the same request planned into a fresh Move.
      using Shape = typename P::template Shape<double>;
      const Shape* shape = std::get_if<Shape>(&m.profile().variant());
      ASSERT_NE(shape, nullptr) << P::name;
      const core::Move<double> c{core::Profile<double>{kind.value, Shape{shape->params()}}, m.shaper(), m.peaks()};
      core::Move<double> fresh{};
      ASSERT_EQ(core::plan(r, fresh), Status::ok) << P::name;
      EXPECT_EQ(m.profile().kind(), kind.value);
      EXPECT_EQ(m.duration(), c.duration()) << P::name;
      EXPECT_EQ(m.distance(), c.distance()) << P::name;
      EXPECT_EQ(m.duration(), fresh.duration()) << P::name;
      EXPECT_EQ(m.peaks().v, fresh.peaks().v) << P::name;
      EXPECT_EQ(m.shaper().count, s == core::ShaperKind::none ? 1U : 3U) << P::name;
      for (std::size_t i = 0; i < m.shaper().count; ++i) {
        EXPECT_EQ(m.shaper().amp[i], fresh.shaper().amp[i]) << P::name;
        EXPECT_EQ(m.shaper().time[i], fresh.shaper().time[i]) << P::name;
      }
      for (int i = 0; i <= 200; ++i) {
        const double t = c.duration() * i / 200.0;
        EXPECT_EQ(m.at(t).p, c.at(t).p) << P::name << " " << t;
        EXPECT_EQ(m.at(t).j, c.at(t).j) << P::name << " " << t;
        EXPECT_EQ(m.at(t).v, fresh.at(t).v) << P::name << " " << t;
      }
    }
  });
}
