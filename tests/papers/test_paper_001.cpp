// SPDX-License-Identifier: Apache-2.0
// Seeds 001/002 reproduced: the Y values by solving the zero-residual condition numerically with
// an independent RK4 integration of the mass-spring-damper, the residuals of the arbitrary Y, and
// the textbook shaper insensitivity widths by independent formulas.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "rk4.hpp"
#include "settle/core/planner.hpp"
#include "settle/papers/reproduce.hpp"

namespace settle::papers {
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
    ASSERT_EQ(reproduce_001(o, result_), plant::SimStatus::ok);
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
  plant::ModalPlant p;
  ASSERT_EQ(plant::ModalPlant::make_sdof({}, p), plant::SimStatus::ok);
  for (int degree : {3, 5}) {
    plant::ModalPlant q = p;
    ASSERT_EQ(drive(q, plant::InverseDynamicsCommand{1.0, 0.167, kW, kZ, degree}, 1e-4), plant::SimStatus::ok);
    EXPECT_LT(q.residual_amplitude(), 1e-10) << "Sahinkaya, degree " << degree;
  }
  core::MoveRequest r;
  r.profile = core::ProfileKind::ramp_versine;
  r.distance = 1.0;
  r.time = 0.167;
  r.set_mode(kW, kZ);
  r.shaper = core::ShaperKind::zv;
  core::Move<double> m;
  ASSERT_EQ(core::plan(r, m), core::Status::ok);
  plant::ModalPlant q = p;
  ASSERT_EQ(drive(q, plant::MoveCommand{m}, 1e-4), plant::SimStatus::ok);
  EXPECT_LT(q.residual_amplitude(), 1e-12) << "hybrid";
}

// ---- The robustness comparison, like for like ------------------------------------------------
// Independent of the simulator. A command y(t) that moves the plant from rest leaves, once its
// forcing has died out, z = x - y = -Im[e^{st} I] / w_d, with s = -zeta w + i w_d the TRUE plant's
// pole and I = int_0^inf y''(u) e^{-su} du = s int_0^inf y'(u) e^{-su} du (Duhamel's integral of
// z'' + 2 zeta w z' + w^2 z = -y'' against e^{-zeta w t} sin(w_d t) / w_d). Its amplitude at any
// time t, extended to t_ref by the same decay, is |I| e^{-zeta w t_ref} / w_d: no end time and no
// cut-off enter.
const std::complex<double> kPole{-kZ * kW, kW * std::sqrt(1 - kZ * kZ)};

double referred(std::complex<double> velocity_transform, double t_ref) {
  return std::abs(kPole * velocity_transform) * std::exp(-kZ * kW * t_ref) / kPole.imag();
}

// int_0^tau y'(u) e^{-su} du for the family y' = (R / 2pi)(1 - a cos Ru + b sin Ru), R = 2 pi / tau
// (the ramp: a = b = 0; the proposed command: a = Y2/L, b = Y3/L), from int_0^tau e^{cu} du.
std::complex<double> family_velocity(double tau, double a, double b) {
  const double r = 2 * M_PI / tau;
  const std::complex<double> i{0, 1};
  auto e = [&](std::complex<double> c) { return (std::exp(c * tau) - 1.0) / c; };
  const std::complex<double> up = e(-kPole + i * r), down = e(-kPole - i * r);
  return r / (2 * M_PI) * (e(-kPole) - a * (up + down) / 2.0 + b * (up - down) / (2.0 * i));
}

// The proposed command designed for (ws, zs): Y2/L = 1 - R^2/ws^2, Y3/L = 2 zs R / ws (SEEDS.md B).
std::complex<double> proposed_velocity(double tau, double ws, double zs) {
  const double r = 2 * M_PI / tau;
  return family_velocity(tau, 1 - r * r / (ws * ws), 2 * zs * r / ws);
}

// sum_i A_i e^{-s t_i} of Singer & Seering's ZV (n = 1) and ZVD (n = 2) designed for (ws, zs):
// binomial amplitudes in K = exp(-zs pi / sqrt(1 - zs^2)) at multiples of pi / w_d*.
std::complex<double> shaper_phasor(int n, double ws, double zs) {
  const double k = std::exp(-zs * M_PI / std::sqrt(1 - zs * zs)), half = M_PI / (ws * std::sqrt(1 - zs * zs));
  std::complex<double> sum = 0.0;
  double binom = 1.0;
  for (int i = 0; i <= n; ++i) {
    sum += binom * std::pow(k, i) / std::pow(1 + k, n) * std::exp(-kPole * (i * half));
    binom = binom * (n - i) / (i + 1);
  }
  return sum;
}

// Sahinkaya's input for an output polynomial x of duration T: y = x + w, 2 zs ws w' + ws^2 w = x'',
// w(0) = 0, w -> 0. Transforming at s: int w' e^{-su} = s int w e^{-su}, and
// (2 zs ws s + ws^2) int w e^{-su} = int x'' e^{-su} = s X1 (x' = 0 at both ends), so
// int y' e^{-su} = X1 (1 + s^2 / (2 zs ws s + ws^2)), X1 = int_0^T x' e^{-su} by parts (x' a polynomial).
std::complex<double> sahinkaya_velocity(double tt, int degree, double ws, double zs) {
  // x' / L as polynomial coefficients in t, lowest first.
  std::vector<double> c = degree == 3 ? std::vector<double>{0, 6 / std::pow(tt, 2), -6 / std::pow(tt, 3)}
                                      : std::vector<double>{0, 0, 30 / std::pow(tt, 3), -60 / std::pow(tt, 4),
                                                            30 / std::pow(tt, 5)};
  // int p e^{-su} = -e^{-su} sum_k p^(k)(u) / s^(k+1).
  auto antiderivative = [&](double u) {
    std::vector<double> p = c;
    std::complex<double> acc = 0.0, sk = kPole;
    while (!p.empty()) {
      double v = 0.0;
      for (std::size_t j = p.size(); j-- > 0;) v = v * u + p[j];
      acc += v / sk;
      sk *= kPole;
      for (std::size_t j = 1; j < p.size(); ++j) p[j - 1] = static_cast<double>(j) * p[j];
      p.pop_back();
    }
    return -std::exp(-kPole * u) * acc;
  };
  const std::complex<double> x1 = antiderivative(tt) - antiderivative(0.0);
  return x1 * (1.0 + kPole * kPole / (2 * zs * ws * kPole + ws * ws));
}

// The independent residual of each compared method designed for (ws, zs), referred to t_ref.
double independent_residual(const std::string& method, double ws, double zs, double t_ref) {
  const double tau = kTaus001[0];
  std::complex<double> v = 0.0;
  if (method == "proposed") v = proposed_velocity(tau, ws, zs);
  if (method == "hybrid") v = proposed_velocity(tau, ws, zs) * shaper_phasor(1, ws, zs);
  if (method == "zv") v = family_velocity(tau, 0, 0) * shaper_phasor(1, ws, zs);
  if (method == "zvd") v = family_velocity(tau, 0, 0) * shaper_phasor(2, ws, zs);
  if (method == "sahinkaya") v = sahinkaya_velocity(tau, 5, ws, zs);
  if (method == "sahinkaya-cubic") v = sahinkaya_velocity(tau, 3, ws, zs);
  return referred(v, t_ref);
}

class Robust001 : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    Options001 o;
    o.history = false;
    ASSERT_EQ(reproduce_001(o, result_), plant::SimStatus::ok);
  }
  static const Grid001& grid(const std::string& m) {
    for (const Grid001& g : result_.grids) {
      if (g.method == m) return g;
    }
    throw std::runtime_error{"no grid " + m};
  }
  static Result001 result_;
};
Result001 Robust001::result_;

TEST_F(Robust001, EveryMethodMovesInTheSameTimeAndIsReferredToIt) {
  EXPECT_DOUBLE_EQ(result_.residual_at, 0.167);
  const double tau = kTaus001[0];
  const double half = M_PI / (kW * std::sqrt(1 - kZ * kZ));  // ZV's second impulse
  EXPECT_NEAR(grid("proposed").duration, tau, 1e-12);
  EXPECT_NEAR(grid("zv").duration, tau + half, 1e-12);      // a ramp of tau, shaped
  EXPECT_NEAR(grid("zvd").duration, tau + 2 * half, 1e-12);
  EXPECT_NEAR(grid("hybrid").duration, tau + half, 1e-12);
  EXPECT_GT(grid("sahinkaya").duration, tau + 0.3);         // its tail
}

// The grid's corners (and every other point) against the Laplace transform of the command: ZV and
// ZVD on the ramp, the proposed command and the hybrid (phasor sums), Sahinkaya's two inputs.
TEST_F(Robust001, GridAgreesWithTheIndependentResidual) {
  for (const char* m : {"proposed", "zv", "zvd", "hybrid", "sahinkaya", "sahinkaya-cubic"}) {
    const Grid001& g = grid(m);
    const std::size_t n = g.eps.size();
    ASSERT_EQ(n, 21u);
    EXPECT_NEAR(g.eps.front(), -0.2, 1e-15);
    EXPECT_NEAR(g.eps.back(), 0.2, 1e-15);
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        const double want = independent_residual(m, kW * (1 + g.eps[i]), kZ * (1 + g.eps[j]), 0.167);
        worst = std::max(worst, want);
        EXPECT_NEAR(g.residual[i * n + j], want, 1e-8) << m << " eps(w) " << g.eps[i] << " eps(zeta) " << g.eps[j];
      }
    }
    EXPECT_NEAR(g.worst, worst, 1e-8) << m;
    EXPECT_LT(g.nominal, 1e-12) << m;
  }
}

// Sahinkaya's command only ends where its tail is cut; its own-end residual moves with the cut,
// the referred one does not.
TEST_F(Robust001, SahinkayaReferredResidualDoesNotDependOnTheTailCutOff) {
  for (double e : {-0.2, 0.2}) {
    const double ws = kW * (1 + e), zs = kZ * (1 + e);
    const double want = independent_residual("sahinkaya", ws, zs, 0.167);
    std::vector<double> own_end;
    for (double cut : {1e-10, 1e-13, 1e-16}) {
      const plant::InverseDynamicsCommand c{1.0, 0.167, ws, zs, 5, cut};
      double r = 0.0;
      ASSERT_EQ(referred_residual_001(c, 2e-4, 0.167, r), plant::SimStatus::ok);
      EXPECT_NEAR(r, want, 1e-8) << "cut-off " << cut;
      plant::ModalPlant p;
      ASSERT_EQ(plant::ModalPlant::make_sdof({}, p), plant::SimStatus::ok);
      ASSERT_EQ(drive(p, c, 2e-4), plant::SimStatus::ok);
      own_end.push_back(p.residual_amplitude());
    }
    // Each 1e-3 of cut-off is 3 kappa* = 3 x 2 zs / ws more tail, a factor exp(6 zeta zs w / ws).
    EXPECT_GT(own_end[0] / own_end[1], 1.2) << e;
    EXPECT_GT(own_end[1] / own_end[2], 1.2) << e;
  }
}

TEST(Referred001, RefusesWhatItCannotRefer) {
  const plant::InverseDynamicsCommand c{1.0, 0.167, kW, kZ};
  double r = -1.0;
  EXPECT_EQ(referred_residual_001(c, 2e-4, std::nan(""), r), plant::SimStatus::bad_range);
  EXPECT_EQ(referred_residual_001(c, 2e-4, -HUGE_VAL, r), plant::SimStatus::bad_range);
  EXPECT_EQ(referred_residual_001(plant::InverseDynamicsCommand{0.0, 0.167, kW, kZ}, 2e-4, 0.167, r), plant::SimStatus::bad_range);
  // exp(zeta w_n x 1e3 s) overflows.
  EXPECT_EQ(referred_residual_001(c, 2e-4, -1e3, r), plant::SimStatus::non_finite_result);
  EXPECT_EQ(r, -1.0);
}

// The artefact docs/simulation.md describes, over the whole grid: the worst residual at the
// command's own end falls as the tail is cut later; referred to 0.167 s it stays 0.2640 (a cut at
// 1e-3 D is itself a step big enough to show).
TEST_F(Robust001, SahinkayaOwnEndWorstFollowsTheCutOff) {
  const double cuts[4] = {1e-3, 1e-6, 1e-10, 1e-16}, own_end[4] = {0.2030, 0.1429, 0.0897, 0.0461};
  const double referred_tol[4] = {5e-4, 1e-6, 1e-6, 1e-6};
  const Grid001& g = grid("sahinkaya");
  for (int k = 0; k < 4; ++k) {
    double worst_own = 0.0, worst_referred = 0.0;
    for (double ew : g.eps) {
      for (double ez : g.eps) {
        const plant::InverseDynamicsCommand c{1.0, 0.167, kW * (1 + ew), kZ * (1 + ez), 5, cuts[k]};
        plant::ModalPlant p;
        ASSERT_EQ(plant::ModalPlant::make_sdof({}, p), plant::SimStatus::ok);
        ASSERT_EQ(drive(p, c, 2e-4), plant::SimStatus::ok);
        worst_own = std::max(worst_own, p.residual_amplitude());
        double r = 0.0;
        ASSERT_EQ(referred_residual_001(c, 2e-4, 0.167, r), plant::SimStatus::ok);
        worst_referred = std::max(worst_referred, r);
      }
    }
    EXPECT_NEAR(worst_own, own_end[k], 1e-4) << cuts[k];
    EXPECT_NEAR(worst_referred, g.worst, referred_tol[k]) << cuts[k];
  }
  EXPECT_NEAR(g.worst, 0.2640, 1e-4);
}

// What docs/simulation.md reports: referred to the common time, the hybrid is more robust than
// Sahinkaya's input (both outputs) and than the proposed command; the shaped ramps rank EI, ZVD, ZV.
TEST_F(Robust001, PaperRankingOnTheCommonTime) {
  EXPECT_LT(grid("hybrid").worst, grid("sahinkaya").worst);
  EXPECT_LT(grid("hybrid").worst, grid("sahinkaya-cubic").worst);
  EXPECT_LT(grid("hybrid").worst, 0.6 * grid("proposed").worst);
  EXPECT_LT(grid("ei").worst, grid("zvd").worst);
  EXPECT_LT(grid("zvd").worst, grid("zv").worst);
  EXPECT_NEAR(grid("proposed").worst, 0.2738, 1e-4);
  EXPECT_NEAR(grid("zv").worst, 0.1269, 1e-4);
  EXPECT_NEAR(grid("zvd").worst, 0.0666, 1e-4);
  EXPECT_NEAR(grid("ei").worst, 0.0381, 1e-4);
  EXPECT_NEAR(grid("ei").nominal, 0.0330, 1e-4);
  EXPECT_NEAR(grid("sahinkaya").worst, 0.2640, 1e-4);
  EXPECT_NEAR(grid("sahinkaya-cubic").worst, 0.2213, 1e-4);
  EXPECT_NEAR(grid("hybrid").worst, 0.1438, 1e-4);
}

}  // namespace
}  // namespace settle::papers
