// SPDX-License-Identifier: Apache-2.0
// The reference numbers of SEEDS.md, each derived here independently of the code under test:
// Cramer's rule for the pseudo-polynomial coefficients, the residual condition solved
// numerically for Y1..Y3, and the Duhamel integral for the residuals of the arbitrary input.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "residual.hpp"
#include "settle/core/pseudo_poly.hpp"
#include "test_helpers.hpp"

using namespace settle;
using core::ProfileKind;

namespace {

double det3(const std::array<std::array<double, 3>, 3>& m) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// C by Cramer's rule on Z c = e0 with Z rows (1, g, g(g-1)).
std::array<double, 3> cramer(const std::array<double, 3>& g) {
  std::array<std::array<double, 3>, 3> z{};
  for (std::size_t i = 0; i < 3; ++i) {
    z[0][i] = 1.0;
    z[1][i] = g[i];
    z[2][i] = g[i] * (g[i] - 1.0);
  }
  const double d = det3(z);
  std::array<double, 3> c{};
  for (std::size_t i = 0; i < 3; ++i) {
    auto zi = z;
    zi[0][i] = 1.0;
    zi[1][i] = 0.0;
    zi[2][i] = 0.0;
    c[i] = det3(zi) / d;
  }
  return c;
}

TEST(Seed004, CoefficientsOfThe345Polynomial) {
  const double g[3] = {3, 4, 5};
  core::PseudoPolyParams p{};
  ASSERT_EQ(core::pseudo_poly_design(1.0, 1.0, g, 3, p), core::Status::ok);
  const auto c = cramer({3, 4, 5});
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(p.coeffs[i], c[i], 1e-12);
  EXPECT_NEAR(c[0], 10.0, 1e-12);
  EXPECT_NEAR(c[1], -15.0, 1e-12);
  EXPECT_NEAR(c[2], 6.0, 1e-12);
  // And it is the textbook polynomial D(10 s^3 - 15 s^4 + 6 s^5).
  const auto m = test::must_plan(test::timed(ProfileKind::poly345, 2.0, 1.5));
  for (int i = 0; i <= 50; ++i) {
    const double s = i / 50.0;
    EXPECT_NEAR(m.at(1.5 * s).p, 2.0 * (10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5)), 1e-12);
  }
}

TEST(Seed004, CoefficientsForPaperStyleExponents) {
  const double g[3] = {4.5, 6.2, 8.4};
  core::PseudoPolyParams p{};
  ASSERT_EQ(core::pseudo_poly_design(1.0, 1.0, g, 3, p), core::Status::ok);
  const auto c = cramer({4.5, 6.2, 8.4});
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(p.coeffs[i], c[i], 1e-10);
  // SEEDS.md prints them to 4 decimals.
  EXPECT_NEAR(c[0], 7.8552, 5e-5);
  EXPECT_NEAR(c[1], -10.1070, 5e-5);
  EXPECT_NEAR(c[2], 3.2517, 5e-5);
}

TEST(Seed004, HigherOrderCommandsZeroTheirDerivativesAtTheStart) {
  // n + 1 = 8 exponents: the k-th derivative at t = 0 is proportional to sum_i C_i P(gamma_i, k),
  // which must be 1 for k = 0 (phi(0) = 0) and 0 for k = 1..7. Evaluated here from the definition.
  const double g[8] = {3.5, 4.2, 5.1, 6.3, 7.0, 8.4, 9.9, 11.2};
  core::PseudoPolyParams p{};
  ASSERT_EQ(core::pseudo_poly_design(1.0, 1.0, g, 8, p), core::Status::ok);
  for (int k = 0; k < 8; ++k) {
    double sum = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < 8; ++i) {
      double pk = 1.0;
      for (int r = 0; r < k; ++r) pk *= g[i] - r;
      sum += p.coeffs[i] * pk;
      scale += std::fabs(p.coeffs[i] * pk);
    }
    EXPECT_NEAR(sum, k == 0 ? 1.0 : 0.0, 1e-10 * scale) << "derivative " << k;
  }
  // and the evaluator agrees: velocity, acceleration and jerk start at zero
  const core::PseudoPoly<double> pp{p};
  const auto pk = core::pseudo_poly_peaks(p);
  const auto s0 = pp.at(1e-6);
  EXPECT_LT(std::fabs(s0.v), 1e-9 * pk.v);
  EXPECT_LT(std::fabs(s0.a), 1e-9 * pk.a);
  EXPECT_LT(std::fabs(s0.j), 1e-9 * pk.j);
}

// The residual of a ramp-versine command is linear in (Y2, Y3) once Y1 = L - Y2 - Y3: the test
// builds the 2x2 system from two Duhamel integrals and solves it, independently of the formula.
std::array<double, 3> solve_zero_residual_y(double tau, double omega, double zeta) {
  const double wd = omega * std::sqrt(1 - zeta * zeta);
  const std::complex<double> k{zeta * omega, -wd};
  auto integral = [&](double y2, double y3) {
    // y'' = (R^2/2pi)(Y2 sin + Y3 cos) on (0, tau) plus the velocity-step impulses at 0 and tau.
    const double r = 2 * M_PI / tau;
    const test::GaussLegendre gl{20};
    std::complex<double> acc = r / (2 * M_PI) * (1.0 - y2) * (1.0 - std::exp(k * tau));
    const int panels = 64;
    for (int p = 0; p < panels; ++p) {
      const double lo = tau * p / panels, h = tau / panels;
      for (std::size_t q = 0; q < gl.x.size(); ++q) {
        const double t = lo + 0.5 * h * (gl.x[q] + 1.0);
        acc += 0.5 * h * gl.w[q] * r * r / (2 * M_PI) * (y2 * std::sin(r * t) + y3 * std::cos(r * t)) * std::exp(k * t);
      }
    }
    return acc;
  };
  const auto f0 = integral(0, 0), fa = integral(1, 0) - f0, fb = integral(0, 1) - f0;
  // fa Y2 + fb Y3 = -f0, real and imaginary parts.
  const double det = fa.real() * fb.imag() - fb.real() * fa.imag();
  const double y2 = (-f0.real() * fb.imag() + fb.real() * f0.imag()) / det;
  const double y3 = (-fa.real() * f0.imag() + f0.real() * fa.imag()) / det;
  return {1.0 - y2 - y3, y2, y3};
}

TEST(Seed001, ComputedYMatchTheIndependentSolutionAndThePaper) {
  const double omega = std::sqrt(800.0), zeta = 9.0 / (2 * std::sqrt(800.0));
  struct Ref {
    double tau;
    std::array<double, 3> y;
  };
  for (const Ref& ref : {Ref{0.167, {1.3462, -0.7694, 0.4233}}, Ref{0.74, {-0.0054, 0.9099, 0.0955}}}) {
    const auto indep = solve_zero_residual_y(ref.tau, omega, zeta);
    const auto m = test::must_plan(test::timed(ProfileKind::ramp_versine, 1.0, ref.tau, omega, zeta));
    const auto& p = std::get_if<core::RampVersine<double>>(&m.profile().variant())->params();
    EXPECT_NEAR(p.y1, indep[0], 1e-8);
    EXPECT_NEAR(p.y2, indep[1], 1e-8);
    EXPECT_NEAR(p.y3, indep[2], 1e-8);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(indep[i], ref.y[i], 6e-5) << "tau=" << ref.tau << " i=" << i;
  }
}

TEST(Seed001, ArbitraryYLeaveTheResidualOfThePaper) {
  const double omega = std::sqrt(800.0), zeta = 9.0 / (2 * std::sqrt(800.0));
  for (auto [tau, expected] : {std::pair{0.167, 0.277}, std::pair{0.74, 0.035}}) {
    auto r = test::timed(ProfileKind::ramp_versine, 1.0, tau, omega, zeta);
    r.y_fractions = std::array<double, 3>{0.5, 0.25, 0.25};
    const auto m = test::must_plan(r);
    EXPECT_NEAR(test::residual_amplitude(m, omega, zeta), expected, 0.0015) << "tau=" << tau;
  }
}

TEST(Seed000, PeakAccelerationAtPoint8TnIsAboutFourTimesA) {
  const double omega = 22.04871;
  const auto m = test::must_plan(test::timed(ProfileKind::scurve, 0.1, 0.8 * 2 * M_PI / omega, omega));
  const auto& p = std::get_if<core::RampCycloid<double>>(&m.profile().variant())->params();
  EXPECT_NEAR(m.peaks().a / p.amplitude, 4.0, 0.15);
  // and the transition reduces to the paper's A2 = A (1 - Tn^2/tau^2)
  const double tn = 2 * M_PI / omega;
  EXPECT_NEAR(p.c2, 1 - tn * tn / (p.tau * p.tau), 1e-12);
}

}  // namespace
