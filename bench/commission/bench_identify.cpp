// SPDX-License-Identifier: Apache-2.0
// What identifying a machine costs: the estimator (settle/commission/identify.hpp) on 5 s of a seeded
// synthetic three-mode record (1 kHz, 1-count quantisation, 1 % noise), looking for up to three
// modes. Target (issue 15): <= 50 ms, in Release. Also the default record and the hardest case.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdlib>
#include <vector>

#include "identify_record.hpp"
#include "settle/commission/identify.hpp"

namespace {

using namespace settle;

// `modes` recorded with the excitation `ex`, 1 % noise (seeded by `seed`), fitted repeatedly;
// an error unless as many modes are found.
void identify(benchmark::State& state, const std::vector<plant::Mode>& modes, const settle::testing::Excitation& ex,
              std::uint64_t seed) {
  settle::testing::Record rec{};
  if (!settle::testing::make_record(modes, 0.01, seed, rec, ex)) std::abort();
  commission::IdentifyInput in{};
  in.period_s = rec.period_s;
  in.counts_per_unit = rec.counts_per_unit;
  in.load_counts_per_unit = rec.load_counts_per_unit;
  in.motor = rec.motor;
  in.load = rec.load;
  std::size_t found = 0;
  for (auto _ : state) {
    const commission::IdentifyResult r = commission::identify_modes(in, {});
    found = r.modes.size();
    benchmark::DoNotOptimize(found);
  }
  if (found != modes.size()) state.SkipWithError("did not identify every mode");
  state.counters["samples"] = static_cast<double>(rec.motor.size());
}

// Three modes (4, 9 and 17 Hz) recorded with the excitation `ex`.
void identify_three_modes(benchmark::State& state, const settle::testing::Excitation& ex) {
  const std::vector<plant::Mode> modes{{.omega = 2 * M_PI * 4.0, .zeta = 0.02, .gain = 1.0},
                                     {.omega = 2 * M_PI * 9.0, .zeta = 0.05, .gain = 1.0},
                                     {.omega = 2 * M_PI * 17.0, .zeta = 0.1, .gain = 1.0}};
  identify(state, modes, ex, 1);
}

// Issue 15's cost target: 5 s of data, the move alone (--train 0).
void BM_IdentifyThreeModes5s(benchmark::State& state) {
  settle::testing::Excitation ex{};
  ex.rest_before_s = 0.0;
  ex.hold_s = 5.0 - 0.13;  // with the 0.13 s move: 5 s of data
  identify_three_modes(state, ex);
}
BENCHMARK(BM_IdentifyThreeModes5s)->Unit(benchmark::kMillisecond);

// As settle identify records by default: the move after a train of 15 round trips (--train 15),
// then a 5 s hold: about 11 s of data.
void BM_IdentifyThreeModesTrain(benchmark::State& state) {
  settle::testing::Excitation ex{};
  ex.move.round_trips = commission::kDefaultTrainRoundTrips;
  ex.rest_before_s = 0.0;
  identify_three_modes(state, ex);
}
BENCHMARK(BM_IdentifyThreeModesTrain)->Unit(benchmark::kMillisecond);

// The hardest case step 6 of the estimate meets (docs/identification.md): three heavily damped
// modes at 1.41, 2.11 and 2.83 Hz (zeta 0.29, 0.24, 0.21) that the fit first merges into broad
// ones, so that with three modes fitted two are swapped for the scan's picks, round after round.
// The plant, noise seed and excitation of Identify.BroadModesAreReplacedByTheModesTheyHide's last
// case (seed 81 of the slow row, the tests' excitation with the default train).
void BM_IdentifyMergedModes(benchmark::State& state) {
  const std::vector<plant::Mode> modes{
      {.omega = 8.8608673964952107, .zeta = 0.29422779729039961, .gain = 0.014907425840454512},
      {.omega = 17.768442874472818, .zeta = 0.20571206796027017, .gain = 0.015028044722983896},
      {.omega = 13.265121239938614, .zeta = 0.2393962395725229, .gain = 0.014811314586307885}};
  settle::testing::Excitation ex{};
  ex.move = {.distance = 0.05,
             .limits = {.vmax = 0.5, .amax = 20.0, .jmax = 20000.0},
             .round_trips = commission::kDefaultTrainRoundTrips};
  identify(state, modes, ex, 7919 * 81);
}
BENCHMARK(BM_IdentifyMergedModes)->Unit(benchmark::kMillisecond);

}  // namespace
