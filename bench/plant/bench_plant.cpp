// SPDX-License-Identifier: Apache-2.0
// What sim costs: one second of the 3-mode Table 1 beam at 10 kHz (the drive node's per-SYNC
// stepping, and an offline run of a planned move), and the seed-004 optimiser from (3, 4, 5).
// Targets (issue 3): the beam second <= 1 ms, the optimiser <= 50 ms, in Release.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "settle/core/planner.hpp"
#include "settle/commission/energy_optimiser.hpp"
#include "settle/plant/sensitivity.hpp"
#include "settle/plant/simulate.hpp"
#include "settle/commission/tune.hpp"

namespace {

using namespace settle;

constexpr double kDt = 1e-4;
constexpr int kSteps = 10000;  // 1 s at 10 kHz

core::Move<double> scurve_08(double w1) {
  core::MoveRequest r;
  r.profile = core::ProfileKind::scurve;
  r.distance = 0.07;
  r.time = 0.8 * 2.0 * M_PI / w1;
  r.set_mode(w1);
  core::Move<double> m;
  (void)core::plan(r, m);
  return m;
}

// The drive node's loop: linear interpolation between 10 kHz setpoints, one exact step each.
void BM_Beam3Mode1sLinearSetpoints(benchmark::State& state) {
  plant::ModalPlant beam;
  (void)plant::ModalPlant::make_beam({}, beam);
  const core::Move<double> m = scurve_08(beam.fundamental().omega);
  std::vector<double> sp(kSteps + 1);
  for (int k = 0; k <= kSteps; ++k) sp[static_cast<std::size_t>(k)] = m.at(k * kDt).p;
  for (auto _ : state) {
    beam.reset(0.0);
    for (std::size_t k = 0; k < kSteps; ++k) {
      if (beam.advance(kDt, plant::BasePolynomial::linear(sp[k], sp[k + 1], kDt)) != plant::SimStatus::ok) {
        state.SkipWithError("advance failed");
      }
    }
    benchmark::DoNotOptimize(beam.deflection());
  }
  state.SetItemsProcessed(state.iterations() * kSteps);
}
BENCHMARK(BM_Beam3Mode1sLinearSetpoints)->Unit(benchmark::kMicrosecond);

// Follows the move offline, then holds the base for the rest of the second.
void follow_then_rest(plant::ModalPlant& beam, const plant::MoveCommand& cmd, int rest, benchmark::State& state) {
  if (drive(beam, cmd, kDt) != plant::SimStatus::ok) state.SkipWithError("drive failed");
  const plant::BasePolynomial hold = plant::BasePolynomial::constant(cmd.final_position());
  for (int k = 0; k < rest; ++k) (void)beam.advance(kDt, hold);
  benchmark::DoNotOptimize(beam.residual_amplitude());
}

// Offline: follow the planned S-curve by quintic Hermite pieces (sampling the profile, exact at its
// breakpoints), then rest for the rest of the second.
void BM_Beam3Mode1sFollowMove(benchmark::State& state) {
  plant::ModalPlant beam;
  (void)plant::ModalPlant::make_beam({}, beam);
  const plant::MoveCommand cmd{scurve_08(beam.fundamental().omega)};
  const int rest = kSteps - static_cast<int>(std::ceil(cmd.duration() / kDt));
  for (auto _ : state) follow_then_rest(beam, cmd, rest, state);
}
BENCHMARK(BM_Beam3Mode1sFollowMove)->Unit(benchmark::kMicrosecond);

// The same from scratch each time: beam modal analysis and every matrix exponential included.
void BM_Beam3Mode1sFollowMoveCold(benchmark::State& state) {
  plant::ModalPlant probe;
  (void)plant::ModalPlant::make_beam({}, probe);
  const plant::MoveCommand cmd{scurve_08(probe.fundamental().omega)};
  const int rest = kSteps - static_cast<int>(std::ceil(cmd.duration() / kDt));
  for (auto _ : state) {
    plant::ModalPlant beam;
    (void)plant::ModalPlant::make_beam({}, beam);
    follow_then_rest(beam, cmd, rest, state);
  }
}
BENCHMARK(BM_Beam3Mode1sFollowMoveCold)->Unit(benchmark::kMicrosecond);

void BM_Optimiser004(benchmark::State& state) {
  const commission::EnergyTarget t = commission::belt_energy_target(plant::BeltParams{}, 30.0 * M_PI, 1.0);
  for (auto _ : state) {
    commission::OptimiserResult r;
    if (commission::optimise_exponents(t, {3.0, 4.0, 5.0}, commission::OptimiserOptions{}, r) != plant::SimStatus::ok) {
      state.SkipWithError("optimiser failed");
    }
    benchmark::DoNotOptimize(r.h_final);
  }
}
BENCHMARK(BM_Optimiser004)->Unit(benchmark::kMillisecond);

// settle tune's residual: the Duhamel quadrature (relative_residual) against the exact-stepping
// simulation it replaces in the search (prv_on_mode), on the same shaped move and mode.
core::Move<double> tune_bench_move() {
  core::MoveRequest r;
  r.profile = core::ProfileKind::poly345;
  r.distance = 0.1;
  r.time = 0.4;
  r.set_mode(12.566, 0.03);
  r.shaper = core::ShaperKind::zvd;
  core::Move<double> m;
  (void)core::plan(r, m);
  return m;
}

void BM_TuneResidualQuadrature(benchmark::State& state) {
  const core::Move<double> m = tune_bench_move();
  double w = 11.0;
  for (auto _ : state) {
    double r = 0.0;
    (void)commission::relative_residual(m, w, 0.03, r);
    benchmark::DoNotOptimize(r);
    w = w < 14.0 ? w + 0.01 : 11.0;
  }
}
BENCHMARK(BM_TuneResidualQuadrature)->Unit(benchmark::kMicrosecond);

void BM_TuneResidualSimulated(benchmark::State& state) {
  const plant::MoveCommand cmd{tune_bench_move()};
  double w = 11.0;
  for (auto _ : state) {
    double prv = 0.0;
    (void)plant::prv_on_mode(cmd, w, 0.03, prv);
    benchmark::DoNotOptimize(prv);
    w = w < 14.0 ? w + 0.01 : 11.0;
  }
}
BENCHMARK(BM_TuneResidualSimulated)->Unit(benchmark::kMicrosecond);

// A whole search: two modes with +-10 % bands, limits (what docs/tuning.md's example asks).
void BM_TuneTwoModesLimits(benchmark::State& state) {
  auto band = [](double w, double z) {
    return commission::UncertainMode{.omega = w, .zeta = z, .gain = 1.0, .omega_lo = 0.9 * w, .omega_hi = 1.1 * w,
                              .zeta_lo = z - 0.01, .zeta_hi = z + 0.01};
  };
  const commission::TuneMove mv{.distance = 0.1, .time = {}, .limits = {.vmax = 0.5, .amax = 5.0, .jmax = 200.0}};
  for (auto _ : state) {
    commission::TuneResult r;
    if (commission::tune({band(12.566, 0.03), band(44.0, 0.02)}, mv, {}, r) != commission::TuneStatus::ok) {
      state.SkipWithError("tune failed");
    }
    benchmark::DoNotOptimize(r.chosen);
  }
}
BENCHMARK(BM_TuneTwoModesLimits)->Unit(benchmark::kMillisecond);

}  // namespace
