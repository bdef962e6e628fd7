// Seeds 001/002 reproduced: the Y values by solving the zero-residual condition numerically with
// an independent RK4 integration of the mass-spring-damper, the residuals of the arbitrary Y, and
// the textbook shaper insensitivity widths by independent formulas.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <map>
#include <string>

#include "rk4.hpp"
#include "settle/core/planner.hpp"
#include "settle/sim/reproduce.hpp"

namespace settle::sim {
namespace {

const double kW = std::sqrt(800.0), kZ = 9.0 / (2.0 * std::sqrt(800.0));

// x'' + 2 z w x' + w^2 x = 2 z w y' + w^2 y from rest, y given with y'; returns (x, x') at tau
// (the command is smooth on (0, tau), its velocity steps sit at the ends).
template <typename Y, typename DY>
std::array<double, 2> rk4(Y y, DY dy, double tau, int steps = 40000) {
  return test::rk4([&](double t, double x, double v) { return 2 * kZ * kW * (dy(t) - v) + kW * kW * (y(t) - x); },
                   tau, steps);
}

// The command of SEEDS.md B with L = 1: y = Rt/2pi - (Y2/2pi) sin Rt + (Y3/2pi)(1 - cos Rt).
std::array<double, 2> end_state(double tau, double y2, double y3) {
  const double r = 2 * M_PI / tau;
  return rk4([&](double t) { return r * t / (2 * M_PI) - y2 / (2 * M_PI) * std::sin(r * t) + y3 / (2 * M_PI) * (1 - std::cos(r * t)); },
             [&](double t) { return r / (2 * M_PI) * (1 - y2 * std::cos(r * t) + y3 * std::sin(r * t)); }, tau);
}

double amplitude(const std::array<double, 2>& s) {  // relative to rest at L = 1
  const double wd = kW * std::sqrt(1 - kZ * kZ), e = s[0] - 1.0;
  return std::hypot(e, (s[1] + kZ * kW * e) / wd);
}

class Paper001 : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    Options001 o;
    o.history = false;
    o.grids = false;
    ASSERT_EQ(reproduce_001(o, result_), SimStatus::ok);
  }
  static Result001 result_;
};
Result001 Paper001::result_;

TEST_F(Paper001, ComputedYSolveTheZeroResidualCondition) {
  const double ref[2][3] = {{1.3462, -0.7694, 0.4233}, {-0.0054, 0.9099, 0.0955}};
  for (std::size_t c = 0; c < 2; ++c) {
    const double tau = kTaus001[c];
    // The end state is affine in (Y2, Y3): solve x(tau) = 1, x'(tau) = 0 from three runs.
    const auto s0 = end_state(tau, 0, 0), s2 = end_state(tau, 1, 0), s3 = end_state(tau, 0, 1);
    const double a11 = s2[0] - s0[0], a12 = s3[0] - s0[0], a21 = s2[1] - s0[1], a22 = s3[1] - s0[1];
    const double b1 = 1.0 - s0[0], b2 = -s0[1];
    const double det = a11 * a22 - a12 * a21;
    const double y2 = (b1 * a22 - a12 * b2) / det, y3 = (a11 * b2 - a21 * b1) / det;
    const auto& y = result_.cases[c].y_computed;
    EXPECT_NEAR(y[1], y2, 1e-8);
    EXPECT_NEAR(y[2], y3, 1e-8);
    EXPECT_NEAR(y[0], 1.0 - y2 - y3, 1e-8);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(y[static_cast<std::size_t>(k)], ref[c][k], 6e-5);
    EXPECT_LT(result_.cases[c].residual_computed, 1e-12);
  }
}

TEST_F(Paper001, ArbitraryYLeaveTheReportedResidual) {
  const double ref[2] = {0.277, 0.035};
  for (std::size_t c = 0; c < 2; ++c) {
    const double rk = amplitude(end_state(kTaus001[c], 0.25, 0.25));
    EXPECT_NEAR(result_.cases[c].residual_arbitrary, rk, 1e-9);
    EXPECT_NEAR(rk, ref[c], 1e-3);
  }
}

double width_by_bisection(const std::function<double(double)>& v, double thr) {
  auto edge = [&](double lo_in, double hi_out) {
    for (int i = 0; i < 200; ++i) {
      const double m = 0.5 * (lo_in + hi_out);
      (v(m) <= thr ? lo_in : hi_out) = m;
    }
    return lo_in;
  };
  return edge(1.0, 2.0) - edge(1.0, 0.5);
}

TEST_F(Paper001, TextbookShaperWidthsAtZeroDamping) {
  // ZV: |cos(pi r / 2)| <= 5 %; ZVD: cos^2 <= 5 %: closed forms.
  const double zv = 4.0 / M_PI * std::asin(0.05), zvd = 4.0 / M_PI * std::asin(std::sqrt(0.05));
  // EI (Singhose): impulses (1+V)/4, (1-V)/2, (1+V)/4 at 0, T/2, T with V = 5 %.
  const double vt = 0.05;
  auto ei = [&](double r) {
    const std::complex<double> s = (1 + vt) / 4 + (1 - vt) / 2 * std::exp(std::complex<double>{0, M_PI * r}) +
                                   (1 + vt) / 4 * std::exp(std::complex<double>{0, 2 * M_PI * r});
    return std::abs(s);
  };
  const double eiw = width_by_bisection(ei, vt * (1 + 1e-12));
  std::map<std::string, double> got;
  for (const Width001& w : result_.widths) {
    if (w.zeta == 0.0) got[w.method] = w.width.width;
  }
  EXPECT_NEAR(got["zv"], zv, 1e-8);
  EXPECT_NEAR(got["zvd"], zvd, 1e-8);
  EXPECT_NEAR(got["ei"], eiw, 1e-6);
  EXPECT_NEAR(zv, 0.0637, 1e-4);
  EXPECT_NEAR(zvd, 0.2871, 1e-4);
  EXPECT_NEAR(eiw, 0.3995, 1e-3);
}

TEST_F(Paper001, EveryComparedCommandIsExactOnTheNominalPlant) {
  ModalPlant p;
  ASSERT_EQ(ModalPlant::make_sdof({}, p), SimStatus::ok);
  for (int degree : {3, 5}) {
    ModalPlant q = p;
    ASSERT_EQ(drive(q, InverseDynamicsCommand{1.0, 0.167, kW, kZ, degree}, 1e-4), SimStatus::ok);
    EXPECT_LT(q.residual_amplitude(), 1e-10) << "Sahinkaya, degree " << degree;
  }
  core::MoveRequest r;
  r.profile = core::ProfileKind::ramp_versine;
  r.distance = 1.0;
  r.time = 0.167;
  r.omega = kW;
  r.zeta = kZ;
  r.shaper = core::ShaperKind::zv;
  core::Move<double> m;
  ASSERT_EQ(core::plan(r, m), core::Status::ok);
  ModalPlant q = p;
  ASSERT_EQ(drive(q, MoveCommand{m}, 1e-4), SimStatus::ok);
  EXPECT_LT(q.residual_amplitude(), 1e-12) << "hybrid";
}

}  // namespace
}  // namespace settle::sim
