// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the identify tests share: the excitation settle identify uses by default, the estimator
// call, the accuracy judgement, the random plants of the range tests and the Cramer-Rao bound that
// says which of them a record can determine (test_identify.cpp: unit; test_identify_soak.cpp).
#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>
#include <Eigen/Dense>
#include "identify_record.hpp"
#include "settle/commission/identify.hpp"
#include "settle/commission/identify_excitation.hpp"

namespace settle::commission::identify_test {


using testing::Record;
using testing::make_record;

inline constexpr double kTwoPi = 6.283185307179586;

inline testing::Excitation excitation() {
  testing::Excitation ex{};
  ex.move.distance = 0.05;
  ex.move.limits = {.vmax = 0.5, .amax = 20.0, .jmax = 20000.0};
  ex.move.round_trips = kDefaultTrainRoundTrips;  // settle identify's default --train
  // Only for DISABLED_ExploreRange's measurements (see there).
  if (const char* e = std::getenv("R_TRAIN")) ex.move.round_trips = std::strtoul(e, nullptr, 10);
  return ex;
}

inline IdentifyResult identify(const Record& r, std::size_t max_modes = 3) {
  IdentifyInput in{};
  in.period_s = r.period_s;
  in.counts_per_unit = r.counts_per_unit;
  in.load_counts_per_unit = r.load_counts_per_unit;
  in.motor = r.motor;
  in.load = r.load;
  IdentifyOptions opt{};
  opt.max_modes = max_modes;
  return identify_modes(in, opt);
}

// The true modes sorted by frequency against the identified ones (already sorted).
inline void expect_accurate(std::vector<plant::Mode> truth, const IdentifyResult& r, std::uint64_t seed) {
  ASSERT_EQ(r.status, IdentifyStatus::ok) << "seed " << seed << ": " << to_string(r.status);
  ASSERT_EQ(r.modes.size(), truth.size()) << "seed " << seed;
  std::sort(truth.begin(), truth.end(), [](const plant::Mode& a, const plant::Mode& b) { return a.omega < b.omega; });
  for (std::size_t j = 0; j < truth.size(); ++j) {
    EXPECT_LT(std::fabs(r.modes[j].omega / truth[j].omega - 1.0), 0.005)
        << "seed " << seed << " mode " << j << ": omega " << r.modes[j].omega << " true " << truth[j].omega;
    EXPECT_LT(std::fabs(r.modes[j].zeta - truth[j].zeta), 0.01)
        << "seed " << seed << " mode " << j << ": zeta " << r.modes[j].zeta << " true " << truth[j].zeta;
    EXPECT_LT(std::fabs(r.modes[j].gain / truth[j].gain - 1.0), 0.1) << "seed " << seed << " mode " << j;
  }
}


// A mode's share of the load deflection the excitation causes: the peak of its own contribution
// to the load response, |q_j| over the record, made by the simulated drive's physics on a plant
// with that mode alone (the deflection is linear in the modes, so this is exactly the mode's part
// of the whole). This is what "gain >= 10 % of the largest" means in the range test below: a
// mode's plant gain g_j says little on its own, since its deflection scales as g_j / omega_j^2
// (docs/identification.md).
inline double deflection_peak(const plant::Mode& m, const testing::Excitation& ex = excitation()) {
  Record rec{};
  if (!make_record({m}, 0.0, 1, rec, ex)) return 0.0;
  return rec.peak_deflection;
}

// The random plants of the range test: 1..3 modes, omega log-uniform in 2 pi [f_lo, f_hi] rad/s
// and at least kMinModeRatio apart, zeta uniform in [zeta_lo, zeta_hi], each mode's deflection
// peak drawn uniformly between 10 % and 100 % of the largest (one mode at 100 %, kLargestPeak).
// The gain that gives each mode its drawn share is found with deflection_peak (linear in g).
inline constexpr double kMinModeRatio = 1.3;
inline constexpr double kLargestPeak = 1e-3;  // m: 1000 load counts, so the 1 % noise is about 10 counts

struct PlantRange {
  double f_lo{1.0}, f_hi{100.0};  // Hz
  double zeta_lo{0.005}, zeta_hi{0.3};
};

inline std::vector<plant::Mode> random_plant(std::uint64_t seed, const PlantRange& range,
                               const testing::Excitation& ex = excitation()) {
  std::mt19937_64 rng{seed};
  std::uniform_real_distribution<double> u{0.0, 1.0};
  const std::size_t n = 1 + static_cast<std::size_t>(u(rng) * 3.0) % 3;
  std::vector<plant::Mode> modes;
  while (modes.size() < n) {
    const double omega = kTwoPi * range.f_lo * std::pow(range.f_hi / range.f_lo, u(rng));
    const bool apart = std::all_of(modes.begin(), modes.end(), [&](const plant::Mode& m) {
      return std::max(m.omega, omega) / std::min(m.omega, omega) >= kMinModeRatio;
    });
    const double zeta = range.zeta_lo + (range.zeta_hi - range.zeta_lo) * u(rng);
    if (apart) modes.push_back({.omega = omega, .zeta = zeta, .gain = 1.0});
  }
  const std::size_t largest = static_cast<std::size_t>(u(rng) * static_cast<double>(n)) % n;
  for (std::size_t j = 0; j < n; ++j) {
    const double share = j == largest ? 1.0 : 0.1 + 0.9 * u(rng);
    modes[j].gain = share * kLargestPeak / deflection_peak(modes[j], ex);
  }
  return modes;
}

// Every true mode found once (identified modes sorted by omega against the truth sorted the
// same way), omega within 0.5 %, zeta within 0.01, no other mode.
inline bool accurate(std::vector<plant::Mode> truth, const IdentifyResult& r) {
  if (r.status != IdentifyStatus::ok || r.modes.size() != truth.size()) return false;
  std::sort(truth.begin(), truth.end(), [](const plant::Mode& a, const plant::Mode& b) { return a.omega < b.omega; });
  for (std::size_t j = 0; j < truth.size(); ++j) {
    if (!(std::fabs(r.modes[j].omega / truth[j].omega - 1.0) < 0.005)) return false;
    if (!(std::fabs(r.modes[j].zeta - truth[j].zeta) < 0.01)) return false;
  }
  return true;
}

inline std::string describe(const std::vector<plant::Mode>& truth, const IdentifyResult& r) {
  std::string s = "true";
  char buf[96];
  for (const plant::Mode& m : truth) {
    std::snprintf(buf, sizeof buf, " (%.3f Hz, zeta %.4f)", m.omega / kTwoPi, m.zeta);
    s += buf;
  }
  s += std::string{"; "} + to_string(r.status) + ", identified";
  for (const UncertainMode& m : r.modes) {
    std::snprintf(buf, sizeof buf, " (%.3f Hz sd %.2f %%, zeta %.4f sd %.4f)", m.omega / kTwoPi,
                  100.0 * m.omega_sd / m.omega, m.zeta, m.zeta_sd);
    s += buf;
  }
  return s;
}

// What the record can determine at best, whatever the estimator: the Cramer-Rao bound of the
// model's parameters for white noise of the record's standard deviation, from the Fisher
// information J^T J / sigma^2, J the sensitivities of the load to every parameter (each mode's
// omega, zeta, gain, and the rigid gain and offset the estimator fits too). The sensitivities
// come from the drive's physics (make_record, central differences of each mode's deflection
// alone: the deflection is linear in the modes), not from the estimator's own model or
// covariance. Returns, per mode, the bound on omega's relative and zeta's absolute error.
struct Bound {
  double omega_rel{0.0};
  double zeta{0.0};
};

inline std::vector<Bound> cramer_rao(const std::vector<plant::Mode>& truth, double noise_sd,
                              const testing::Excitation& ex = excitation()) {
  const auto deflection = [&ex](const plant::Mode& m) {
    Record rec{};
    (void)make_record({m}, 0.0, 1, rec, ex);
    return rec.deflection;
  };
  Record base{};
  (void)make_record(truth, 0.0, 1, base, ex);
  const auto n = static_cast<Eigen::Index>(base.motor.size());
  const auto m = static_cast<Eigen::Index>(truth.size());
  Eigen::MatrixXd j(n, 3 * m + 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    j(k, 3 * m) = base.motor[static_cast<std::size_t>(k)] / base.counts_per_unit;  // rigid gain
    j(k, 3 * m + 1) = 1.0;                                                          // offset
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    const plant::Mode& mode = truth[static_cast<std::size_t>(i)];
    const double dw = 1e-4 * mode.omega;
    const double dz = 1e-4;
    plant::Mode wp = mode, wm = mode, zp = mode, zm = mode, unit = mode;
    wp.omega += dw;
    wm.omega -= dw;
    zp.zeta += dz;
    zm.zeta = std::max(0.0, mode.zeta - dz);
    unit.gain = 1.0;
    const std::vector<double> a = deflection(wp), b = deflection(wm), c = deflection(zp), d = deflection(zm),
                              u = deflection(unit);
    for (Eigen::Index k = 0; k < n; ++k) {
      const auto s = static_cast<std::size_t>(k);
      j(k, 3 * i) = (a[s] - b[s]) / (2.0 * dw);
      j(k, 3 * i + 1) = (c[s] - d[s]) / (mode.zeta + dz - zm.zeta);
      j(k, 3 * i + 2) = u[s];
    }
  }
  const Eigen::MatrixXd cov = (j.transpose() * j).ldlt().solve(Eigen::MatrixXd::Identity(3 * m + 2, 3 * m + 2));
  std::vector<Bound> out;
  for (Eigen::Index i = 0; i < m; ++i) {
    out.push_back({.omega_rel = noise_sd * std::sqrt(cov(3 * i, 3 * i)) / truth[static_cast<std::size_t>(i)].omega,
                   .zeta = noise_sd * std::sqrt(cov(3 * i + 1, 3 * i + 1))});
  }
  return out;
}

// A plant the tolerances can be asked of: every mode's bound at most a third of them (3 sigma).
inline bool determinable(const std::vector<plant::Mode>& truth, const Record& rec, const testing::Excitation& ex = excitation()) {
  const std::vector<Bound> b = cramer_rao(truth, rec.noise_sd, ex);
  return std::all_of(b.begin(), b.end(), [](const Bound& x) { return x.omega_rel <= 0.005 / 3.0 && x.zeta <= 0.01 / 3.0; });
}

struct RangeCount {
  int determinable{0}, determinable_ok{0};  // plants within the bound, and those identified
  int beyond{0}, beyond_ok{0};              // plants past it (not asserted), and those identified
};

// Seeds first..last of random_plant(range), identified and judged; the misses are printed.
inline RangeCount identified_plants(const PlantRange& range, std::uint64_t first, std::uint64_t last) {
  RangeCount c{};
  for (std::uint64_t seed = first; seed <= last; ++seed) {
    const std::vector<plant::Mode> truth = random_plant(seed, range);
    Record rec{};
    if (!make_record(truth, 0.01, 7919 * seed, rec, excitation())) {
      ADD_FAILURE() << "seed " << seed << ": no record";
      continue;
    }
    const IdentifyResult r = identify(rec, 3);
    const bool ok = accurate(truth, r);
    const bool within = determinable(truth, rec);
    (within ? c.determinable : c.beyond) += 1;
    (within ? c.determinable_ok : c.beyond_ok) += ok ? 1 : 0;
    if (!ok) {
      std::printf("seed %llu (%s): %s\n", static_cast<unsigned long long>(seed), within ? "determinable" : "beyond",
                  describe(truth, r).c_str());
    }
  }
  return c;
}

}  // namespace settle::commission::identify_test
