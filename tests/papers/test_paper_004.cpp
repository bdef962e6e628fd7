// SPDX-License-Identifier: Apache-2.0
// Seed 004 reproduced: H(3,4,5) in closed form (the command is a polynomial, so F and G are exact
// integrals of polynomials times exponentials), H at the paper's exponents and at the optimiser's
// result by an independent composite Gauss-Legendre quadrature in the original time variable, the
// boundary conditions of the optimised command, and E(T) from the time-stepped plant.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <vector>

#include "residual.hpp"
#include "settle/core/planner.hpp"
#include "settle/papers/reproduce.hpp"

namespace settle::papers {
namespace {

const double kPhi = 30.0 * M_PI;  // 15 motor revolutions

// H = G^2 + w^2 F^2 by composite Gauss-Legendre with phi'' from core's Move. phi'' ~ (T - tau)^(g-2)
// is not smooth at tau = T for non-integer g, so integrate in v with T - tau = T v^4, which makes
// the integrand ~ v^(4g - 5) and the rule converge fast.
double h_by_quadrature(const commission::EnergyTarget& t, const core::Move<double>& m, int panels = 200) {
  static const test::GaussLegendre gl{16};
  const double xi = t.zeta, w = t.omega, wd = w * std::sqrt(1 - xi * xi), delta = std::atan2(xi, std::sqrt(1 - xi * xi));
  double f = 0.0, g = 0.0;
  const double h = 1.0 / panels;
  for (int p = 0; p < panels; ++p) {
    for (std::size_t q = 0; q < gl.x.size(); ++q) {
      const double v = p * h + 0.5 * h * (gl.x[q] + 1.0);
      const double s = t.duration * v * v * v * v, jac = 4.0 * t.duration * v * v * v;
      const double a = m.at(t.duration - s).a * 0.5 * h * gl.w[q] * jac * std::exp(-xi * w * s);
      f += a * std::sin(wd * s);
      g += w * a * std::cos(wd * s + delta);
    }
  }
  return g * g + w * w * f * f;
}

core::Move<double> pseudo(const std::vector<double>& g) {
  core::MoveRequest r;
  r.profile = core::ProfileKind::pseudopoly;
  r.distance = kPhi;
  r.time = 1.0;
  r.gamma_count = g.size();
  for (std::size_t i = 0; i < g.size(); ++i) r.gammas[i] = g[i];
  core::Move<double> m;
  EXPECT_EQ(core::plan(r, m), core::Status::ok);
  return m;
}

class Paper004 : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    Options004 o;
    o.history = false;
    o.exponents = false;
    ASSERT_EQ(reproduce_004(o, result_), plant::SimStatus::ok);
  }
  static Result004 result_;
};
Result004 Paper004::result_;

TEST_F(Paper004, DerivedPlatformParameters) {
  EXPECT_NEAR(result_.target.omega, 31.1769, 1e-4);
  EXPECT_NEAR(result_.target.zeta, 0.02598, 1e-5);
  EXPECT_NEAR(result_.target.lambda, 1.0 / 30.0, 1e-15);
}

TEST_F(Paper004, H345InClosedForm) {
  // The platform from Table III itself, not from the implementation: J = 6 kg m^2, belt k = 9e4 N/m
  // and c = 150 N s/m per branch on R = 0.18 m, lambda = z r / R = 0.1 * 0.06 / 0.18.
  const double inertia = 6.0, kt = 2.0 * 9e4 * 0.18 * 0.18, ct = 2.0 * 150.0 * 0.18 * 0.18;
  const double lambda = 0.1 * 0.06 / 0.18;
  const double w = std::sqrt(kt / inertia), xi = ct / (2.0 * inertia * w);
  // phi'' = (Phi/T^2)(60 s - 180 s^2 + 120 s^3); with u = 1 - s the integrals are
  // J_m = int_0^1 u^m e^{r u} du, J_0 = (e^r - 1)/r, J_m = (e^r - m J_{m-1})/r, exact.
  const double beta = std::sqrt(1 - xi * xi), delta = std::atan2(xi, beta), wd = w * beta;
  const std::complex<double> r{-xi * w, w * beta};
  std::complex<double> j[4];
  j[0] = (std::exp(r) - 1.0) / r;
  for (int m = 1; m < 4; ++m) j[m] = (std::exp(r) - double(m) * j[m - 1]) / r;
  // 60 s - 180 s^2 + 120 s^3 in u = 1 - s: 60(1-u) - 180(1-u)^2 + 120(1-u)^3 = -60 u + 180 u^2 - 120 u^3.
  // i = int_0^T phi''(tau) e^{r (T - tau)} d tau.
  const std::complex<double> i = kPhi * (-60.0 * j[1] + 180.0 * j[2] - 120.0 * j[3]);
  const double f = i.imag(), g = w * (std::exp(std::complex<double>{0, delta}) * i).real();
  const double h = g * g + w * w * f * f;
  EXPECT_NEAR(result_.initial.h_index, h, 1e-10 * h);
  EXPECT_NEAR(h, 1.0439e4, 1e-4 * h);
  // E(T) as the platform's physical energy, by Duhamel, not through E = h H: the mode
  // alpha'' + 2 xi w alpha' + w^2 alpha = -lambda phi'' from rest gives at T
  //   alpha = -(lambda / wd) Im i,  alpha' = -(lambda / wd)(wd Re i - xi w Im i),
  // and with the motor at rest E = 1/2 J (alpha'^2 + w^2 alpha^2).
  const double alpha = -(lambda / wd) * i.imag();
  const double dalpha = -(lambda / wd) * (wd * i.real() - xi * w * i.imag());
  const double energy = 0.5 * inertia * (dalpha * dalpha + w * w * alpha * alpha);
  EXPECT_NEAR(result_.initial.energy, energy, 1e-10 * energy);
  EXPECT_NEAR(energy, 0.0358, 1e-4);
}

TEST_F(Paper004, PaperExponentsByIndependentQuadrature) {
  const double h = h_by_quadrature(result_.target, pseudo({3.024, 4.565, 5.874}));
  EXPECT_NEAR(result_.paper.h_index, h, 1e-6 * h);
  EXPECT_NEAR(h, 1.87e-4, 0.01e-4);
}

TEST_F(Paper004, OptimiserReachesTheTargetAndKeepsTheBoundaryConditions) {
  const commission::OptimiserResult& o = result_.optimiser;
  ASSERT_EQ(o.gammas.size(), 3u);
  EXPECT_GT(o.gammas[0], 2.0);
  EXPECT_GT(o.gammas[1] - o.gammas[0], 0.04);
  EXPECT_GT(o.gammas[2] - o.gammas[1], 0.04);
  const double h0 = result_.initial.h_index;
  EXPECT_LE(o.h_final, 1e-6 * h0);
  // Not only by the optimiser's own quadrature: the independent one agrees to its accuracy.
  EXPECT_LE(h_by_quadrature(result_.target, pseudo(o.gammas)), 1e-6 * h0);
  const core::Move<double> m = pseudo(o.gammas);
  const auto s0 = m.at(1e-12), s1 = m.at(1.0 - 1e-9);
  EXPECT_NEAR(s0.p, 0.0, 1e-9);
  EXPECT_NEAR(s0.v, 0.0, 1e-9);
  EXPECT_NEAR(s0.a, 0.0, 1e-7);
  EXPECT_NEAR(s1.p, kPhi, 1e-9);
  EXPECT_NEAR(s1.v, 0.0, 1e-7);
  EXPECT_LE(result_.boundary_error, 1e-12);
}

TEST_F(Paper004, TimeSteppedPlantGivesTheSameEnergy) {
  EXPECT_NEAR(result_.h_simulated_initial, result_.initial.h_index, 1e-8 * result_.initial.h_index);
  EXPECT_LE(result_.h_simulated_optimised, 1e-10 * result_.initial.h_index);
}

TEST_F(Paper004, MoreExponentsStillReachZeroEnergy) {
  for (std::size_t n = 4; n <= 6; ++n) {
    std::vector<double> start;
    for (std::size_t i = 0; i < n; ++i) start.push_back(3.0 + static_cast<double>(i));
    commission::OptimiserResult r;
    ASSERT_EQ(commission::optimise_exponents(result_.target, start, commission::OptimiserOptions{}, r), plant::SimStatus::ok) << n;
    EXPECT_LE(r.h_final, 1e-6 * result_.initial.h_index) << n;
    EXPECT_LE(h_by_quadrature(result_.target, pseudo(r.gammas)), 1e-6 * result_.initial.h_index) << n;
  }
}

}  // namespace
}  // namespace settle::papers
