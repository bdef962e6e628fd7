// SPDX-License-Identifier: Apache-2.0
// The exact integrator against closed-form solutions: a polynomial base motion must be followed to
// rounding, over thousands of steps of mixed sizes, so integration error can never pass for
// residual vibration. Also the jump rule (impulses from base discontinuities) and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "settle/plant/linear_plant.hpp"
#include "settle/plant/modal_plant.hpp"

namespace settle::plant {
namespace {

ModalPlant one_mode(double omega, double zeta, double gain) {
  Mode m;
  m.omega = omega;
  m.zeta = zeta;
  m.gain = gain;
  ModalPlant p;
  EXPECT_EQ(ModalPlant::make_modes({m}, 1.0, PlantKind::modes, p), SimStatus::ok);
  return p;
}

// Steps of sizes cycling through an irregular list, so the cache, odd steps and many repeated
// steps are all exercised.
std::vector<double> step_sizes(double total) {
  const double pattern[] = {1e-4, 1e-4, 3.7e-5, 1e-4, 2.3e-4, 1e-4, 7e-6};
  std::vector<double> out;
  double t = 0.0;
  for (std::size_t i = 0; t < total; ++i) {
    out.push_back(pattern[i % 7]);
    t += out.back();
  }
  return out;
}

TEST(LinearPlant, UndampedModeUnderConstantBaseAccelerationMatchesClosedForm) {
  // q'' + w^2 q = g a with y = a t^2 / 2 from rest: q = (g a / w^2)(1 - cos w t).
  const double w = 37.0, g = -0.4, a = 2.5;
  ModalPlant p = one_mode(w, 0.0, g);
  double t = 0.0, worst = 0.0;
  const double scale = std::fabs(g * a / (w * w));
  for (double h : step_sizes(2.0)) {
    BasePolynomial b{};
    b.c = {0.5 * a * t * t, a * t, 0.5 * a};
    b.degree = 2;
    ASSERT_EQ(p.advance(h, b), SimStatus::ok);
    t += h;
    const double exact = g * a / (w * w) * (1.0 - std::cos(w * t));
    worst = std::max(worst, std::fabs(p.mode_q(0) - exact) / scale);
  }
  EXPECT_LE(worst, 1e-10);
}

TEST(LinearPlant, DampedModeUnderCubicBaseMatchesClosedForm) {
  // y = c t^3, q'' + 2 z w q' + w^2 q = 6 c g t: q = 6cg/w^2 (t - 2z/w) + e^{-z w t}(A cos + B sin).
  const double w = 120.0, z = 0.08, g = 1.3, c = 0.7;
  const double wd = w * std::sqrt(1.0 - z * z);
  const double ca = 12.0 * c * g * z / (w * w * w);
  const double cb = (z * w * ca - 6.0 * c * g / (w * w)) / wd;
  ModalPlant p = one_mode(w, z, g);
  double t = 0.0, worst = 0.0, peak = 0.0;
  for (double h : step_sizes(1.0)) {
    BasePolynomial b{};
    b.c = {c * t * t * t, 3.0 * c * t * t, 3.0 * c * t, c};
    b.degree = 3;
    ASSERT_EQ(p.advance(h, b), SimStatus::ok);
    t += h;
    const double exact =
        6.0 * c * g / (w * w) * (t - 2.0 * z / w) + std::exp(-z * w * t) * (ca * std::cos(wd * t) + cb * std::sin(wd * t));
    worst = std::max(worst, std::fabs(p.mode_q(0) - exact));
    peak = std::max(peak, std::fabs(exact));
  }
  EXPECT_LE(worst / peak, 1e-10);
}

TEST(LinearPlant, SdofDrivenThroughSpringAndDamperFollowsARamp) {
  // x'' + 2 z w x' + w^2 x = 2 z w y' + w^2 y, y = v t: x = v t - (v / wd) e^{-z w t} sin wd t.
  // The ramp starts with a velocity step, which the plant must take as an impulse.
  ModalPlant p;
  ASSERT_EQ(ModalPlant::make_sdof({1.0, 800.0, 9.0}, p), SimStatus::ok);
  const double w = std::sqrt(800.0), z = 9.0 / (2.0 * std::sqrt(800.0)), v = 0.3;
  const double wd = w * std::sqrt(1.0 - z * z);
  double t = 0.0, worst = 0.0;
  for (double h : step_sizes(1.5)) {
    ASSERT_EQ(p.advance(h, BasePolynomial::linear(v * t, v * (t + h), h)), SimStatus::ok);
    t += h;
    const double exact = v * t - v / wd * std::exp(-z * w * t) * std::sin(wd * t);
    worst = std::max(worst, std::fabs(p.position() - exact) / (v * t));
  }
  EXPECT_LE(worst, 1e-10);
}

TEST(LinearPlant, PositionStepIsTheImpulseOfADoublet) {
  // A step D of the base on q'' + 2 z w q' + w^2 q = g y'': q(0+) = g D, q'(0+) = -2 z w g D.
  const double w = 10.0, z = 0.1, g = -2.0, d = 0.25;
  ModalPlant p = one_mode(w, z, g);
  ASSERT_EQ(p.advance(1e-3, BasePolynomial::constant(d)), SimStatus::ok);
  // Compare with the free response from those initial conditions after 1 ms.
  const double wd = w * std::sqrt(1.0 - z * z), t = 1e-3;
  const double q0 = g * d, dq0 = -2.0 * z * w * g * d;
  const double e = std::exp(-z * w * t);
  const double q = e * (q0 * std::cos(wd * t) + (dq0 + z * w * q0) / wd * std::sin(wd * t));
  EXPECT_NEAR(p.mode_q(0), q, 1e-14);
  // Its residual is what an unshaped step leaves: the amplitude of the free response from those
  // initial conditions (the envelope's value at the step), decayed for 1 ms.
  const double amp0 = std::hypot(q0, (dq0 + z * w * q0) / wd);
  EXPECT_NEAR(p.mode_residual(0), amp0 * e, 1e-13);
  EXPECT_NEAR(p.mode_step_residual(0, d), amp0, 1e-13);
}

TEST(LinearPlant, StepSizesComposeExactly) {
  // Ten steps of 1 ms and one of 10 ms, with the base on one polynomial: the same state.
  ModalPlant a = one_mode(300.0, 0.02, 1.0), b = a;
  const double c3 = 4.0;
  for (int k = 0; k < 10; ++k) {
    const double t = k * 1e-3;
    BasePolynomial pk{};
    pk.c = {c3 * t * t * t, 3.0 * c3 * t * t, 3.0 * c3 * t, c3};
    pk.degree = 3;
    ASSERT_EQ(a.advance(1e-3, pk), SimStatus::ok);
  }
  BasePolynomial whole{};
  whole.c = {0.0, 0.0, 0.0, c3};
  whole.degree = 3;
  ASSERT_EQ(b.advance(1e-2, whole), SimStatus::ok);
  EXPECT_NEAR(a.mode_q(0), b.mode_q(0), 1e-12 * std::fabs(b.mode_q(0)));
  EXPECT_NEAR(a.mode_dq(0), b.mode_dq(0), 1e-12 * std::fabs(b.mode_dq(0)));
}

TEST(LinearPlant, GeneralFreeAmplitudeAgreesWithTheModalFormula) {
  ModalPlant p = one_mode(50.0, 0.2, 1.0);
  BasePolynomial b{};
  b.c = {0.0, 0.0, 3.0};
  b.degree = 2;
  ASSERT_EQ(p.advance(0.013, b), SimStatus::ok);
  ASSERT_EQ(p.advance(0.01, BasePolynomial::constant(p.base().p)), SimStatus::ok);  // velocity drops to 0
  EXPECT_NEAR(p.linear().free_amplitude(kRowDeflection), p.residual_amplitude(), 1e-12 * p.residual_amplitude());
}

TEST(BasePolynomial, HermiteBuildersMatchTheirEndConditions) {
  const BaseState s0{0.1, -2.0, 30.0}, s1{0.4, 5.0, -7.0};
  const double h = 0.02;
  const BasePolynomial q = BasePolynomial::quintic_hermite(s0, s1, h);
  for (int k = 0; k < 3; ++k) {
    const double at0[3] = {s0.p, s0.v, s0.a}, at1[3] = {s1.p, s1.v, s1.a};
    EXPECT_NEAR(q.derivative(k, 0.0), at0[k], 1e-12 * (1.0 + std::fabs(at0[k])));
    EXPECT_NEAR(q.derivative(k, h), at1[k], 1e-9 * (1.0 + std::fabs(at1[k])));
  }
  const BasePolynomial c = BasePolynomial::cubic_hermite(0.1, -2.0, 0.4, 5.0, h);
  EXPECT_NEAR(c.derivative(0, h), 0.4, 1e-12);
  EXPECT_NEAR(c.derivative(1, h), 5.0, 1e-10);
  const BasePolynomial l = BasePolynomial::linear(1.0, 3.0, 0.5);
  EXPECT_DOUBLE_EQ(l.derivative(1, 0.2), 4.0);
}

TEST(LinearPlant, RejectsBadStepsAndMatrices) {
  ModalPlant p = one_mode(10.0, 0.0, 1.0);
  EXPECT_EQ(p.advance(0.0, BasePolynomial::constant(0.0)), SimStatus::non_positive_step);
  EXPECT_EQ(p.advance(-1e-3, BasePolynomial::constant(0.0)), SimStatus::non_positive_step);
  EXPECT_EQ(p.advance(NAN, BasePolynomial::constant(0.0)), SimStatus::non_positive_step);
  BasePolynomial high{};
  high.degree = kMaxBaseDegree + 1;
  EXPECT_EQ(p.advance(1e-3, high), SimStatus::degree_too_high);
  EXPECT_EQ(p.advance(1e-3, BasePolynomial::constant(NAN)), SimStatus::non_finite_input);
  LinearPlant lp;
  EXPECT_EQ(LinearPlant::make(Eigen::MatrixXd::Zero(2, 3), Eigen::MatrixXd::Zero(2, 3), Eigen::MatrixXd::Zero(1, 2),
                              Eigen::MatrixXd::Zero(1, 3), lp),
            SimStatus::dimension_mismatch);
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(2, 2);
  a(0, 1) = INFINITY;
  EXPECT_EQ(LinearPlant::make(a, Eigen::MatrixXd::Zero(2, 3), Eigen::MatrixXd::Zero(1, 2), Eigen::MatrixXd::Zero(1, 3), lp),
            SimStatus::non_finite_parameter);
}

}  // namespace
}  // namespace settle::plant
