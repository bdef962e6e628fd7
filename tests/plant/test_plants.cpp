// SPDX-License-Identifier: Apache-2.0
// The plants as users configure them: derived parameters against SEEDS.md, the beam's roots for
// the classical clamped-free case by an independent Newton iteration, and every bad parameter
// rejected with its own code.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "settle/plant/beam.hpp"
#include "settle/plant/modal_plant.hpp"

namespace settle::plant {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(Plants, SdofOfSeed001) {
  ModalPlant p;
  ASSERT_EQ(ModalPlant::make_sdof({}, p), SimStatus::ok);
  EXPECT_NEAR(p.modes()[0].omega, 28.28427, 1e-5);
  EXPECT_NEAR(p.modes()[0].zeta, 0.159099, 1e-6);
}

TEST(Plants, BeltOfSeed004) {
  ModalPlant p;
  ASSERT_EQ(ModalPlant::make_belt({}, p), SimStatus::ok);
  EXPECT_NEAR(p.modes()[0].omega, 31.1769, 1e-4);
  EXPECT_NEAR(p.modes()[0].omega / (2.0 * M_PI), 4.962, 1e-3);
  EXPECT_NEAR(p.modes()[0].zeta, 0.02598, 1e-5);
  EXPECT_NEAR(p.rigid_gain(), 1.0 / 30.0, 1e-15);
  EXPECT_NEAR(p.modes()[0].gain, -1.0 / 30.0, 1e-15);
}

TEST(Plants, ClampedFreeRootsWithoutTipMass) {
  BeamParams b;
  b.tip_mass = 0.0;
  std::vector<BeamMode> m;
  ASSERT_EQ(beam_modes(b, 5, m), SimStatus::ok);
  // Independent: Newton on f(b) = cos b cosh b + 1 from the textbook approximations.
  const double guess[5] = {1.875, 4.694, 7.855, 10.996, 14.137};
  for (int j = 0; j < 5; ++j) {
    double x = guess[j];
    for (int it = 0; it < 50; ++it) {
      const double f = std::cos(x) * std::cosh(x) + 1.0;
      const double df = -std::sin(x) * std::cosh(x) + std::cos(x) * std::sinh(x);
      x -= f / df;
    }
    EXPECT_NEAR(m[static_cast<std::size_t>(j)].beta, x, 1e-10 * x) << "mode " << j + 1;
  }
  EXPECT_NEAR(m[0].beta, 1.8751, 5e-5);
  EXPECT_NEAR(m[1].beta, 4.6941, 5e-5);
  EXPECT_NEAR(m[2].beta, 7.8548, 5e-5);
}

TEST(Plants, ManyBeamModesStayFiniteAndOrdered) {
  std::vector<BeamMode> m;
  ASSERT_EQ(beam_modes(BeamParams{}, kMaxBeamModes, m), SimStatus::ok);
  for (std::size_t j = 1; j < m.size(); ++j) {
    EXPECT_GT(m[j].beta, m[j - 1].beta + 2.5);
    EXPECT_TRUE(std::isfinite(m[j].lambda) && std::isfinite(m[j].phi_tip));
  }
}

TEST(Plants, StableShapeEqualsTheTextbookFormulaWhereThatIsAccurate) {
  const double b = 1.320266;
  const double g = (std::cosh(b) + std::cos(b)) / (std::sinh(b) + std::sin(b));
  for (double xi : {0.0, 0.3, 0.7, 1.0}) {
    const double naive = std::cosh(b * xi) - std::cos(b * xi) - g * (std::sinh(b * xi) - std::sin(b * xi));
    EXPECT_NEAR(beam_shape(b, xi), naive, 1e-13);
  }
}

TEST(Plants, BadParametersHaveSpecificCodes) {
  ModalPlant p;
  EXPECT_EQ(ModalPlant::make_sdof({-1.0, 800.0, 9.0}, p), SimStatus::non_positive_mass);
  EXPECT_EQ(ModalPlant::make_sdof({1.0, 0.0, 9.0}, p), SimStatus::non_positive_stiffness);
  EXPECT_EQ(ModalPlant::make_sdof({1.0, 800.0, -1.0}, p), SimStatus::negative_damping);
  EXPECT_EQ(ModalPlant::make_sdof({1.0, 800.0, 60.0}, p), SimStatus::not_underdamped);  // zeta > 1
  EXPECT_EQ(ModalPlant::make_sdof({kNaN, 800.0, 9.0}, p), SimStatus::non_finite_parameter);

  BeamOptions o;
  o.params.length = 0.0;
  EXPECT_EQ(ModalPlant::make_beam(o, p), SimStatus::non_positive_length);
  o = {};
  o.params.modulus = -3e9;
  EXPECT_EQ(ModalPlant::make_beam(o, p), SimStatus::non_positive_modulus);
  o = {};
  o.params.thickness = 0.0;
  EXPECT_EQ(ModalPlant::make_beam(o, p), SimStatus::non_positive_section);
  o = {};
  o.params.beam_mass = 0.0;
  EXPECT_EQ(ModalPlant::make_beam(o, p), SimStatus::non_positive_mass);
  o = {};
  o.params.tip_mass = -0.1;
  EXPECT_EQ(ModalPlant::make_beam(o, p), SimStatus::negative_tip_mass);
  o = {};
  o.modes = 0;
  EXPECT_EQ(ModalPlant::make_beam(o, p), SimStatus::bad_mode_count);
  o = {};
  o.modal_damping = 1.0;
  EXPECT_EQ(ModalPlant::make_beam(o, p), SimStatus::not_underdamped);

  BeltParams b;
  b.inertia = 0.0;
  EXPECT_EQ(ModalPlant::make_belt(b, p), SimStatus::non_positive_mass);
  b = {};
  b.pulley_R = -0.18;
  EXPECT_EQ(ModalPlant::make_belt(b, p), SimStatus::non_positive_radius);
  b = {};
  b.ratio = 0.0;
  EXPECT_EQ(ModalPlant::make_belt(b, p), SimStatus::non_positive_ratio);
  b = {};
  b.belt_damping = 1e6;  // xi far above 1
  EXPECT_EQ(ModalPlant::make_belt(b, p), SimStatus::not_underdamped);

  Mode m;
  m.omega = 0.0;
  EXPECT_EQ(ModalPlant::make_modes({m}, 1.0, PlantKind::modes, p), SimStatus::non_positive_omega);
  m.omega = 10.0;
  m.zeta = 1.0;
  EXPECT_EQ(ModalPlant::make_modes({m}, 1.0, PlantKind::modes, p), SimStatus::not_underdamped);
  EXPECT_EQ(ModalPlant::make_modes({}, 1.0, PlantKind::modes, p), SimStatus::bad_mode_count);
}

TEST(Plants, FailureLeavesThePlantUntouched) {
  ModalPlant p;
  ASSERT_EQ(ModalPlant::make_sdof({}, p), SimStatus::ok);
  ASSERT_NE(ModalPlant::make_sdof({-1.0, 1.0, 0.0}, p), SimStatus::ok);
  EXPECT_NEAR(p.modes()[0].omega, std::sqrt(800.0), 1e-12);
}

TEST(Plants, SpecBuildsEachKind) {
  PlantSpec s;
  ModalPlant p;
  for (PlantKind k : {PlantKind::sdof, PlantKind::beam, PlantKind::belt}) {
    s.kind = k;
    ASSERT_EQ(make_plant(s, p), SimStatus::ok);
    EXPECT_EQ(p.kind(), k);
  }
  s.kind = PlantKind::modes;
  EXPECT_EQ(make_plant(s, p), SimStatus::bad_mode_count);
  s.modes = {Mode{5.0, 0.01, 1.0, 1.0, 1.0, 0.0, 0.0}, Mode{2.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0}};
  ASSERT_EQ(make_plant(s, p), SimStatus::ok);
  EXPECT_DOUBLE_EQ(p.fundamental().omega, 2.0);
}

TEST(Plants, EnergyOfTheBeltIsJThetaDotSquaredOverTwoPlusBeltStrain) {
  ModalPlant p;
  ASSERT_EQ(ModalPlant::make_belt({}, p), SimStatus::ok);
  BasePolynomial b{};
  b.c = {0.0, 0.0, 40.0};
  b.degree = 2;
  ASSERT_EQ(p.advance(0.05, b), SimStatus::ok);
  const double theta_dot = p.velocity();
  const double kt = 2.0 * 9e4 * 0.18 * 0.18;
  const Energy e = p.energy();
  EXPECT_NEAR(e.kinetic, 0.5 * 6.0 * theta_dot * theta_dot, 1e-12 * e.kinetic);
  EXPECT_NEAR(e.potential, 0.5 * kt * p.mode_q(0) * p.mode_q(0), 1e-12 * e.potential);
}

}  // namespace
}  // namespace settle::plant
