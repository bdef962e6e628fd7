// SPDX-License-Identifier: Apache-2.0
// settle simulate and settle reproduce as a user meets them: the JSON keys the issue names, exit
// status 2 with the offending option for bad plant parameters, CSV output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "run_cli.hpp"
#include "scratch.hpp"

namespace {

struct Out {
  int status;
  std::string text;
};

Out run(const std::string& args) {
  const settle::test::CliResult r = settle::test::run_cli(args);
  return {r.status, r.out};
}

bool has(const std::string& s, const std::string& key) { return s.find("\"" + key + "\":") != std::string::npos; }

TEST(SimCli, SimulateJsonHasTheNamedKeys) {
  const Out o = run("simulate --plant beam --profile scurve --distance 0.07 --time 0.228 --json");
  ASSERT_EQ(o.status, 0) << o.text;
  for (const char* k : {"residual_amplitude", "prv_percent", "peak_deflection", "final_energy", "modes", "omega",
                        "beta", "lambda"}) {
    EXPECT_TRUE(has(o.text, k)) << k << "\n" << o.text;
  }
}

// Issue 12's hang: a denormal damping ratio ends (the search is bounded) and says why there is no
// settling time, apart from an undamped mode that truly never settles.
TEST(SimCli, SettlingBeyondTheHorizonIsToldApartFromUndamped) {
  const Out slow = run("simulate --plant modes --mode 10,1e-320,1 --profile poly345 --distance 0.1 --time 0.5 --json");
  ASSERT_EQ(slow.status, 0) << slow.text;
  EXPECT_NE(slow.text.find("\"settling\":\"beyond_horizon\""), std::string::npos) << slow.text;
  EXPECT_NE(slow.text.find("\"settling_time\":null"), std::string::npos) << slow.text;
  const Out text = run("simulate --plant modes --mode 10,1e-320,1 --profile poly345 --distance 0.1 --time 0.5");
  EXPECT_NE(text.text.find("not within 3600 s"), std::string::npos) << text.text;
  const Out undamped = run("simulate --plant modes --mode 10,0,1 --profile poly345 --distance 0.1 --time 0.5 --json");
  ASSERT_EQ(undamped.status, 0) << undamped.text;
  EXPECT_NE(undamped.text.find("\"settling\":\"undamped\""), std::string::npos) << undamped.text;
}

TEST(SimCli, EveryPlantRuns) {
  for (const char* p : {"--plant sdof --mass 2 --stiffness 500 --damping 3", "--plant belt --inertia 5",
                        "--plant modes --mode 20,0.01,1 --mode 90,0.02,0.3", "--plant beam --modes 5 --modal-damping 0.01"}) {
    const Out o = run(std::string{"simulate "} + p + " --profile poly345 --distance 1 --time 0.5 --json");
    EXPECT_EQ(o.status, 0) << p << "\n" << o.text;
    EXPECT_TRUE(has(o.text, "prv_percent")) << p;
  }
}

TEST(SimCli, BadPlantParametersAreRefusedWithTheirCode) {
  // Each value outside its documented range is refused by the option table, naming the option.
  const Out o = run("simulate --plant sdof --mass -1 --profile poly345 --distance 1 --time 1 --json");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.text.find("\"error\":\"out_of_range\",\"parameter\":\"--mass\""), std::string::npos) << o.text;
  const Out z = run("simulate --plant beam --length 0 --profile poly345 --distance 1 --time 1 --json");
  EXPECT_EQ(z.status, 2);
  EXPECT_NE(z.text.find("\"error\":\"out_of_range\",\"parameter\":\"--length\""), std::string::npos) << z.text;
  const Out d = run("simulate --plant modes --mode 10,1.2,1 --profile poly345 --distance 1 --time 1 --json");
  EXPECT_EQ(d.status, 2);
  EXPECT_NE(d.text.find("\"error\":\"out_of_range\",\"parameter\":\"--mode\""), std::string::npos) << d.text;
  // Values each in range that combine into an overdamped plant: the plant's own code.
  const Out c = run("simulate --plant sdof --damping 100 --profile poly345 --distance 1 --time 1 --json");
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.text.find("\"error\":\"not_underdamped\",\"parameter\":\"--damping\""), std::string::npos) << c.text;
}

TEST(SimCli, ErrorsNameTheOptionToChange) {
  const Out o = run("simulate --plant belt --pulley-R -1 --profile poly345 --distance 1 --time 1 --json");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.text.find("\"parameter\":\"--pulley-R\""), std::string::npos) << o.text;
  const Out x = run("simulate --plant sdof --length 1 --profile poly345 --distance 1 --time 1 --json");
  EXPECT_EQ(x.status, 2);
  EXPECT_NE(x.text.find("option_not_for_plant"), std::string::npos) << x.text;
}

TEST(SimCli, CsvHistory) {
  const std::string path = settle::test::scratch_path("sim_cli.csv");
  const Out o = run("simulate --plant sdof --profile ramp-versine --distance 1 --time 0.167 --csv " + path);
  ASSERT_EQ(o.status, 0) << o.text;
  std::ifstream f{path};
  std::string header;
  std::getline(f, header);
  EXPECT_EQ(header.rfind("t_s,command_position_m,", 0), 0u) << header;
}

// number after "key": in a one-line JSON document.
double json_number(const std::string& doc, const std::string& key) {
  const std::size_t at = doc.find("\"" + key + "\":");
  return at == std::string::npos ? std::nan("") : std::stod(doc.substr(at + key.size() + 3));
}

// --png draws the move and what it leaves: the figure's data beside it is the run's own history, and
// what its zoomed tail shows is the residual the text reports (the free response after the move
// stays within the residual amplitude, the sum of the modes' amplitudes, and comes close to it).
// plan --png and sample --png draw the move they print: sample's figure data is its own output, the
// plan's 2001 samples end on the target, and each panel's dashed line is the plan's peak.
TEST(SimCli, PlanAndSampleDrawTheMoveTheyPrint) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path{::testing::TempDir()} / "settle move 'figure'";
  fs::create_directories(dir);
  const std::vector<std::string> move = {"--profile", "fastest", "--distance", "0.1", "--vmax", "1", "--amax", "20",
                                         "--jmax", "800", "--omega", "22", "--zeta", "0.02"};
  auto run = [&](std::vector<std::string> head, const std::vector<std::string>& tail) {
    head.insert(head.end(), move.begin(), move.end());
    head.insert(head.end(), tail.begin(), tail.end());
    return settle::test::run_cli_argv(head);
  };
  auto read = [](const fs::path& p) {
    std::ifstream f{p};
    return std::string{std::istreambuf_iterator<char>{f}, {}};
  };
  const settle::test::CliResult s = run({"sample"}, {"--dt", "0.001", "--png", (dir / "sampled.png").string()});
  ASSERT_EQ(s.status, 0) << s.out;
  EXPECT_EQ(read(dir / "sampled.csv"), s.stdout_text);
  EXPECT_GT(fs::file_size(dir / "sampled.png"), 10000u);  // gnuplot: tools/setup installs it
  const settle::test::CliResult p = run({"plan"}, {"--json", "--png", (dir / "planned.png").string()});
  ASSERT_EQ(p.status, 0) << p.out;
  EXPECT_GT(fs::file_size(dir / "planned.png"), 10000u);
  std::istringstream csv{read(dir / "planned.csv")};
  std::string line, last;
  std::size_t rows = 0;
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(line, "t_s,position_m,velocity_m_per_s,acceleration_m_per_s2,jerk_m_per_s3");
  while (std::getline(csv, line)) {
    ++rows;
    last = line;
  }
  EXPECT_EQ(rows, 2001u);
  double t = 0, pos = 0;
  ASSERT_EQ(std::sscanf(last.c_str(), "%lf,%lf", &t, &pos), 2) << last;
  EXPECT_NEAR(t, json_number(p.stdout_text, "duration"), 1e-9);
  EXPECT_NEAR(pos, 0.1, 1e-12);
  const std::string script = read(dir / "planned.gp");
  for (const char* peak : {"velocity", "acceleration", "jerk"}) {
    char value[64];
    std::snprintf(value, sizeof value, "%.17g with lines dashtype 2", json_number(p.stdout_text, peak));
    EXPECT_NE(script.find(value), std::string::npos) << peak << " " << value;
  }
  // One axis is drawn; several are refused before anything is written.
  const settle::test::CliResult axes = settle::test::run_cli_argv(
      {"plan", "--axes", "2", "--profile", "scurve", "--distance", "0.1,0.2", "--time", "0.5", "--png",
       (dir / "axes.png").string()});
  EXPECT_EQ(axes.status, 2);
  EXPECT_NE(axes.out.find("--png: draws one axis"), std::string::npos) << axes.out;
  EXPECT_FALSE(fs::exists(dir / "axes.gp"));
  const settle::test::CliResult many = run({"sample"}, {"--dt", "2e-7", "--png", (dir / "many.png").string()});
  EXPECT_EQ(many.status, 2);
  EXPECT_NE(many.out.find("a figure takes at most 1e6"), std::string::npos) << many.out;
}

TEST(SimCli, AFigureShowsTheResidualZoomedAfterTheMove) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path{::testing::TempDir()} / "settle sim 'figure'";
  fs::create_directories(dir);
  const std::vector<std::string> move = {"simulate", "--plant", "modes", "--mode", "22,0.1,1", "--mode", "50,0.02,0.3",
                                         "--profile", "scurve", "--distance", "0.1", "--time", "0.5", "--omega", "22"};
  const auto with = [&](std::vector<std::string> head, const std::vector<std::string>& tail) {
    head.insert(head.end(), tail.begin(), tail.end());
    return settle::test::run_cli_argv(head);
  };
  const settle::test::CliResult r = with(move, {"--json", "--png", (dir / "scurve.png").string()});
  ASSERT_EQ(r.status, 0) << r.out;
  const double residual = json_number(r.stdout_text, "residual_amplitude");
  const double end = json_number(r.stdout_text, "duration");
  ASSERT_GT(residual, 1e-4);
  std::ifstream csv{dir / "scurve.csv"};
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  ASSERT_EQ(line.rfind("t_s,command_position_m,command_velocity_m_per_s,command_acceleration_m_per_s2,deflection_m,position_m,", 0),
            0u);
  double tail_peak = 0.0;
  std::size_t tail_rows = 0;
  while (std::getline(csv, line)) {
    double t = 0, p = 0, v = 0, a = 0, deflection = 0, position = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf", &t, &p, &v, &a, &deflection, &position), 6) << line;
    if (t < end) continue;
    ++tail_rows;
    tail_peak = std::max(tail_peak, std::fabs(position - 0.1));
    EXPECT_NEAR(deflection, position - 0.1, 1e-12) << "t " << t;  // the tail panel plots the deflection
  }
  EXPECT_GT(tail_rows, 1000u);
  EXPECT_LE(tail_peak, residual * (1.0 + 1e-6));
  EXPECT_GE(tail_peak, 0.5 * residual);
  // The script draws the residual amplitude and starts the zoomed panel where the move ends.
  std::ifstream gp{dir / "scurve.gp"};
  const std::string script{std::istreambuf_iterator<char>{gp}, {}};
  char value[64];
  std::snprintf(value, sizeof value, "%.17g", residual);
  EXPECT_NE(script.find(std::string{value} + " with lines dashtype 2 lc rgb 'red'"), std::string::npos);
  std::snprintf(value, sizeof value, "set xrange [%.17g:*]", end);
  EXPECT_NE(script.find(value), std::string::npos);
  EXPECT_GT(fs::file_size(dir / "scurve.png"), 10000u);  // gnuplot: tools/setup installs it
  // A name that is not a PNG, and a figure of several axes, are refused before anything runs.
  const settle::test::CliResult jpg = with(move, {"--png", (dir / "scurve.jpg").string()});
  EXPECT_EQ(jpg.status, 2);
  EXPECT_NE(jpg.out.find("--png: the figure's file name must end in .png"), std::string::npos) << jpg.out;
  EXPECT_FALSE(fs::exists(dir / "scurve.jpg"));
  const settle::test::CliResult axes =
      with({"simulate", "--axes", "2", "--plant", "sdof", "--profile", "scurve", "--distance", "0.1,0.1", "--time",
            "0.5"},
           {"--png", (dir / "axes.png").string()});
  EXPECT_EQ(axes.status, 2) << axes.out;
  EXPECT_NE(axes.out.find("--png: one axis at a time"), std::string::npos) << axes.out;
  EXPECT_FALSE(fs::exists(dir / "axes.png"));
  fs::remove_all(dir);
}

// A CSV that cannot take its rows is a failure (exit 1), not exit 0 with every row lost: a file that
// opens but takes no data (/proc/version) and a full disk (/dev/full).
TEST(SimCli, ACsvThatLosesItsRowsIsAFailure) {
  for (const char* path : {"/proc/version", "/dev/full"}) {
    const Out o = run(std::string{"simulate --plant sdof --profile scurve --distance 0.1 --time 0.5 --csv "} + path);
    EXPECT_EQ(o.status, 1) << path << ": " << o.text;
    EXPECT_NE(o.text.find(std::string{"cannot write "} + path), std::string::npos) << o.text;
  }
}

TEST(SimCli, Reproduce004Json) {
  const Out o = run("reproduce 004 --json");
  ASSERT_EQ(o.status, 0) << o.text;
  for (const char* k : {"H_initial", "H_paper", "H_optimized", "gammas"}) EXPECT_TRUE(has(o.text, k)) << k;
}

// Seed 001 states how its residuals compare: referred to one time, divided by the distance.
TEST(SimCli, Reproduce001JsonStatesItsResidualConvention) {
  const Out o = run("reproduce 001 --json");
  ASSERT_EQ(o.status, 0) << o.text;
  EXPECT_NE(o.text.find("\"residual_at\":0.167"), std::string::npos) << o.text;
  EXPECT_NE(o.text.find("\"normalised_by\":\"distance\""), std::string::npos) << o.text;
  EXPECT_NE(o.text.find("\"method\":\"ei\""), std::string::npos) << o.text;
}

TEST(SimCli, UnknownExperiment) { EXPECT_EQ(run("reproduce 003").status, 2); }

}  // namespace
