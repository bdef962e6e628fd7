// settle plan|sample|simulate --axes N (issue 17, docs/multi_axis.md): the coordinated move's JSON,
// its samples (one common end, a straight line with --sync path), its simulation on the plant (the
// trade-off between path and time sync, measured by the simulator's own stepping), and every bad
// per-axis list refused with exit 2 naming the option.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "refusal.hpp"
#include "run_cli.hpp"

namespace {

using settle::test::Case;
using settle::test::CliResult;
using settle::test::expect_refused;
using settle::test::run_cli;

const std::string kThree =
    "--axes 3 --profile jerk-limited --distance 0.1,0.05,-0.2 --omega 22,30,15 --zeta 0,0.05,0.1 --vmax 1 "
    "--amax 20,10,40 --jmax 800";
const double kD[3] = {0.1, 0.05, -0.2};
const double kAmax[3] = {20.0, 10.0, 40.0};

nlohmann::json run_json(const std::string& args) {
  const CliResult r = run_cli(args + " --json");
  EXPECT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.stdout_text, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.stdout_text;
  return j;
}

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

TEST(CliAxes, PlanPathReportsEveryAxisWithinItsLimitsOnAStraightLine) {
  const auto j = run_json("plan " + kThree);
  EXPECT_EQ(j.at("status"), "ok");
  EXPECT_EQ(j.at("axes"), 3);
  EXPECT_EQ(j.at("sync"), "path");
  EXPECT_LE(j.at("line_deviation").get<double>(), 1e-12);
  EXPECT_EQ(j.at("path_modes").size(), 3u);
  EXPECT_EQ(j.at("path").at("distance"), 1.0);
  EXPECT_EQ(j.at("path").at("duration"), j.at("duration"));
  ASSERT_EQ(j.at("axis").size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& a = j.at("axis")[i];
    EXPECT_EQ(a.at("distance").get<double>(), kD[i]);
    EXPECT_EQ(a.at("limits").at("vmax"), 1.0);  // one value for every axis
    EXPECT_EQ(a.at("limits").at("amax"), kAmax[i]);
    EXPECT_LE(a.at("peaks").at("velocity").get<double>(), 1.0 * (1 + 1e-9));
    EXPECT_LE(a.at("peaks").at("acceleration").get<double>(), kAmax[i] * (1 + 1e-9));
    EXPECT_LE(a.at("peaks").at("jerk").get<double>(), 800.0 * (1 + 1e-9));
  }
  // The text form says the same.
  const CliResult t = run_cli("plan " + kThree);
  ASSERT_EQ(t.status, 0) << t.out;
  EXPECT_NE(t.stdout_text.find("axes         3 (sync path)"), std::string::npos) << t.stdout_text;
}

TEST(CliAxes, PlanTimeGivesEveryAxisTheCommonDurationAndReportsTheDeviation) {
  const auto j = run_json("plan " + kThree + " --shaper zv --sync time");
  EXPECT_EQ(j.at("sync"), "time");
  EXPECT_FALSE(j.contains("path"));
  const double t = j.at("duration").get<double>();
  double largest = 0.0;
  for (const auto& a : j.at("axis")) {
    EXPECT_NEAR(a.at("plan").at("duration").get<double>(), t, 1e-12 * t);
    EXPECT_EQ(a.at("plan").at("shaper").at("impulses").size(), 2u);  // its own mode only
    largest = std::max(largest, a.at("line_deviation").get<double>());
  }
  EXPECT_GT(j.at("line_deviation").get<double>(), 1e-4);
  EXPECT_GE(j.at("line_deviation").get<double>(), largest);
}

TEST(CliAxes, SampleEndsEveryAxisOnTheSameRowAndKeepsThePathStraight) {
  for (const char* sync : {"path", "time"}) {
    SCOPED_TRACE(sync);
    const auto j = run_json("sample " + kThree + " --sync " + sync + " --dt 0.001");
    ASSERT_EQ(j.at("columns").size(), 13u);
    EXPECT_EQ(j.at("columns")[5], "position_2");
    const auto& rows = j.at("rows");
    const double t_end = rows.back()[0].get<double>();
    // The row at which each axis first reaches its target at rest: the same for all (the last).
    for (std::size_t i = 0; i < 3; ++i) {
      std::size_t first = rows.size();
      for (std::size_t k = rows.size(); k-- > 0;) {
        if (rows[k][1 + 4 * i].get<double>() != kD[i] || rows[k][2 + 4 * i].get<double>() != 0.0) break;
        first = k;
      }
      EXPECT_EQ(first, rows.size() - 1) << "axis " << i;
      EXPECT_EQ(rows.back()[0].get<double>(), t_end);
    }
    if (std::string{sync} != "path") continue;
    // Straight: every sample of axis i is D_i times the same s; at the drive's default 1e6 counts
    // per unit the rounded setpoints stay within one count of the line.
    for (const auto& r : rows) {
      const double s = r[1 + 4 * 2].get<double>() / kD[2];
      for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_NEAR(r[1 + 4 * i].get<double>(), kD[i] * s, 1e-15);
        EXPECT_LE(std::fabs(std::round(r[1 + 4 * i].get<double>() * 1e6) - kD[i] * s * 1e6), 0.5 + 1e-6);
      }
    }
  }
}

TEST(CliAxes, SimulateShowsThePathSyncCancelsEveryModeAndTimeSyncOnlyEachAxisOwn) {
  // The sdof plant's mode (mass 1, stiffness 800, damping 9) is axis 1's; axis 2 declares another.
  const double w = std::sqrt(800.0), z = 9.0 / (2.0 * std::sqrt(800.0));
  const std::string args = "simulate --plant sdof --axes 2 --profile jerk-limited --distance 0.1,0.05 --vmax 1 "
                           "--amax 20 --jmax 800 --omega " + num(w) + ",45 --zeta " + num(z) + ",0.02 --dt 1e-4";
  const auto path = run_json(args + " --sync path");
  ASSERT_EQ(path.at("axis").size(), 2u);
  for (const auto& a : path.at("axis")) EXPECT_LT(a.at("prv_percent").get<double>(), 1e-5) << a.dump();
  const auto time = run_json(args + " --sync time");
  EXPECT_LT(time.at("axis")[0].at("prv_percent").get<double>(), 1e-5);
  EXPECT_GT(time.at("axis")[1].at("prv_percent").get<double>(), 1.0);
  EXPECT_GT(path.at("move_duration").get<double>(), time.at("move_duration").get<double>());
}

TEST(CliAxes, BadPerAxisRequestsExitTwoNamingTheOption) {
  const std::string p = "plan --axes 3 --profile jerk-limited ";
  const std::string lim = " --vmax 1 --amax 20 --jmax 800";
  const std::vector<Case> cases = {
      {p + "--distance 0.1,0.2" + lim, "--distance", "bad_list"},
      {p + "--distance 0.1,0.2,0.3 --vmax 1,2 --amax 20 --jmax 800", "--vmax", "bad_list"},
      {p + "--distance 0.1,0.2,0.3 --omega 22,30" + lim, "--omega", "bad_list"},
      {p + "--distance 0.1,0.2,0.3 --omega 22,30,15 --zeta 0,0,1" + lim, "--zeta", "out_of_range"},
      {p + "--distance 0.1,0.2,0.3 --omega 22,30,15 --omega 1,2,3" + lim, "--omega", "bad_option"},
      {p + "--distance 0.1,nan,0.3" + lim, "--distance", "non_finite_input"},
      {p + "--distance 0.1,,0.3" + lim, "--distance", "bad_list"},
      {p + "--distance 0.1,0.2,0.3 --amax 20,-1,3 --vmax 1 --jmax 800", "--amax", "out_of_range"},
      {p + "--distance" + lim, "--distance", "missing_value"},
      {"plan --axes 9 --profile jerk-limited --distance 1" + lim, "--axes", "out_of_range"},
      {"plan --axes 0 --profile jerk-limited --distance 1" + lim, "--axes", "out_of_range"},
      {"plan --axes 8 --profile jerk-limited --distance 1,2,3,4,5,6,7,8,9" + lim, "--distance", "bad_list"},
      {"plan --axes 2 --sync both --profile jerk-limited --distance 1,2" + lim, "--sync", "unknown_sync"},
      // Without --axes: one axis, as before.
      {"plan --profile poly345 --distance 0.1,0.2 --time 1", "--distance", "bad_option"},
      {"plan --profile poly345 --distance 0.1 --time 1 --sync time", "--sync", "bad_option"},
      // A plan that fails names the option and the axis.
      {"plan --axes 2 --profile poly345 --distance 0.1,0.1 --time 0.1 --vmax 10,0.01", "--vmax",
       "velocity_limit_exceeded"},
      {"plan --axes 2 --sync time --profile fastest --distance 0.1,0.2 --omega 20,30" + lim, "--sync",
       "unsupported_request"},
      {"sample --axes 2 --profile poly345 --distance 0.1,0.2 --time 1", "--dt", "missing_option"},
      {"sample --axes 2 --profile poly345 --distance 0.1,0.2 --time 1 --dt 1e-7", "--dt", "too_many_samples"},
      {"simulate --axes 2 --plant sdof --profile poly345 --distance 0.1,0.2 --time 0.5 --halt-at 0.1", "--halt-at",
       "conflicting_options"},
  };
  for (const Case& c : cases) expect_refused(c);
  const CliResult r = run_cli("plan --axes 2 --profile poly345 --distance 0.1,0.1 --time 0.1 --vmax 10,0.01");
  EXPECT_NE(r.stderr_text.find("axis 2"), std::string::npos) << r.stderr_text;
}

}  // namespace
