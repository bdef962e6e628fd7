// SPDX-License-Identifier: Apache-2.0
#pragma once
// Synthetic records for the estimator's tests and benchmark: the excitation `settle identify`
// streams (plan_identify_excitation: a jerk-limited move, optionally after a train) as integer setpoints through sim's DriveAxis (the simulated drive's physics, exact stepping of
// the plant: a different code path from the estimator's own mode response), then a hold. The load
// gets white noise of a given fraction of the excitation's peak deflection, then 1-count
// quantisation.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "settle/testbed/drive_axis.hpp"
#include "settle/commission/identify_excitation.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/testbed/stream_check.hpp"

namespace settle::testing {

struct Record {
  std::vector<std::int32_t> motor;
  std::vector<std::int32_t> load;
  std::vector<double> deflection;  // the plant's deflection per sample, output units, before noise and quantisation
  double peak_deflection{0.0};  // output units
  double noise_sd{0.0};         // output units
  double counts_per_unit{1e6};
  double load_counts_per_unit{1e6};
  double period_s{1e-3};
};

struct Excitation {
  commission::IdentifyExcitation move{.distance = 0.05, .limits = {.vmax = 0.5, .amax = 20.0, .jmax = 4000.0}};  // m
  double rest_before_s{0.1};
  double hold_s{5.0};
};

// Returns false when the move cannot be planned or the drive refuses the plant.
inline bool make_record(const std::vector<plant::Mode>& modes, double noise_fraction, std::uint64_t seed, Record& out,
                        const Excitation& ex = {}) {
  plant::ModalPlant plant{};
  if (plant::ModalPlant::make_modes(modes, 1.0, plant::PlantKind::modes, plant) != plant::SimStatus::ok) return false;
  core::Move<double> move{};
  if (commission::plan_identify_excitation(ex.move, move) != core::Status::ok) return false;
  testbed::DriveAxisConfig cfg{};
  cfg.scale.counts_per_unit = out.counts_per_unit;
  cfg.scale.period_us = static_cast<std::uint32_t>(std::lround(out.period_s * 1e6));
  cfg.load_counts_per_unit = out.load_counts_per_unit;
  std::vector<std::int32_t> sp;
  if (testbed::stream_setpoints(move, cfg.scale, 0, sp) != plant::SimStatus::ok) return false;
  const auto rest = static_cast<std::size_t>(ex.rest_before_s / out.period_s);
  const auto hold = static_cast<std::size_t>(ex.hold_s / out.period_s);
  std::vector<std::int32_t> targets(rest, 0);
  targets.insert(targets.end(), sp.begin(), sp.end());
  targets.insert(targets.end(), hold, sp.back());
  testbed::DriveAxis axis{};
  if (testbed::DriveAxis::make(cfg, plant, 0, axis) != plant::SimStatus::ok) return false;
  std::vector<double> load(targets.size());
  out.motor.assign(targets.size(), 0);
  out.deflection.assign(targets.size(), 0.0);
  double peak = 0.0;
  for (std::size_t k = 0; k < targets.size(); ++k) {
    if (axis.step(targets[k]) != plant::SimStatus::ok) return false;
    out.motor[k] = axis.feedback().position_actual;
    load[k] = axis.load_position();
    out.deflection[k] = axis.plant().deflection();
    peak = std::max(peak, std::fabs(out.deflection[k]));
  }
  out.peak_deflection = peak;
  out.noise_sd = noise_fraction * peak;
  std::mt19937_64 rng{seed};
  std::normal_distribution<double> noise{0.0, out.noise_sd > 0.0 ? out.noise_sd : 1.0};
  out.load.resize(load.size());
  for (std::size_t k = 0; k < load.size(); ++k) {
    const double n = out.noise_sd > 0.0 ? noise(rng) : 0.0;
    out.load[k] = static_cast<std::int32_t>(std::lround((load[k] + n) * out.load_counts_per_unit));
  }
  return true;
}

}  // namespace settle::testing
