// SPDX-License-Identifier: Apache-2.0
// The estimator (settle/commission/identify.hpp) on seeded synthetic records made by the simulated
// drive's physics (identify_record.hpp): 1 kHz, 1-count quantisation, white noise of 1 % of the
// excitation's peak load deflection, a jerk-limited move (1 ms jerk phases) after a train of 15
// round trips of it (settle identify's default --train), then a 5 s hold.
// Accuracy (omega within 0.5 %, zeta within 0.01), no spurious modes, interval coverage, refusals.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "identify_range.hpp"

namespace settle::commission {
namespace {

using namespace identify_test;

// One mode anywhere in the range (omega log-uniform in 2 pi [1, 100] rad/s, zeta uniform in
// [0.005, 0.3]), 100 seeds: every one accurate, never a second mode although three are allowed,
// and the 95 % intervals contain the truth in at least 90 of 100 for omega and for zeta.
TEST(Identify, OneModeAcrossTheRangeNoSpuriousModeAndCoverage) {
  int omega_covered = 0;
  int zeta_covered = 0;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    std::mt19937_64 rng{seed};
    std::uniform_real_distribution<double> u{0.0, 1.0};
    plant::Mode m{};
    m.omega = kTwoPi * std::pow(100.0, u(rng));
    m.zeta = 0.005 + 0.295 * u(rng);
    m.gain = 1.0;
    Record rec{};
    ASSERT_TRUE(make_record({m}, 0.01, seed, rec, excitation()));
    const IdentifyResult r = identify(rec, 3);
    expect_accurate({m}, r, seed);
    if (r.modes.size() != 1) continue;
    omega_covered += r.modes[0].omega_lo <= m.omega && m.omega <= r.modes[0].omega_hi ? 1 : 0;
    zeta_covered += r.modes[0].zeta_lo <= m.zeta && m.zeta <= r.modes[0].zeta_hi ? 1 : 0;
  }
  std::printf("95 %% intervals containing the truth, of 100: omega %d, zeta %d\n", omega_covered, zeta_covered);
  EXPECT_GE(omega_covered, 90);
  EXPECT_GE(zeta_covered, 90);
}

// Two and three modes, each case over 20 seeds: the range's corners (1 Hz at zeta 0.005, 100 Hz,
// zeta 0.3) and gains down to 15 % of the largest (the 10 % cut is the estimator's), with modes whose deflection stands out of the
// 1 % noise (a mode's deflection scales as gain / omega^2: see docs/identification.md).
TEST(Identify, TwoAndThreeModes) {
  const std::vector<std::vector<plant::Mode>> cases{
      {{.omega = kTwoPi * 1.0, .zeta = 0.005, .gain = 1.0}, {.omega = kTwoPi * 2.5, .zeta = 0.05, .gain = 1.0}},
      {{.omega = kTwoPi * 30.0, .zeta = 0.3, .gain = 1.0}, {.omega = kTwoPi * 100.0, .zeta = 0.02, .gain = 2.0}},
      {{.omega = kTwoPi * 1.2, .zeta = 0.01, .gain = 0.15}, {.omega = kTwoPi * 3.0, .zeta = 0.1, .gain = 1.0}},
      {{.omega = kTwoPi * 4.0, .zeta = 0.02, .gain = 1.0},
       {.omega = kTwoPi * 9.0, .zeta = 0.05, .gain = 1.0},
       {.omega = kTwoPi * 17.0, .zeta = 0.1, .gain = 3.0}},
      {{.omega = kTwoPi * 1.5, .zeta = 0.3, .gain = 0.5},
       {.omega = kTwoPi * 4.0, .zeta = 0.01, .gain = 1.0},
       {.omega = kTwoPi * 10.0, .zeta = 0.03, .gain = 2.0}},
      {{.omega = kTwoPi * 20.0, .zeta = 0.005, .gain = 1.0},
       {.omega = kTwoPi * 45.0, .zeta = 0.02, .gain = 1.0},
       {.omega = kTwoPi * 100.0, .zeta = 0.01, .gain = 1.0}},
  };
  for (std::size_t c = 0; c < cases.size(); ++c) {
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      SCOPED_TRACE("case " + std::to_string(c));
      Record rec{};
      ASSERT_TRUE(make_record(cases[c], 0.01, 1000 * c + seed, rec, excitation()));
      expect_accurate(cases[c], identify(rec, 3), seed);
    }
  }
}

// Issue 15's accuracy statement over its range, "gain" read as the mode's share of the load
// deflection (random_plant), on the first 40 of the soak's 400 seeded plants (1..3 modes, 1 kHz,
// 1-count quantisation, noise 1 % of the excitation's peak load deflection): every plant whose modes
// the record can determine (the Cramer-Rao bound within a third of each tolerance) has every mode
// found, omega within 0.5 %, zeta within 0.01 and no other mode. All 400: test_identify_soak.cpp.
TEST(Identify, RandomPlantsAcrossTheRangeSample) {
  const RangeCount c = identified_plants({}, 1, 40);
  std::printf("random plants identified: %d of %d determinable, %d of %d beyond the bound\n", c.determinable_ok,
              c.determinable, c.beyond_ok, c.beyond);
  EXPECT_EQ(c.determinable_ok, c.determinable);
  // The bound leaves most of the sample in the test (39 of 40 measured; 380 of the soak's 400).
  EXPECT_GE(c.determinable, 37);
}

// The train's reason to be, checked on the bound itself (the drive's physics, not the estimator):
// heavily damped modes ring for a few periods after each acceleration step, so the 68 steps of
// --train 8 carry far more about them than the move's 4. Plants at the range's hard corner (a
// heavily damped fast mode at 10-15 % of the deflection beside a slow one): the bound on its
// omega and zeta at least 3 times lower with --train 8 (measured: 3.7-4.1 times; sqrt(17) = 4.1)
// and 4.5 times with the default 15 (measured 5.0-5.6; sqrt(31) = 5.6). These stay beyond the
// bound even so (0.18-0.50 % in omega with 15): the corner the range test counts as beyond.
TEST(Identify, TheTrainLowersTheBoundOnHeavilyDampedModes) {
  const std::vector<std::vector<plant::Mode>> plants{
      {{.omega = kTwoPi * 100.0, .zeta = 0.3, .gain = 1.0}, {.omega = kTwoPi * 5.0, .zeta = 0.01, .gain = 1.0}},
      {{.omega = kTwoPi * 30.0, .zeta = 0.3, .gain = 1.0}, {.omega = kTwoPi * 3.0, .zeta = 0.05, .gain = 1.0}},
      {{.omega = kTwoPi * 60.0, .zeta = 0.25, .gain = 1.0}, {.omega = kTwoPi * 20.0, .zeta = 0.1, .gain = 1.0}},
  };
  const std::vector<double> shares{0.1, 0.1, 0.15};
  for (std::size_t p = 0; p < plants.size(); ++p) {
    SCOPED_TRACE("plant " + std::to_string(p));
    std::vector<double> bound_w(3), bound_z(3);
    for (const std::size_t trips : {std::size_t{0}, std::size_t{8}, kDefaultTrainRoundTrips}) {
      testing::Excitation ex = excitation();
      ex.move.round_trips = trips;
      // The fast mode at its share of the slow one's peak deflection, under this excitation.
      std::vector<plant::Mode> truth = plants[p];
      for (std::size_t j = 0; j < 2; ++j) {
        truth[j].gain = (j == 0 ? shares[p] : 1.0) * kLargestPeak / deflection_peak(truth[j], ex);
      }
      Record rec{};
      ASSERT_TRUE(make_record(truth, 0.01, 1, rec, ex));
      const std::vector<Bound> b = cramer_rao(truth, rec.noise_sd, ex);
      const std::size_t k = trips == 0 ? 0 : trips == 8 ? 1 : 2;
      bound_w[k] = b[0].omega_rel;
      bound_z[k] = b[0].zeta;
      std::printf("plant %zu, %zu round trips: fast mode's bound omega %.3f %%, zeta %.4f\n", p, trips,
                  100.0 * b[0].omega_rel, b[0].zeta);
    }
    EXPECT_GT(bound_w[0], 3.0 * bound_w[1]);
    EXPECT_GT(bound_z[0], 3.0 * bound_z[1]);
    EXPECT_GT(bound_w[0], 4.5 * bound_w[2]);
    EXPECT_GT(bound_z[0], 4.5 * bound_z[2]);
  }
}

// The excitation itself: --train n is the move, then back, ... 2n + 1 copies that never overlap,
// so the path stays between 0 and the distance, ends there at rest, and its peaks (and the limits
// the CLI checks them against) are the move's; n beyond kMaxTrainRoundTrips is refused.
TEST(IdentifyExcitation, TheTrainIsTheMoveBackAndForthWithinItsLimits) {
  const IdentifyExcitation base{.distance = 0.01, .limits = {.vmax = 0.1, .amax = 5.0, .jmax = 5000.0}};
  core::Move<double> alone{};
  ASSERT_EQ(plan_identify_excitation(base, alone), core::Status::ok);
  EXPECT_EQ(train_round_trips(alone), 0U);
  for (const std::size_t trips : {1U, 8U, 15U}) {
    SCOPED_TRACE(trips);
    IdentifyExcitation ex = base;
    ex.round_trips = trips;
    core::Move<double> m{};
    ASSERT_EQ(plan_identify_excitation(ex, m), core::Status::ok);
    EXPECT_EQ(train_round_trips(m), trips);
    ASSERT_EQ(m.shaper().count, 2 * trips + 1);
    const double t_move = alone.duration();
    for (std::size_t k = 0; k < m.shaper().count; ++k) {
      EXPECT_EQ(m.shaper().amp[k], k % 2 == 0 ? 1.0 : -1.0);
      if (k > 0) {
        EXPECT_GE(m.shaper().time[k] - m.shaper().time[k - 1], 1.25 * t_move * (1.0 - 1e-12));
        EXPECT_LE(m.shaper().time[k] - m.shaper().time[k - 1], 1.75 * t_move * (1.0 + 1e-12));
      }
    }
    EXPECT_NEAR(m.peaks().v, alone.peaks().v, 1e-12 * alone.peaks().v);
    EXPECT_NEAR(m.peaks().a, alone.peaks().a, 1e-12 * alone.peaks().a);
    EXPECT_NEAR(m.peaks().j, alone.peaks().j, 1e-12 * alone.peaks().j);
    double vmax = 0.0, amax = 0.0, lo = 0.0, hi = 0.0;
    for (double t = 0.0; t <= m.duration(); t += 1e-4) {
      const core::Sample<double> s = m.at(t);
      vmax = std::max(vmax, std::fabs(s.v));
      amax = std::max(amax, std::fabs(s.a));
      lo = std::min(lo, s.p);
      hi = std::max(hi, s.p);
    }
    EXPECT_LE(vmax, base.limits.vmax * (1.0 + 1e-9));
    EXPECT_LE(amax, base.limits.amax * (1.0 + 1e-9));
    EXPECT_GE(vmax, 0.99 * base.limits.vmax);  // every copy reaches the move's cruise
    EXPECT_GE(lo, -1e-12);
    EXPECT_LE(hi, base.distance * (1.0 + 1e-12));
    const core::Sample<double> end = m.at(m.duration());
    EXPECT_EQ(end.p, base.distance);
    EXPECT_EQ(end.v, 0.0);
  }
  IdentifyExcitation too_many = base;
  too_many.round_trips = kMaxTrainRoundTrips + 1;
  core::Move<double> untouched = alone;
  EXPECT_EQ(plan_identify_excitation(too_many, untouched), core::Status::too_many_impulses);
  EXPECT_EQ(untouched.duration(), alone.duration());
}

TEST(Identify, RandomPlantSharesAreTheDrawnOnes) {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const std::vector<plant::Mode> truth = random_plant(seed, {});
    double largest = 0.0;
    for (const plant::Mode& m : truth) largest = std::max(largest, deflection_peak(m));
    EXPECT_NEAR(largest, kLargestPeak, 1e-9);
    for (const plant::Mode& m : truth) EXPECT_GE(deflection_peak(m), 0.1 * largest * (1.0 - 1e-9)) << "seed " << seed;
  }
}

// The bound against the estimator's own standard errors (its covariance s^2 (J^T J)^-1 from its
// own mode response at the fitted parameters): two derivations of the same quantity, the bound's
// from the drive's physics at the true parameters. They agree within a factor of 1.25 on every
// mode of ten random plants the estimator identified (measured: 0.89 .. 1.02).
TEST(Identify, CramerRaoBoundAgreesWithTheFitsErrors) {
  double worst = 1.0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    std::vector<plant::Mode> truth = random_plant(seed, {});
    Record rec{};
    ASSERT_TRUE(make_record(truth, 0.01, 7919 * seed, rec, excitation()));
    const IdentifyResult r = identify(rec, 3);
    if (!accurate(truth, r)) continue;
    std::sort(truth.begin(), truth.end(), [](const plant::Mode& a, const plant::Mode& b) { return a.omega < b.omega; });
    const std::vector<Bound> b = cramer_rao(truth, rec.noise_sd);
    for (std::size_t j = 0; j < truth.size(); ++j) {
      const double rw = r.modes[j].omega_sd / r.modes[j].omega / b[j].omega_rel;
      const double rz = r.modes[j].zeta_sd / b[j].zeta;
      std::printf("seed %llu mode %zu: fit/bound omega %.3f zeta %.3f\n", static_cast<unsigned long long>(seed), j, rw, rz);
      worst = std::max({worst, rw, 1.0 / rw, rz, 1.0 / rz});
    }
  }
  EXPECT_LT(worst, 1.25);
}

// Heavily damped modes that the fit had merged into one broad mode (zeta 0.86-0.99), at times
// beside a spurious lightly damped one: determinable plants of the sub-range rows of
// docs/identification.md's table that the estimator missed before step 6 replaced a broad mode by
// the two the scan picks without it. With the default train (the two determinable plants the
// train had lost against the move alone) and with --train 15 (three more, among them 1.15, 2.84
// and 5.96 Hz seen as 1.70 Hz at zeta 0.99 beside an invented 8.9 Hz mode). The last, with the
// move alone, was missed by a first version that kept the first replacement that helped, not the
// best of all: it replaced the lightly damped 7.4 Hz mode, and the broad one's split found no room.
// And one plant beyond the bound (so held to the tolerances on its seed only), three heavily
// damped modes at 1.41, 2.11 and 2.83 Hz, that was fitted as 1.99 Hz at zeta 0.63, 2.85 Hz and
// 3.54 Hz at zeta 0.59: with three modes fitted there is no room for two, and two of them are
// replaced by the scan's two.
TEST(Identify, BroadModesAreReplacedByTheModesTheyHide) {
  struct Case {
    PlantRange range;
    std::uint64_t seed;
    std::size_t round_trips;
    bool determinable{true};
  };
  const PlantRange damped{.zeta_lo = 0.2, .zeta_hi = 0.3};
  const PlantRange slow{.f_lo = 1.0, .f_hi = 10.0};
  const Case cases[] = {{damped, 37, 8},    {slow, 85, 8}, {damped, 37, 15}, {damped, 124, 15},
                        {damped, 191, 15}, {slow, 4, 15}, {slow, 85, 15},  {{}, 298, 0},
                        {slow, 81, 15, false}};
  for (const Case& c : cases) {
    testing::Excitation ex = excitation();
    ex.move.round_trips = c.round_trips;
    const std::vector<plant::Mode> truth = random_plant(c.seed, c.range, ex);
    Record rec{};
    ASSERT_TRUE(make_record(truth, 0.01, 7919 * c.seed, rec, ex));
    const std::string what = "seed " + std::to_string(c.seed) + ", --train " + std::to_string(c.round_trips);
    EXPECT_EQ(determinable(truth, rec, ex), c.determinable) << what;
    const IdentifyResult r = identify(rec, 3);
    EXPECT_TRUE(accurate(truth, r)) << what << ": " << describe(truth, r);
  }
}

// The measurements behind docs/identification.md's table, per sub-range (not run by default):
//   R_FLO=1 R_FHI=100 R_ZLO=0.005 R_ZHI=0.3 R_FIRST=1 R_N=200 settle_sim_identify_tests
//     --gtest_also_run_disabled_tests --gtest_filter='*ExploreRange'
// and R_TRAIN=n for the excitation's round trips (default 8; 0: the move alone).
TEST(Identify, DISABLED_ExploreRange) {
  PlantRange range{};
  if (const char* e = std::getenv("R_FLO")) range.f_lo = std::atof(e);
  if (const char* e = std::getenv("R_FHI")) range.f_hi = std::atof(e);
  if (const char* e = std::getenv("R_ZLO")) range.zeta_lo = std::atof(e);
  if (const char* e = std::getenv("R_ZHI")) range.zeta_hi = std::atof(e);
  const int n = std::getenv("R_N") ? std::atoi(std::getenv("R_N")) : 100;
  const std::uint64_t first = std::getenv("R_FIRST") ? std::strtoull(std::getenv("R_FIRST"), nullptr, 10) : 1;
  const RangeCount c = identified_plants(range, first, first + static_cast<std::uint64_t>(n) - 1);
  std::printf("RANGE f [%g, %g] zeta [%g, %g]: %d of %d determinable, %d of %d beyond\n", range.f_lo, range.f_hi,
              range.zeta_lo, range.zeta_hi, c.determinable_ok, c.determinable, c.beyond_ok, c.beyond);
}

// Undamped modes (a beam's with no modal damping): zeta exactly 0 is inside the range the fit
// searches, so the fit does not stop at a floor above the truth.
TEST(Identify, UndampedModes) {
  const std::vector<plant::Mode> modes{{.omega = 40.0, .zeta = 0.0, .gain = 1.0}, {.omega = 150.0, .zeta = 0.0, .gain = 3.0}};
  int covered = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    Record rec{};
    ASSERT_TRUE(make_record(modes, 0.01, seed, rec, excitation()));
    const IdentifyResult r = identify(rec, 3);
    expect_accurate(modes, r, seed);
    for (const UncertainMode& m : r.modes) covered += m.zeta_lo <= 0.0 ? 1 : 0;
  }
  EXPECT_GE(covered, 17);  // of 20 intervals at 95 %
}

// --max-modes caps the count: the three-mode plant asked for one gives its strongest mode only.
TEST(Identify, MaxModesCapsTheCount) {
  const std::vector<plant::Mode> modes{{.omega = kTwoPi * 4.0, .zeta = 0.02, .gain = 1.0},
                                {.omega = kTwoPi * 9.0, .zeta = 0.05, .gain = 1.0},
                                {.omega = kTwoPi * 17.0, .zeta = 0.1, .gain = 1.0}};
  Record rec{};
  ASSERT_TRUE(make_record(modes, 0.01, 7, rec, excitation()));
  const IdentifyResult r = identify(rec, 1);
  ASSERT_EQ(r.status, IdentifyStatus::ok);
  ASSERT_EQ(r.modes.size(), 1U);
  EXPECT_NEAR(r.modes[0].omega, modes[0].omega, 0.05 * modes[0].omega);
}

// A response buried in noise (the mode's deflection 1/20 of the noise) is refused, not fitted
// with invented modes; so is pure noise.
TEST(Identify, NoiseDominatedResponseIsRefused) {
  int refused = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Record rec{};
    ASSERT_TRUE(make_record({{.omega = kTwoPi * 10.0, .zeta = 0.05, .gain = 1.0}}, 20.0, seed, rec, excitation()));
    const IdentifyResult r = identify(rec, 3);
    refused += r.status == IdentifyStatus::response_too_small ? 1 : 0;
    EXPECT_TRUE(r.modes.empty()) << "seed " << seed << ": " << r.modes.size() << " modes from noise";
  }
  EXPECT_EQ(refused, 20);
}

TEST(Identify, RefusesRecordsWithoutExcitationOrFreeResponse) {
  Record rec{};
  ASSERT_TRUE(make_record({{.omega = kTwoPi * 10.0, .zeta = 0.05, .gain = 1.0}}, 0.01, 1, rec, excitation()));
  IdentifyInput in{};
  in.motor = rec.motor;
  in.load = rec.load;
  EXPECT_EQ(identify_modes(in).status, IdentifyStatus::ok);
  // Cut 50 samples after the motor stops: too short a free response.
  const IdentifyResult full = identify_modes(in);
  in.motor = std::span<const std::int32_t>{rec.motor}.first(full.motion_end + 50);
  in.load = std::span<const std::int32_t>{rec.load}.first(full.motion_end + 50);
  EXPECT_EQ(identify_modes(in).status, IdentifyStatus::free_response_too_short);
  // The motor at rest throughout.
  const std::vector<std::int32_t> still(2000, 5);
  in.motor = still;
  in.load = still;
  EXPECT_EQ(identify_modes(in).status, IdentifyStatus::no_motion);
  // One sample more than the estimator fits: refused before any work.
  const std::vector<std::int32_t> longest(kMaxIdentifySamples + 1, 5);
  in.motor = longest;
  in.load = longest;
  EXPECT_EQ(identify_modes(in).status, IdentifyStatus::too_many_samples);
  // Sizes that differ, and a mode count out of range.
  in.motor = rec.motor;
  in.load = std::span<const std::int32_t>{rec.load}.first(10);
  EXPECT_EQ(identify_modes(in).status, IdentifyStatus::bad_input);
  in.load = rec.load;
  IdentifyOptions opt{};
  opt.max_modes = kMaxIdentifyModes + 1;
  EXPECT_EQ(identify_modes(in, opt).status, IdentifyStatus::bad_input);
  opt.max_modes = 0;
  EXPECT_EQ(identify_modes(in, opt).status, IdentifyStatus::bad_input);
}

// The estimator's own mode response against the drive's exact plant stepping (a different code
// path): the deflection of a two-mode plant is the sum of the gains times the unit responses.
TEST(Identify, ModeResponseMatchesThePlantsStepping) {
  const std::vector<plant::Mode> modes{{.omega = 40.0, .zeta = 0.03, .gain = 1.5}, {.omega = 300.0, .zeta = 0.2, .gain = -0.4}};
  Record rec{};
  ASSERT_TRUE(make_record(modes, 0.0, 1, rec, excitation()));
  rec.load_counts_per_unit = 1e6;
  std::vector<double> x(rec.motor.size());
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = rec.motor[k] / rec.counts_per_unit;
  std::vector<double> q0(x.size());
  std::vector<double> q1(x.size());
  mode_response(modes[0].omega, modes[0].zeta, rec.period_s, x, q0);
  mode_response(modes[1].omega, modes[1].zeta, rec.period_s, x, q1);
  double worst = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double predicted = x[k] + modes[0].gain * q0[k] + modes[1].gain * q1[k];
    worst = std::max(worst, std::fabs(predicted - rec.load[k] / rec.load_counts_per_unit));
  }
  EXPECT_LT(worst * rec.load_counts_per_unit, 0.51);  // the load's 1-count quantisation, nothing more
}

}  // namespace
}  // namespace settle::commission
