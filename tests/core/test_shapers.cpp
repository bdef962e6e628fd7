// Input shapers: the defining residual conditions of each design, checked through an
// independent evaluation of V(omega, zeta) written here from its definition.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

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
