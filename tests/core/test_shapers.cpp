// SPDX-License-Identifier: Apache-2.0
// Input shapers: the defining residual conditions of each design, checked through an
// independent evaluation of V(omega, zeta) written here from its definition.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include "settle/core/shaper.hpp"

using namespace settle;
using core::ShaperKind;

namespace {

// V(w): residual of a unit step through the shaper on a mode of frequency w and damping z, as a
// fraction of the unshaped step's residual.
double v_of(const core::Shaper<double>& s, double w, double z) {
  const double wd = w * std::sqrt(1 - z * z);
  std::complex<double> acc{};
  for (std::size_t i = 0; i < s.count; ++i) {
    acc += s.amp[i] * std::exp(std::complex<double>{z * w, wd} * (s.time[i] - s.duration()));
  }
  return std::abs(acc);
}

// Every impulse positive, the times increasing, the gain 1 (to tol).
void expect_positive_increasing_unit_gain(const core::Shaper<double>& s, double tol) {
  double sum = 0.0;
  for (std::size_t i = 0; i < s.count; ++i) {
    EXPECT_GT(s.amp[i], 0.0) << i;
    if (i > 0) {
      EXPECT_GT(s.time[i], s.time[i - 1]) << i;
    }
    sum += s.amp[i];
  }
  EXPECT_NEAR(sum, 1.0, tol);
}

core::Shaper<double> design(ShaperKind k, double w, double z, double vtol = 0.05) {
  core::Shaper<double> s{};
  EXPECT_EQ(core::design_shaper(k, w, z, vtol, s), core::Status::ok);
  return s;
}

TEST(Shapers, UnitGainAndZeroResidualAtTheDesignMode) {
  for (double z : {0.0, 0.05, 0.159, 0.3, 0.6}) {
    for (auto k : {ShaperKind::zv, ShaperKind::zvd, ShaperKind::zvdd}) {
      const auto s = design(k, 20.0, z);
      double sum = 0;
      for (std::size_t i = 0; i < s.count; ++i) sum += s.amp[i];
      EXPECT_NEAR(sum, 1.0, 1e-14);
      EXPECT_LT(v_of(s, 20.0, z), 1e-13) << core::to_string(k) << " z=" << z;
      EXPECT_NEAR(core::shaper_residual(s, 20.0, z), v_of(s, 20.0, z), 1e-14);
    }
  }
}

TEST(Shapers, ZvMatchesSingerSeering) {
  const double z = 0.159, w = 28.28;
  const auto s = design(ShaperKind::zv, w, z);
  const double k = std::exp(-z * M_PI / std::sqrt(1 - z * z));
  ASSERT_EQ(s.count, 2u);
  EXPECT_NEAR(s.amp[0], 1 / (1 + k), 1e-15);
  EXPECT_NEAR(s.amp[1], k / (1 + k), 1e-15);
  EXPECT_NEAR(s.time[1], M_PI / (w * std::sqrt(1 - z * z)), 1e-15);
}

TEST(Shapers, EachOrderFlattensTheCurveFurther) {
  // dV/dw = 0 at the design frequency for ZVD, and d2V/dw2 = 0 too for ZVDD: measure V at a
  // small relative error e, which scales like e^order.
  const double w = 10.0, z = 0.1;
  struct Case {
    ShaperKind k;
    double order;
  };
  for (const Case c : {Case{ShaperKind::zv, 1}, Case{ShaperKind::zvd, 2}, Case{ShaperKind::zvdd, 3}}) {
    const auto s = design(c.k, w, z);
    const double v1 = v_of(s, w * 1.01, z), v2 = v_of(s, w * 1.02, z);
    EXPECT_NEAR(std::log2(v2 / v1), c.order, 0.1) << core::to_string(c.k);
  }
}

TEST(Shapers, EiUndampedIsTheClassicSymmetricShaper) {
  const double v = 0.05, w = 5.0;
  const auto s = design(ShaperKind::ei, w, 0.0, v);
  ASSERT_EQ(s.count, 3u);
  EXPECT_NEAR(s.amp[0], (1 + v) / 4, 1e-10);
  EXPECT_NEAR(s.amp[1], (1 - v) / 2, 1e-10);
  EXPECT_NEAR(s.amp[2], (1 + v) / 4, 1e-10);
  EXPECT_NEAR(s.time[1], M_PI / w, 1e-10);
  EXPECT_NEAR(s.time[2], 2 * M_PI / w, 1e-10);
}

TEST(Shapers, EiWithDampingMeetsItsDefinition) {
  // V(wn) = Vtol, dV/dw(wn) = 0, and V = 0 at one frequency below and one above wn.
  for (double z : {0.0, 0.05, 0.1, 0.2, 0.3}) {
    const double w = 12.0, vtol = 0.05;
    const auto s = design(ShaperKind::ei, w, z, vtol);
    EXPECT_NEAR(v_of(s, w, z), vtol, 1e-9) << z;
    const double h = 1e-5 * w;
    EXPECT_NEAR((v_of(s, w + h, z) - v_of(s, w - h, z)) / (2 * h), 0.0, 1e-6) << z;
    double min_lo = 1, min_hi = 1;
    for (double r = 0.5; r < 1.0; r += 1e-4) min_lo = std::min(min_lo, v_of(s, r * w, z));
    for (double r = 1.0; r < 1.6; r += 1e-4) min_hi = std::min(min_hi, v_of(s, r * w, z));
    EXPECT_LT(min_lo, 1e-3) << z;
    EXPECT_LT(min_hi, 1e-3) << z;
  }
}

// Two- and three-hump EI (Singhose, Seering & Singer). Undamped: the closed forms, impulses half a
// period apart, found again by the design's Newton solve on the defining conditions.
TEST(Shapers, MultiHumpEiUndampedIsTheClosedForm) {
  const double v = 0.05, w = 7.0, half = M_PI / w;
  const double x = std::cbrt(v * v * (std::sqrt(1 - v * v) + 1));
  const double a2 = (3 * x * x + 2 * x + 3 * v * v) / (16 * x);
  const double e2[] = {a2, 0.5 - a2, 0.5 - a2, a2};
  const double a3 = (1 + 3 * v + 2 * std::sqrt(2 * v * (v + 1))) / 16, b3 = (1 - v) / 4;
  const double e3[] = {a3, b3, 1 - 2 * (a3 + b3), b3, a3};
  const auto s2 = design(ShaperKind::ei2, w, 0.0, v), s3 = design(ShaperKind::ei3, w, 0.0, v);
  ASSERT_EQ(s2.count, 4u);
  ASSERT_EQ(s3.count, 5u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(s2.amp[i], e2[i], 1e-10) << i;
    EXPECT_NEAR(s2.time[i], static_cast<double>(i) * half, 1e-10) << i;
  }
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_NEAR(s3.amp[i], e3[i], 1e-10) << i;
    EXPECT_NEAR(s3.time[i], static_cast<double>(i) * half, 1e-10) << i;
  }
  // The published amplitudes at 5 % (0.16 / 0.34; 0.11 / 0.24 / 0.30, two decimals).
  EXPECT_NEAR(s2.amp[0], 0.16, 0.005);
  EXPECT_NEAR(s3.amp[2], 0.30, 0.005);
}

// With damping: V <= vtol from the lowest zero to the highest, V = vtol at each hump (the local
// maxima between zeros), V = 0 at each zero the design reports; the band (V <= vtol around the
// design frequency) widens with the humps: EI < two humps < three at the same damping. The
// classic structure ends with heavy damping, and the design says so.
TEST(Shapers, MultiHumpEiWithDampingMeetsItsDefinition) {
  const double w = 12.0, vtol = 0.05;
  const auto band = [&](const core::Shaper<double>& s, double z) {
    double lo = 1.0, hi = 1.0;
    while (v_of(s, (lo - 1e-4) * w, z) <= vtol * (1 + 1e-9)) lo -= 1e-4;
    while (v_of(s, (hi + 1e-4) * w, z) <= vtol * (1 + 1e-9)) hi += 1e-4;
    return hi - lo;
  };
  for (double z : {0.0, 0.05, 0.1, 0.2}) {
    double last_band = band(design(ShaperKind::ei, w, z, vtol), z);
    for (std::size_t humps : {2u, 3u}) {
      SCOPED_TRACE("humps " + std::to_string(humps) + ", zeta " + std::to_string(z));
      core::Shaper<double> s{};
      std::array<double, 4> zeros{};
      ASSERT_EQ(core::multi_hump_ei_shaper(humps, w, z, vtol, s, zeros.data()), core::Status::ok);
      ASSERT_EQ(s.count, humps + 2);
      expect_positive_increasing_unit_gain(s, 1e-12);
      for (std::size_t i = 0; i <= humps; ++i) {
        EXPECT_LT(v_of(s, zeros[i] * w, z), 1e-10) << "zero " << i;
        if (i > 0) {
          EXPECT_GT(zeros[i], zeros[i - 1]);
        }
      }
      // Sampled between the outer zeros: never above vtol, and reaching it once per hump.
      int humps_seen = 0;
      double prev2 = v_of(s, zeros[0] * w, z), prev = v_of(s, (zeros[0] + 1e-5) * w, z), top = 0.0;
      for (double r = zeros[0] + 2e-5; r <= zeros[humps]; r += 1e-5) {
        const double cur = v_of(s, r * w, z);
        EXPECT_LE(cur, vtol * (1 + 1e-8)) << r;
        if (prev > prev2 && prev >= cur) {
          ++humps_seen;
          EXPECT_NEAR(prev, vtol, 1e-7) << "hump at " << r;
        }
        top = std::max(top, cur);
        prev2 = prev;
        prev = cur;
      }
      EXPECT_EQ(humps_seen, static_cast<int>(humps));
      const double b = band(s, z);
      EXPECT_GT(b, last_band);
      last_band = b;
      // The same design through design_shaper.
      const auto d = design(humps == 2 ? ShaperKind::ei2 : ShaperKind::ei3, w, z, vtol);
      EXPECT_EQ(d.count, s.count);
      for (std::size_t i = 0; i < s.count; ++i) EXPECT_EQ(d.amp[i], s.amp[i]);
    }
  }
  core::Shaper<double> s{};
  EXPECT_EQ(core::design_shaper(ShaperKind::ei2, w, 0.3, vtol, s), core::Status::ok);
  EXPECT_EQ(core::design_shaper(ShaperKind::ei3, w, 0.3, vtol, s), core::Status::no_solution);
  EXPECT_EQ(core::design_shaper(ShaperKind::ei3, w, 0.0, 0.6, s), core::Status::vtol_out_of_range);
  EXPECT_EQ(core::multi_hump_ei_shaper(4, w, 0.0, vtol, s), core::Status::unsupported_request);
}

// Any mode and tolerance in range: a design is either refused or a valid shaper (positive
// impulses, increasing times, unit gain, the residual at the design frequency within vtol).
TEST(Shapers, MultiHumpEiIsValidOrRefusedAcrossTheRange) {
  std::mt19937 g(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int designed = 0;
  for (int i = 0; i < 300; ++i) {
    const double w = std::pow(10.0, -3.0 + 9.0 * u(g)), z = u(g) < 0.2 ? 0.0 : 0.99 * u(g) * u(g);
    const double vtol = std::min(0.49, std::pow(10.0, -12.0 + 11.7 * u(g)));
    for (auto k : {ShaperKind::ei2, ShaperKind::ei3}) {
      SCOPED_TRACE(::testing::Message() << core::to_string(k) << " w " << w << " z " << z << " vtol " << vtol);
      core::Shaper<double> s{};
      const core::Status st = core::design_shaper(k, w, z, vtol, s);
      if (st != core::Status::ok) {
        EXPECT_EQ(st, core::Status::no_solution);
        continue;
      }
      ++designed;
      expect_positive_increasing_unit_gain(s, 1e-9);
      EXPECT_LE(v_of(s, w, z), vtol * (1 + 1e-6) + 1e-12);
    }
  }
  EXPECT_GT(designed, 200);
}

TEST(Shapers, CompositionCancelsBothModes) {
  const auto a = design(ShaperKind::zv, 10.0, 0.05);
  const auto b = design(ShaperKind::zvd, 37.0, 0.02);
  core::Shaper<double> c{};
  ASSERT_EQ(core::compose(a, b, c), core::Status::ok);
  EXPECT_EQ(c.count, 6u);
  EXPECT_LT(v_of(c, 10.0, 0.05), 1e-13);
  EXPECT_LT(v_of(c, 37.0, 0.02), 1e-13);
  EXPECT_NEAR(c.duration(), a.duration() + b.duration(), 1e-15);
}

TEST(Shapers, CompositionMergesCoincidentImpulses) {
  const auto a = design(ShaperKind::zv, 10.0, 0.0);
  core::Shaper<double> c{};
  ASSERT_EQ(core::compose(a, a, c), core::Status::ok);
  ASSERT_EQ(c.count, 3u);  // ZV * ZV = ZVD for an undamped mode
  const auto zvd = design(ShaperKind::zvd, 10.0, 0.0);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(c.amp[i], zvd.amp[i], 1e-15);
}

namespace {

// The mode's response to the shaped unit step at time t (past the last impulse), by superposing
// the closed-form step responses of each impulse: a time-domain check, independent of the C and S
// sums both the design and v_of use. Zero residual means it sits on 1 at every such t.
double shaped_step_response(const core::Shaper<double>& s, double w, double z, double t) {
  const double wd = w * std::sqrt(1 - z * z);
  double x = 0.0;
  for (std::size_t i = 0; i < s.count; ++i) {
    const double u = t - s.time[i];
    x += s.amp[i] * (1.0 - std::exp(-z * w * u) * (std::cos(wd * u) + z * w / wd * std::sin(wd * u)));
  }
  return x;
}

// Random sets of n modes, omega log-uniform over 2..200 rad/s, zeta uniform over 0..0.2.
std::vector<std::pair<double, double>> random_modes(std::mt19937& gen, std::size_t n) {
  std::uniform_real_distribution<double> lw(std::log(2.0), std::log(200.0)), uz(0.0, 0.2);
  std::vector<std::pair<double, double>> m(n);
  for (auto& md : m) md = {std::exp(lw(gen)), uz(gen)};
  return m;
}

}  // namespace

// The joint ZV shaper (one design for all modes): n + 1 positive impulses of unit gain that leave
// every mode at rest, by v_of and by the time-domain superposition; shorter on average than one ZV
// per mode convolved. Where no positive design exists it says so (no_solution) rather than return
// one with a negative impulse; on these sets it finds one for all 200 two-mode and 199 of the 200
// three-mode requests (185 before the start from the slower modes' design; docs/fastest.md).
TEST(Shapers, JointZvCancelsEveryModeWithOneImpulseMoreThanModes) {
  std::mt19937 gen(7);
  for (std::size_t n : {2U, 3U}) {
    int found = 0;
    double joint_sum = 0.0, conv_sum = 0.0;
    for (int trial = 0; trial < 200; ++trial) {
      const auto modes = random_modes(gen, n);
      std::vector<double> w, z;
      core::Shaper<double> conv{};
      for (const auto& [mw, mz] : modes) {
        w.push_back(mw);
        z.push_back(mz);
        core::Shaper<double> both{};
        ASSERT_EQ(core::compose(conv, design(ShaperKind::zv, mw, mz), both), core::Status::ok);
        conv = both;
      }
      core::Shaper<double> s{};
      const core::Status st = core::joint_zv_shaper(w.data(), z.data(), n, s);
      if (st == core::Status::no_solution) continue;
      ASSERT_EQ(st, core::Status::ok);
      ++found;
      joint_sum += s.duration();
      conv_sum += conv.duration();
      ASSERT_EQ(s.count, n + 1);
      expect_positive_increasing_unit_gain(s, 1e-14);
      EXPECT_EQ(s.time[0], 0.0);
      for (const auto& [mw, mz] : modes) {
        EXPECT_LT(v_of(s, mw, mz), 1e-12) << "omega " << mw << " zeta " << mz;
        for (double after : {0.0, 0.37, 1.9, 5.3}) {
          const double t = s.duration() + after * 2.0 * M_PI / mw;
          EXPECT_NEAR(shaped_step_response(s, mw, mz, t), 1.0, 1e-12) << "omega " << mw << " zeta " << mz;
        }
      }
    }
    std::printf("%zu modes: joint ZV for %d of 200, mean length %.4f of the convolved ZVs'\n", n, found,
                joint_sum / conv_sum);
    EXPECT_GE(found, n == 2 ? 200 : 199);
    EXPECT_LT(joint_sum, conv_sum);
  }
}

// A set whose joint design the fixed starts (equal steps, subsets of the convolved ZVs' impulses)
// all miss: the reference grid's case 113 (tests/core/data/fastest_reference_grid.txt), where
// `fastest` was refused for want of any bound. The design for the two slower modes with one
// impulse split by the fastest mode's ZV leads to one (docs/fastest.md, "Several modes"): four
// positive impulses, every mode at rest, 1.667 s, a little longer than the slower pair's 1.659 s.
TEST(Shapers, JointZvFromTheSlowerModesDesignWhereTheFixedStartsMissIt) {
  const double w[3] = {2.1007, 13.5366, 278.7101}, z[3] = {0.1785, 0.173, 0.297};
  core::Shaper<double> s{};
  ASSERT_EQ(core::joint_zv_shaper(w, z, 3, s), core::Status::ok);
  ASSERT_EQ(s.count, 4u);
  expect_positive_increasing_unit_gain(s, 1e-14);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_LT(v_of(s, w[k], z[k]), 1e-12) << "omega " << w[k];
    EXPECT_NEAR(shaped_step_response(s, w[k], z[k], s.duration() + 1.3 * 2.0 * M_PI / w[k]), 1.0, 1e-12);
  }
  core::Shaper<double> pair{};
  ASSERT_EQ(core::joint_zv_shaper(w, z, 2, pair), core::Status::ok);
  EXPECT_GT(s.duration(), pair.duration());
  EXPECT_LT(s.duration(), pair.duration() + M_PI / (w[2] * std::sqrt(1 - z[2] * z[2])) + 1e-9);
  std::printf("2.10 / 13.54 / 278.7 rad/s: joint ZV %.4f s, the slower pair's %.4f s\n", s.duration(),
              pair.duration());
}

// One mode: the joint design is ZV itself. Two undamped modes 1.2 to 2.9 apart: shorter than
// the two ZVs convolved (the simultaneous design's point, Singhose, Crain & Seering 1997).
TEST(Shapers, JointZvIsZvForOneModeAndShorterThanConvolvedForTwo) {
  const double w1 = 10.0, z1 = 0.05;
  core::Shaper<double> one{};
  ASSERT_EQ(core::joint_zv_shaper(&w1, &z1, 1, one), core::Status::ok);
  const auto zv = design(ShaperKind::zv, w1, z1);
  ASSERT_EQ(one.count, zv.count);
  for (std::size_t i = 0; i < zv.count; ++i) {
    EXPECT_EQ(one.amp[i], zv.amp[i]);
    EXPECT_EQ(one.time[i], zv.time[i]);
  }
  for (double ratio = 1.2; ratio < 2.9; ratio += 0.1) {
    const double w[2] = {10.0, 10.0 * ratio}, z[2] = {0.0, 0.0};
    core::Shaper<double> s{};
    ASSERT_EQ(core::joint_zv_shaper(w, z, 2, s), core::Status::ok) << "ratio " << ratio;
    EXPECT_LT(s.duration(), M_PI / w[0] + M_PI / w[1]) << "ratio " << ratio;
  }
}

TEST(Shapers, JointZvRejectsBadInputAndLeavesTheOutputAlone) {
  core::Shaper<double> s = design(ShaperKind::zvd, 3.0, 0.1);
  const auto before = s;
  const double w[5] = {3.0, 9.0, 27.0, 81.0, 150.0}, z[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
  const double bad_w[2] = {3.0, -1.0}, bad_z[2] = {0.0, 1.0}, nan_w[2] = {3.0, NAN};
  EXPECT_EQ(core::joint_zv_shaper(w, z, 0, s), core::Status::unsupported_request);
  EXPECT_EQ(core::joint_zv_shaper(w, z, core::kMaxJointModes + 1, s), core::Status::unsupported_request);
  EXPECT_EQ(core::joint_zv_shaper(bad_w, z, 2, s), core::Status::non_positive_omega);
  EXPECT_EQ(core::joint_zv_shaper(w, bad_z, 2, s), core::Status::zeta_out_of_range);
  EXPECT_EQ(core::joint_zv_shaper(nan_w, z, 2, s), core::Status::non_finite_input);
  EXPECT_EQ(s.count, before.count);
  for (std::size_t i = 0; i < s.count; ++i) {
    EXPECT_EQ(s.amp[i], before.amp[i]);
    EXPECT_EQ(s.time[i], before.time[i]);
  }
}

TEST(Shapers, BadInputIsRejectedAndLeavesTheOutputAlone) {
  core::Shaper<double> s = design(ShaperKind::zvd, 3.0, 0.1);
  const auto before = s;
  EXPECT_EQ(core::design_shaper(ShaperKind::zv, -1.0, 0.0, 0.05, s), core::Status::non_positive_omega);
  EXPECT_EQ(core::design_shaper(ShaperKind::zv, 1.0, 1.0, 0.05, s), core::Status::zeta_out_of_range);
  EXPECT_EQ(core::design_shaper(ShaperKind::zv, NAN, 0.0, 0.05, s), core::Status::non_finite_input);
  EXPECT_EQ(core::design_shaper(ShaperKind::ei, 1.0, 0.0, 0.7, s), core::Status::vtol_out_of_range);
  const double amp[2] = {0.5, 0.4}, t[2] = {0.0, 0.1};
  EXPECT_EQ(core::custom_shaper(amp, t, 2, s), core::Status::shaper_gain_not_unity);
  const double amp2[2] = {0.5, 0.5}, tneg[2] = {0.0, -0.1};
  EXPECT_EQ(core::custom_shaper(amp2, tneg, 2, s), core::Status::bad_impulse);
  core::Shaper<double> big{};
  big.count = 20;
  for (std::size_t i = 0; i < 20; ++i) {
    big.amp[i] = 0.05;
    big.time[i] = 0.01 * static_cast<double>(i);
  }
  core::Shaper<double> big2 = big;
  for (std::size_t i = 0; i < 20; ++i) big2.time[i] = 0.013 * static_cast<double>(i) + 0.0001;
  EXPECT_EQ(core::compose(big, big2, s), core::Status::too_many_impulses);
  EXPECT_EQ(s.count, before.count);
  for (std::size_t i = 0; i < s.count; ++i) EXPECT_EQ(s.amp[i], before.amp[i]);
}

}  // namespace
