// SPDX-License-Identifier: Apache-2.0
// The demo's commissioning scenario (app/commissioning.hpp): its noise is 1 % of the
// excitation's peak load deflection (the scenario simulates the excitation on the true plant;
// checked against the deflection settle identify measures through the loopback drive without
// noise), its plant is the one `--plant modes` builds from its options, and judge() fails the demo
// on every miss the issue names: a mode off by more than 0.5 % in omega or 0.01 in zeta, a mode
// missing or too many, a PRV over 1 %, a step that failed.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commissioning.hpp"
#include "run_cli.hpp"

namespace {

using settle::app::CommissioningResult;
using settle::app::CommissioningScenario;
using settle::app::Json;

CommissioningScenario scenario() {
  CommissioningScenario s;
  EXPECT_EQ(settle::app::commissioning_scenario(s), settle::plant::SimStatus::ok);
  return s;
}

TEST(Commissioning, TheNoiseIsOnePercentOfThePeakDeflectionIdentifyMeasures) {
  const CommissioningScenario s = scenario();
  ASSERT_EQ(s.modes.size(), 2U);
  std::vector<std::string> args{"identify", "--bus", "loopback", "--json"};
  args.insert(args.end(), s.plant.begin(), s.plant.end());
  args.insert(args.end(), s.identify.begin(), s.identify.end());
  const settle::test::CliResult r = settle::test::run_cli_argv(args);
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.stdout_text);
  // The drive's stepping and 1 µm counts against the continuous simulation: within 1 %.
  const double measured = j["excitation"]["peak_deflection"].get<double>();
  EXPECT_NEAR(s.peak_deflection, measured, 0.01 * measured);
  EXPECT_NEAR(s.noise_counts, 0.01 * s.peak_deflection * 1e6, 1e-9 * s.noise_counts);
  // The plant the drive process gets is the truth, mode for mode (what identify found, noiseless).
  ASSERT_EQ(j["modes"].size(), s.modes.size());
  for (std::size_t m = 0; m < s.modes.size(); ++m) {
    EXPECT_NEAR(j["modes"][m]["omega"].get<double>(), s.modes[m].omega, 1e-3 * s.modes[m].omega);
    EXPECT_NEAR(j["modes"][m]["zeta"].get<double>(), s.modes[m].zeta, 1e-3);
  }
}

// Documents as the three commands print them, for modes (omega, zeta) and a PRV.
CommissioningResult result_with(const CommissioningScenario& s, const std::vector<std::pair<double, double>>& modes,
                                double prv) {
  CommissioningResult r;
  Json found = Json::array();
  for (const auto& [w, z] : modes) {
    found.push_back(Json{{"omega", w}, {"zeta", z}, {"gain", 1.0}, {"omega_ci", {w * 0.999, w * 1.001}},
                         {"zeta_ci", {z - 0.001, z + 0.001}}});
  }
  r.identify = Json{{"status", "ok"}, {"modes", found}};
  r.tune = Json{{"status", "ok"}, {"duration", 0.4}, {"worst_residual", 0.005}, {"residual_max", 0.01}};
  r.stream = Json{{"status", "ok"}, {"prv_can_percent", prv}};
  settle::app::judge(s, r);
  return r;
}

TEST(Commissioning, JudgeFailsOnEveryMissTheIssueNames) {
  const CommissioningScenario s = scenario();
  const double w1 = s.modes[0].omega, z1 = s.modes[0].zeta, w2 = s.modes[1].omega, z2 = s.modes[1].zeta;
  // Just inside every tolerance: ok.
  const CommissioningResult good = result_with(s, {{w1 * 1.0049, z1 + 0.0099}, {w2 * 0.9951, z2 - 0.0099}}, 0.99);
  EXPECT_TRUE(good.ok()) << good.error;
  ASSERT_EQ(good.modes.size(), 2U);
  EXPECT_NEAR(good.modes[0].omega_error, 0.0049, 1e-12);
  EXPECT_NEAR(good.modes[1].zeta_error, -0.0099, 1e-12);
  // Each miss alone fails it.
  EXPECT_FALSE(result_with(s, {{w1 * 1.0051, z1}, {w2, z2}}, 0.5).ok()) << "omega off by 0.51 %";
  EXPECT_FALSE(result_with(s, {{w1, z1}, {w2, z2 + 0.0101}}, 0.5).ok()) << "zeta off by 0.0101";
  EXPECT_FALSE(result_with(s, {{w1, z1}}, 0.5).ok()) << "a mode missing";
  EXPECT_FALSE(result_with(s, {{w1, z1}, {w2, z2}, {200.0, 0.1}}, 0.5).ok()) << "a spurious mode";
  const CommissioningResult prv = result_with(s, {{w1, z1}, {w2, z2}}, 1.01);
  EXPECT_TRUE(prv.modes_ok);
  EXPECT_FALSE(prv.prv_ok);
  EXPECT_FALSE(prv.ok()) << "PRV over 1 %";
  // A step that failed: its error, and no verdict from the steps after it.
  CommissioningResult failed = result_with(s, {{w1, z1}, {w2, z2}}, 0.5);
  failed.identify = Json{{"status", "error"}, {"error", "response_too_small"}, {"message", "noise-dominated"}};
  settle::app::judge(s, failed);
  EXPECT_FALSE(failed.ok());
  EXPECT_NE(failed.error.find("response_too_small"), std::string::npos) << failed.error;
  CommissioningResult no_stream = result_with(s, {{w1, z1}, {w2, z2}}, 0.5);
  no_stream.stream.reset();
  settle::app::judge(s, no_stream);
  EXPECT_FALSE(no_stream.ok());
  EXPECT_NE(no_stream.error.find("settle stream"), std::string::npos) << no_stream.error;
}

}  // namespace
