// SPDX-License-Identifier: Apache-2.0
// The demo's verdicts (app/demo_verdicts.hpp), which fail `settle demo` (exit 1) when they say no:
// a paper's method must leave less residual over CAN than its baseline, and float or fixed point
// must leave double's residual within 1 % or within one load count. Over a seeded random grid
// against the rule written out here; a run without a measured residual is never a pass.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>

#include "demo_verdicts.hpp"

namespace {

using settle::app::Json;

Json scalar_run(double percent, double counts) {
  return Json{{"status", "ok"},
              {"evaluation", "ok"},
              {"outcome", "completed"},
              {"residual_vs_double_percent", percent},
              {"residual_vs_double_load_counts", counts}};
}

const Json kDouble{{"status", "ok"}, {"evaluation", "ok"}, {"residual_can", 1e-3}};

TEST(DemoVerdicts, FloatOrFixedPassesOnlyWithinOnePercentOrOneLoadCount) {
  std::mt19937_64 rng{20261205};
  std::uniform_real_distribution<double> log10{-4.0, 3.0};
  int passes = 0, misses = 0;
  for (int i = 0; i < 20000; ++i) {
    const double percent = std::pow(10.0, log10(rng)), counts = std::pow(10.0, log10(rng));
    const bool expected = percent <= 1.0 || counts <= 1.0;
    const settle::app::ScalarCheck c = settle::app::check_scalar(scalar_run(percent, counts), kDouble);
    ASSERT_EQ(c.agrees, expected) << percent << " %, " << counts << " load counts";
    ASSERT_TRUE(c.why.empty());
    (expected ? passes : misses) += 1;
  }
  EXPECT_GT(passes, 1000);
  EXPECT_GT(misses, 1000);
  // The bounds themselves pass; just beyond both does not.
  EXPECT_TRUE(settle::app::check_scalar(scalar_run(1.0, 5.0), kDouble).agrees);
  EXPECT_TRUE(settle::app::check_scalar(scalar_run(5.0, 1.0), kDouble).agrees);
  EXPECT_FALSE(settle::app::check_scalar(scalar_run(1.0000001, 1.0000001), kDouble).agrees);
}

TEST(DemoVerdicts, AScalarRunWithoutAComparisonIsAMiss) {
  Json refused = scalar_run(0.0, 0.0);
  refused["evaluation"] = "out_of_range";
  Json failed = scalar_run(0.0, 0.0);
  failed["status"] = "error";
  failed["outcome"] = "drive_lost";
  Json unmeasured = scalar_run(0.0, 0.0);
  unmeasured["residual_vs_double_load_counts"] = nullptr;
  Json double_failed = kDouble;
  double_failed["status"] = "error";
  const std::optional<Json> none;
  for (const auto& [run, dbl, why] : {std::tuple{std::optional<Json>{refused}, std::optional<Json>{kDouble}, "refused"},
                                      std::tuple{std::optional<Json>{failed}, std::optional<Json>{kDouble}, "drive_lost"},
                                      std::tuple{std::optional<Json>{unmeasured}, std::optional<Json>{kDouble}, "not measured"},
                                      std::tuple{std::optional<Json>{scalar_run(0, 0)}, std::optional<Json>{double_failed},
                                                 "no result"},
                                      std::tuple{none, std::optional<Json>{kDouble}, "no result"}}) {
    const settle::app::ScalarCheck c = settle::app::check_scalar(run, dbl);
    EXPECT_FALSE(c.agrees) << why;
    EXPECT_NE(c.why.find(why), std::string::npos) << c.why;
  }
}

TEST(DemoVerdicts, TheMethodPassesOnlyWithLessResidualThanItsBaseline) {
  std::mt19937_64 rng{37};
  std::uniform_real_distribution<double> log10{-9.0, 0.0};
  for (int i = 0; i < 20000; ++i) {
    const double rm = std::pow(10.0, log10(rng));
    const double rb = i % 100 == 0 ? rm : std::pow(10.0, log10(rng));  // ties too
    const settle::app::ResidualVerdict v = settle::app::compare_residuals(
        Json{{"status", "ok"}, {"residual_can", rm}}, Json{{"status", "ok"}, {"residual_can", rb}});
    ASSERT_EQ(v.less, rm < rb) << rm << " against " << rb;
    ASSERT_DOUBLE_EQ(v.ratio, rb / rm);
  }
  // A residual not measured (null, no run, or a run that failed: its zero is no measurement) is
  // never "less", and has no ratio.
  const Json measured{{"status", "ok"}, {"residual_can", 1e-3}}, unmeasured{{"status", "ok"}, {"residual_can", nullptr}};
  const Json failed{{"status", "error"}, {"residual_can", 0.0}};
  for (const auto& [m, b] : {std::pair{std::optional<Json>{unmeasured}, std::optional<Json>{measured}},
                             std::pair{std::optional<Json>{failed}, std::optional<Json>{measured}},
                             std::pair{std::optional<Json>{measured}, std::optional<Json>{unmeasured}},
                             std::pair{std::optional<Json>{}, std::optional<Json>{measured}}}) {
    const settle::app::ResidualVerdict v = settle::app::compare_residuals(m, b);
    EXPECT_FALSE(v.less);
    EXPECT_TRUE(std::isnan(v.ratio));
  }
}

}  // namespace
