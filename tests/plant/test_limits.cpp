// SPDX-License-Identifier: Apache-2.0
// Every size sim computes with is checked against limits.hpp before anything is allocated, and
// every search ends: the settling time of a mode whose decay time overflows (a denormal damping
// ratio), an undamped mode, tails and grids beyond the bounds, too many modes or sweep points.
// The tests that hung before the fix arm an alarm: a hang kills the test instead of the suite.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <limits>

#include "planned_moves.hpp"
#include "settle/core/planner.hpp"
#include "settle/commission/energy_optimiser.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/sensitivity.hpp"
#include "settle/plant/simulate.hpp"

namespace settle::plant {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Ends the process (a test failure) if a call that must be bounded does not return.
struct HangGuard {
  HangGuard() { alarm(120); }
  ~HangGuard() { alarm(0); }
  HangGuard(const HangGuard&) = delete;
  HangGuard& operator=(const HangGuard&) = delete;
};

ModalPlant modes_plant(std::vector<Mode> modes) {
  ModalPlant p;
  EXPECT_EQ(ModalPlant::make_modes(modes, 1.0, PlantKind::modes, p), SimStatus::ok);
  return p;
}

Mode mode(double omega, double zeta) {
  Mode m;
  m.omega = omega;
  m.zeta = zeta;
  return m;
}

using testing::poly345;

// The reproduction: settle simulate --plant modes --mode 10,1e-320,1 --profile poly345
// --distance 0.1 --time 0.5 never ended (1 / (zeta w) overflows to infinity).
TEST(Limits, DenormalDampingEndsBeyondTheHorizon) {
  const HangGuard guard;
  const ModalPlant p = modes_plant({mode(10.0, 1e-320)});
  SimResult r;
  ASSERT_EQ(simulate(p, MoveCommand{poly345(0.1, 0.5)}, SimOptions{}, r), SimStatus::ok);
  EXPECT_EQ(r.metrics.settling, Settling::beyond_horizon);
  EXPECT_TRUE(std::isinf(r.metrics.settling_time));
  EXPECT_GT(r.metrics.residual_amplitude, r.metrics.band);  // it really is outside the band
  // As `settle stream` runs it for its continuous reference: without recording.
  SimOptions o;
  o.record = false;
  SimResult s;
  ASSERT_EQ(simulate(p, MoveCommand{poly345(0.1, 0.5)}, o, s), SimStatus::ok);
  EXPECT_EQ(s.metrics.settling, Settling::beyond_horizon);
}

TEST(Limits, DenormalDampingInTheClosedFormSearchDirectly) {
  const HangGuard guard;
  ModalPlant p = modes_plant({mode(10.0, std::numeric_limits<double>::denorm_min())});
  Eigen::VectorXd x(2);
  x << 1.0, 0.0;
  p.linear().set_state(x, BaseState{}, 0.0);
  const FreeSettling f = free_settling_time(p, 0.01);
  EXPECT_EQ(f.status, Settling::beyond_horizon);
  EXPECT_TRUE(std::isinf(f.time));
}

// Damped, but so lightly that e^{-zeta w t} is still above the band after the horizon: refused
// by the bound, not searched. zeta w = 1e-5 /s: the amplitude 1 falls to 0.01 after 4.6e5 s.
TEST(Limits, DecayLongerThanTheHorizonIsReportedNotSearched) {
  ModalPlant p = modes_plant({mode(10.0, 1e-6)});
  Eigen::VectorXd x(2);
  x << 1.0, 0.0;
  p.linear().set_state(x, BaseState{}, 0.0);
  EXPECT_EQ(free_settling_time(p, 0.01).status, Settling::beyond_horizon);
  // zeta w = 1e-2 /s: 460 s, inside the horizon: found, and after the envelope's crossing
  // ln(100) / (zeta w) minus at most one period.
  ModalPlant q = modes_plant({mode(10.0, 1e-3)});
  q.linear().set_state(x, BaseState{}, 0.0);
  const FreeSettling f = free_settling_time(q, 0.01);
  ASSERT_EQ(f.status, Settling::settled);
  const double crossing = std::log(100.0 / std::sqrt(1.0 - 1e-6)) / 1e-2;
  EXPECT_LE(f.time, crossing + 1e-6);
  EXPECT_GE(f.time, crossing - 2.0 * M_PI / 10.0);
}

// Documented behaviour of zeta = 0 (SimMetrics, free_settling_time): an undamped mode whose
// amplitude alone exceeds the band never settles (Settling::undamped, +inf); one within the band
// does not stop the damped modes from settling, at the time the closed form gives.
TEST(Limits, UndampedModeNeverSettlesUnlessItIsInsideTheBand) {
  const ModalPlant p = modes_plant({mode(20.0, 0.0)});
  SimResult r;
  ASSERT_EQ(simulate(p, StepsCommand{1.0, core::Shaper<double>{}}, SimOptions{}, r), SimStatus::ok);
  EXPECT_EQ(r.metrics.settling, Settling::undamped);
  EXPECT_TRUE(std::isinf(r.metrics.settling_time));

  // q1 = 0.002 cos(20 t) (undamped, inside the band 0.01) plus q2 = e^{-5 t}(cos wd t + (5/wd) sin wd t).
  ModalPlant q = modes_plant({mode(20.0, 0.0), mode(50.0, 0.1)});
  Eigen::VectorXd x(4);
  x << 0.002, 0.0, 1.0, 0.0;
  q.linear().set_state(x, BaseState{}, 0.0);
  const FreeSettling f = free_settling_time(q, 0.01);
  ASSERT_EQ(f.status, Settling::settled);
  const double s = 5.0, wd = 50.0 * std::sqrt(1.0 - 0.01);
  double last = 0.0;
  for (double t = 0.0; t < 3.0; t += 1e-6) {
    const double y = 0.002 * std::cos(20.0 * t) + std::exp(-s * t) * (std::cos(wd * t) + s / wd * std::sin(wd * t));
    if (std::fabs(y) > 0.01) last = t;
  }
  EXPECT_NEAR(f.time, last, 2e-6);
}

TEST(Limits, TailBeyondTheTimeBoundIsRefusedBeforeAnyConversion) {
  const ModalPlant p = modes_plant({mode(10.0, 0.1)});
  const MoveCommand cmd{poly345(0.1, 0.5)};
  for (double tail : {1e300, kInf, kNaN, kMaxSimulatedTime}) {
    SimOptions o;
    o.tail = tail;
    SimResult r;
    EXPECT_EQ(simulate(p, cmd, o, r), SimStatus::too_long) << tail;
    EXPECT_TRUE(r.history.empty());
  }
  // Without recording, the tail is not simulated and not checked.
  SimOptions o;
  o.tail = 1e300;
  o.record = false;
  SimResult r;
  EXPECT_EQ(simulate(p, cmd, o, r), SimStatus::ok);
}

TEST(Limits, MoveLongerThanTheTimeBoundIsRefused) {
  const ModalPlant p = modes_plant({mode(10.0, 0.1)});
  SimOptions o;
  o.record = false;
  o.dt = 1.0;  // a coarse grid: only the duration bound can refuse this
  SimResult r;
  EXPECT_EQ(simulate(p, MoveCommand{poly345(0.1, kMaxSimulatedTime + 1.0)}, o, r), SimStatus::too_long);
  EXPECT_EQ(simulate(p, MoveCommand{poly345(0.1, kMaxSimulatedTime - 1.0)}, o, r), SimStatus::ok);
}

TEST(Limits, GridOfMoreThanTheSampleBoundIsRefused) {
  const ModalPlant p = modes_plant({mode(10.0, 0.1)});
  const MoveCommand cmd{poly345(0.1, 0.3)};
  SimOptions o;
  o.record = false;
  o.dt = 0.3 / (1.05 * static_cast<double>(kMaxSamples));
  SimResult r;
  EXPECT_EQ(simulate(p, cmd, o, r), SimStatus::too_many_samples);
  std::vector<double> grid;
  EXPECT_EQ(command_grid(cmd, o.dt, grid), SimStatus::too_many_samples);
  EXPECT_TRUE(grid.empty());
  ModalPlant driven = p;
  EXPECT_EQ(drive(driven, cmd, o.dt), SimStatus::too_many_samples);
  EXPECT_EQ(command_grid(cmd, 0.0, grid), SimStatus::non_positive_step);
}

TEST(Limits, RecordedGridAndTailCountTogether) {
  // 0.3 s + 1 s at 1e-7 s: 1.3e7 rows, each under the bound alone.
  const ModalPlant p = modes_plant({mode(10.0, 0.1)});
  SimOptions o;
  o.dt = 1e-7;
  o.tail = 1.0;
  SimResult r;
  EXPECT_EQ(simulate(p, MoveCommand{poly345(0.1, 0.3)}, o, r), SimStatus::too_many_samples);
  EXPECT_TRUE(r.history.empty());
}

TEST(Limits, AtMostKMaxModes) {
  std::vector<Mode> modes;
  for (std::size_t j = 0; j < kMaxModes; ++j) modes.push_back(mode(10.0 + static_cast<double>(j), 0.01));
  ModalPlant p;
  EXPECT_EQ(ModalPlant::make_modes(modes, 1.0, PlantKind::modes, p), SimStatus::ok);
  modes.push_back(mode(100.0, 0.01));
  ModalPlant q;
  EXPECT_EQ(ModalPlant::make_modes(modes, 1.0, PlantKind::modes, q), SimStatus::too_many_modes);
  EXPECT_TRUE(q.modes().empty());
  PlantSpec s;
  s.kind = PlantKind::modes;
  s.modes = modes;
  EXPECT_EQ(make_plant(s, q), SimStatus::too_many_modes);
  const auto n = static_cast<Eigen::Index>(kMaxStates + 2);
  LinearPlant lp;
  EXPECT_EQ(LinearPlant::make(Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXd::Zero(n, 3), Eigen::MatrixXd::Zero(1, n),
                              Eigen::MatrixXd::Zero(1, 3), lp),
            SimStatus::too_many_modes);
}

TEST(Limits, SweepsAreBounded) {
  const HangGuard guard;
  const StepsCommand step{1.0, core::Shaper<double>{}};
  std::vector<SensitivityPoint> pts;
  EXPECT_EQ(omega_sensitivity(step, 10.0, 0.0, 0.5, 2.0, kMaxSweepPoints + 1, pts), SimStatus::too_many_samples);
  EXPECT_EQ(zeta_sensitivity(step, 10.0, 0.1, 0.5, kInf, 10, pts), SimStatus::bad_range);
  EXPECT_TRUE(pts.empty());
  // A shaped step never leaves more than 100 % PRV: under a 150 % threshold and with no upper
  // bound on the search, the walk never ended.
  core::Shaper<double> s;
  ASSERT_EQ(core::design_shaper(core::ShaperKind::zv, 10.0, 0.0, 0.05, s), core::Status::ok);
  InsensitivityWidth w;
  EXPECT_EQ(insensitivity_width(StepsCommand{1.0, s}, 10.0, 0.0, 150.0, w, 0.25, kInf), SimStatus::bad_range);
  EXPECT_EQ(insensitivity_width(StepsCommand{1.0, s}, 10.0, 0.0, 150.0, w, kNaN, 3.0), SimStatus::bad_range);
  // Bounded: both walks reach their limits.
  ASSERT_EQ(insensitivity_width(StepsCommand{1.0, s}, 10.0, 0.0, 150.0, w), SimStatus::ok);
  EXPECT_TRUE(w.lo_open && w.hi_open);
  EXPECT_DOUBLE_EQ(w.hi, 3.0);
}

TEST(Limits, EnergyQuadratureIsBounded) {
  // One quadrature panel per 2 rad of w T: w = 1e300 was an out-of-range float-to-int conversion,
  // w T = 1e7 five million panels.
  commission::EnergyTarget t;
  t.zeta = 0.02;
  t.distance = 1.0;
  t.duration = 1.0;
  commission::EnergyIntegrals e;
  for (double w : {1e300, 1e7, 2.0 * kMaxEnergyPhase}) {
    t.omega = w;
    EXPECT_EQ(commission::energy_integrals(t, {3.0, 4.0, 5.0}, e), SimStatus::too_many_samples) << w;
    commission::OptimiserResult o;
    EXPECT_EQ(commission::optimise_exponents(t, {3.0, 4.0, 5.0}, commission::OptimiserOptions{}, o), SimStatus::too_many_samples) << w;
  }
  t.omega = 1e4;
  EXPECT_EQ(commission::energy_integrals(t, {3.0, 4.0, 5.0}, e), SimStatus::ok);
}

TEST(Limits, OverflowingPlantIsAStatusNotANumber) {
  // k = 1e308: w dt = 1e150, the step's matrix exponential overflows. A status, not NaN metrics.
  ModalPlant p;
  ASSERT_EQ(ModalPlant::make_sdof({1.0, 1e308, 9.0}, p), SimStatus::ok);
  SimResult r;
  EXPECT_EQ(simulate(p, MoveCommand{poly345(0.1, 0.5)}, SimOptions{}, r), SimStatus::non_finite_result);
}

}  // namespace
}  // namespace settle::plant
