// SPDX-License-Identifier: Apache-2.0
// The settle CLI as a user meets it: exit codes, the one-line error naming the parameter, the
// JSON shapes of success and error, and CSV sampling. JSON is checked structurally with a small
// parser here, so a malformed document fails the test.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cctype>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "refusal.hpp"
#include "run_cli.hpp"

namespace {

using settle::test::CliResult;
CliResult run(const std::string& args) { return settle::test::run_cli(args); }

// Minimal JSON reader: returns flattened "a.b.c" -> raw value text; fails on malformed input.
struct Json {
  std::map<std::string, std::string> flat;
  bool ok = true;
  const std::string& s;
  std::size_t i = 0;
  explicit Json(const std::string& text) : s{text} {
    skip();
    value("");
    skip();
    if (i != s.size()) ok = false;
  }
  void skip() {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  }
  std::string str() {
    std::string r;
    if (s[i] != '"') {
      ok = false;
      return r;
    }
    for (++i; i < s.size() && s[i] != '"'; ++i) {
      if (s[i] == '\\') ++i;
      r += s[i];
    }
    ++i;
    return r;
  }
  void value(const std::string& path) {
    skip();
    if (i >= s.size()) {
      ok = false;
      return;
    }
    if (s[i] == '{') {
      ++i;
      skip();
      if (s[i] == '}') {
        ++i;
        return;
      }
      while (ok) {
        skip();
        const std::string k = str();
        skip();
        if (s[i++] != ':') ok = false;
        value(path.empty() ? k : path + "." + k);
        skip();
        if (s[i] == ',') {
          ++i;
          continue;
        }
        if (s[i++] != '}') ok = false;
        return;
      }
    } else if (s[i] == '[') {
      ++i;
      int idx = 0;
      skip();
      if (s[i] == ']') {
        ++i;
        return;
      }
      while (ok) {
        value(path + "." + std::to_string(idx++));
        skip();
        if (s[i] == ',') {
          ++i;
          continue;
        }
        if (s[i++] != ']') ok = false;
        return;
      }
    } else if (s[i] == '"') {
      flat[path] = str();
    } else {
      const std::size_t b = i;
      while (i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '.' || s[i] == '-' || s[i] == '+')) ++i;
      if (i == b) ok = false;
      flat[path] = s.substr(b, i - b);
    }
  }
};

// The exit status of settle with its standard output on /dev/full (every write fails: ENOSPC).
int status_onto_dev_full(std::vector<std::string> args) {
  args.insert(args.begin(), SETTLE_CLI);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/full", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  int status = 0;
  if (rc != 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

// Output that cannot be written is a runtime failure (exit 1), never success with the output lost:
// `settle plan ... --json > /dev/full` exited 0.
TEST(Cli, AnUnwritableStandardOutputIsAFailure) {
  EXPECT_EQ(status_onto_dev_full({"plan", "--profile", "scurve", "--distance", "0.1", "--time", "0.5", "--omega",
                                  "22.05", "--json"}),
            1);
  EXPECT_EQ(status_onto_dev_full({"plan", "--profile", "scurve", "--distance", "0.1", "--time", "0.5", "--omega",
                                  "22.05"}),
            1);
  EXPECT_EQ(status_onto_dev_full({"--version"}), 1);
  EXPECT_EQ(status_onto_dev_full({"sample", "--profile", "poly345", "--distance", "0.1", "--time", "0.5", "--dt",
                                  "0.01"}),
            1);
}

// settle --version: the project's version (CMakeLists.txt), one line, exit 0.
TEST(Cli, VersionIsTheProjects) {
  const CliResult r = run("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.stdout_text, std::string{"settle "} + SETTLE_PROJECT_VERSION + "\n");
  EXPECT_NE(run("--help").stdout_text.find("settle --version"), std::string::npos);
}

TEST(Cli, PlanPrintsTheSeed000Plan) {
  const CliResult r = run("plan --profile scurve --distance 0.1 --time 0.228 --omega 22.04871");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("duration     0.228"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("A2"), std::string::npos);
}

TEST(Cli, PlanJsonHasTheDocumentedShape) {
  const CliResult r = run("plan --profile ramp-versine --distance 1 --time 0.167 --omega 28.2843 --zeta 0.159 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const Json j{r.out};
  ASSERT_TRUE(j.ok) << r.out;
  EXPECT_EQ(j.flat.at("status"), "ok");
  EXPECT_EQ(j.flat.at("profile"), "ramp-versine");
  EXPECT_NEAR(std::stod(j.flat.at("duration")), 0.167, 1e-12);
  EXPECT_NEAR(std::stod(j.flat.at("params.Y1")), 1.3462, 2e-3);
  EXPECT_EQ(j.flat.at("peaks.velocity_step"), "true");
  EXPECT_EQ(j.flat.at("peaks.acceleration"), "null");  // an impulse, flagged, not a number
  const CliResult text = run("plan --profile ramp-versine --distance 1 --time 0.167 --omega 28.2843 --zeta 0.159");
  ASSERT_EQ(text.status, 0) << text.out;
  EXPECT_EQ(text.stdout_text.find("inf"), std::string::npos) << "an impulse is not printed as a number:\n" << text.out;
  EXPECT_EQ(j.flat.count("shaper.impulses.0.amplitude"), 1u);
}

TEST(Cli, BadRequestsExitTwoNamingTheParameter) {
  struct Case {
    const char* args;
    const char* param;
    const char* code;
  };
  const Case cases[] = {
      {"plan --profile scurve --distance 0.1 --time -1 --omega 20", "--time", "out_of_range"},
      {"plan --profile scurve --distance 0.1 --time 1 --omega 0", "--omega", "out_of_range"},
      {"plan --profile scurve --distance 0.1 --time 1 --omega 20 --zeta 1.5", "--zeta", "out_of_range"},
      {"plan --profile scurve --distance nan --time 1 --omega 20", "--distance", "non_finite_input"},
      {"plan --profile scurve --distance 1 --time 1 --vmax 0.5 --omega 20", "--time", "time_too_short_for_vmax"},
      {"plan --profile scurve --distance 0.1 --time 0.2 --omega 20 --amax 1", "--amax", "acceleration_limit_exceeded"},
      {"plan --profile pseudopoly --distance 1 --time 1 --gammas 3,3,5", "--gammas", "gammas_not_distinct"},
      {"plan --profile pseudopoly --distance 1 --time 1 --gammas 1.5,3,5", "--gammas", "out_of_range"},
      {"plan --profile warp --distance 1 --time 1", "--profile", "unknown_profile"},
      {"plan --profile scurve --distance abc --time 1 --omega 2", "--distance", "bad_number"},
      {"plan --profile scurve --distance 1 --time 1 --omega 2 --bogus 3", "--bogus", "bad_option"},
      {"sample --profile poly345 --distance 1 --time 1 --dt -0.1", "--dt", "out_of_range"},
      // The drive's EDS is read before the bus is opened: a bad one exits 2 whatever the bus.
      {"plant --bus no-such-can9 --eds /nonexistent/drive.eds", "--eds", "bad_eds"},
      {"plant --bus no-such-can9 --eds " SETTLE_TEST_EDS_DIR "/no_interpolation_period_drive.eds --node 0", "--node",
       "out_of_range"},
      // Where another vendor's drive serves its load position: only an object its EDS describes.
      {"plant --bus no-such-can9 --load-feedback 0x2100:1", "--load-feedback", "bad_load_feedback"},
      {"plant --bus no-such-can9 --eds " SETTLE_TEST_EDS_DIR "/no_interpolation_period_drive.eds --load-feedback "
       "0x2100:1", "--load-feedback", "bad_load_feedback"},
  };
  for (const Case& c : cases) {
    const CliResult text = run(c.args);
    EXPECT_EQ(text.status, 2) << c.args;
    EXPECT_EQ(std::count(text.out.begin(), text.out.end(), '\n'), 1) << "one line: " << text.out;
    EXPECT_TRUE(text.stdout_text.empty()) << text.stdout_text;
    EXPECT_NE(text.out.find(c.param), std::string::npos) << text.out;
    const CliResult json = run(std::string{c.args} + " --json");
    EXPECT_EQ(json.status, 2) << c.args;
    const Json j{json.out};
    ASSERT_TRUE(j.ok) << json.out;
    EXPECT_EQ(j.flat.at("status"), "error");
    EXPECT_EQ(j.flat.at("error"), c.code) << c.args;
    EXPECT_EQ(j.flat.at("parameter"), c.param);
    EXPECT_FALSE(j.flat.at("message").empty());
  }
}

// --profile fastest: the plan names the family that won and what each family reached; --omega
// repeats (one --zeta per --omega) for this profile only; --robust is this profile's only.
TEST(Cli, FastestPlansSeveralModesAndSaysWhichFamilyWon) {
  const CliResult one = run("plan --profile fastest --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 22 --json");
  ASSERT_EQ(one.status, 0) << one.out;
  const Json j{one.out};
  ASSERT_TRUE(j.ok) << one.out;
  EXPECT_EQ(j.flat.at("profile"), "fastest");
  EXPECT_EQ(j.flat.count("family"), 1u);
  EXPECT_LE(std::stod(j.flat.at("duration")), 0.3178);  // the time-optimal * ZV
  EXPECT_NEAR(std::stod(j.flat.at("params.time_zv")), 0.3178, 5e-5);
  const CliResult two = run(
      "plan --profile fastest --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 22 --zeta 0.02 --omega 60 --zeta 0.01");
  ASSERT_EQ(two.status, 0) << two.out;
  EXPECT_NE(two.out.find("family"), std::string::npos) << two.out;
  const CliResult robust =
      run("plan --profile fastest --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 22 --robust 10 --json");
  ASSERT_EQ(robust.status, 0) << robust.out;
  struct Bad {
    const char* args;
    const char* param;
    const char* code;
  };
  const Bad bad[] = {
      {"plan --profile scurve --distance 0.1 --time 1 --omega 20 --omega 30", "--omega", "bad_option"},
      {"plan --profile fastest --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 20 --omega 30 --zeta 0.1 "
       "--zeta 0.1 --zeta 0.1",
       "--zeta", "bad_option"},
      {"plan --profile scurve --distance 0.1 --time 1 --omega 20 --robust 10", "--robust", "unused_option"},
      {"plan --profile fastest --distance 0.1 --time 1 --vmax 1 --amax 20 --jmax 800 --omega 20", "--time",
       "unused_option"},
      {"plan --profile fastest --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 20 --robust 0", "--robust",
       "out_of_range"},
  };
  for (const Bad& c : bad) {
    const CliResult json = run(std::string{c.args} + " --json");
    EXPECT_EQ(json.status, 2) << c.args;
    const Json jj{json.out};
    ASSERT_TRUE(jj.ok) << json.out;
    EXPECT_EQ(jj.flat.at("error"), c.code) << c.args;
    EXPECT_EQ(jj.flat.at("parameter"), c.param) << c.args;
  }
}

// Four modes planned: until a fastest move held 47 segments (31 before, session 26) no family
// found a move for these (time-optimal * ZV for every mode did not fit, nor did the joint ZV
// shaper's 5 copies, and the chains found none) and the request was refused with exit 2; the joint
// ZV move (39 segments) now fits. The reason given where none is found names the table's size
// (move_vocabulary.cpp: reason_of).
TEST(Cli, FastestPlansFourModes) {
  const std::string args =
      "plan --profile fastest --distance 1 --vmax 1 --amax 20 --jmax 800 --omega 2 --zeta 0 --omega 3 --zeta 0 "
      "--omega 4 --zeta 0 --omega 5 --zeta 0";
  const CliResult text = run(args);
  EXPECT_EQ(text.status, 0) << text.out;
  EXPECT_NE(text.out.find("time-optimal*joint-ZV"), std::string::npos) << text.out;
}

// --robust within its range (0, 50] but wider than any move the table holds: the reason says so
// and names what holds it; the band the two-hump EI holds plans.
TEST(Cli, FastestSaysWhenNoMoveHoldsTheRobustBand) {
  const std::string base = "plan --profile fastest --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 22 --robust ";
  // 45 % was refused until the table held 47 segments: time-optimal * EI3 (39 segments) now fits.
  const CliResult ei3 = run(base + "45");
  EXPECT_EQ(ei3.status, 0) << ei3.out;
  EXPECT_NE(ei3.out.find("time-optimal*EI3"), std::string::npos) << ei3.out;
  const CliResult wide = run(base + "49");
  EXPECT_EQ(wide.status, 2) << wide.out;
  EXPECT_NE(wide.out.find("--robust: no family found a move within the limits that keeps every mode's residual "
                          "within 5 % over +-49 % of its frequency"),
            std::string::npos)
      << wide.out;
  EXPECT_NE(wide.out.find("--profile jerk-limited --shaper ei2 or ei3"), std::string::npos) << wide.out;
  settle::test::expect_refused({base + "49", "--robust", "no_solution"});
  const CliResult held = run(base + "35");
  EXPECT_EQ(held.status, 0) << held.out;
  EXPECT_NE(held.out.find("time-optimal*EI2"), std::string::npos) << held.out;
  const CliResult shaped = run("plan --profile jerk-limited --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 22 "
                               "--shaper ei3");
  EXPECT_EQ(shaped.status, 0) << shaped.out;
}

TEST(Cli, PlantSimulatesTheDriveItsEdsDescribes) {
  // Each bundled drive and the test drive load; the bus is what fails (exit 1), not the EDS.
  for (const std::string& eds : {std::string{SETTLE_EDS_DIR} + "/split_rpdo_drive.eds",
                                std::string{SETTLE_EDS_DIR} + "/velocity_feedback_drive.eds",
                                std::string{SETTLE_EDS_DIR} + "/static_mapping_drive.eds",
                                std::string{SETTLE_TEST_EDS_DIR} + "/no_interpolation_period_drive.eds"}) {
    const CliResult r = run("plant --bus no-such-can9 --eds " + eds);
    EXPECT_EQ(r.status, 1) << r.out;
    EXPECT_NE(r.out.find("cannot open no-such-can9"), std::string::npos) << r.out;
  }
  // An EDS the simulated drive cannot be: one line naming the file and the object.
  const std::string bad = std::string{SETTLE_EDS_DIR} + "/../CMakeLists.txt";
  const CliResult r = run("plant --bus no-such-can9 --eds " + bad);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_NE(r.out.find("--eds: " + bad + ": "), std::string::npos) << r.out;
}

TEST(Cli, SampleWritesCsvOverTheWholeMove) {
  const CliResult r = run("sample --profile poly345 --distance 2 --time 1 --dt 0.25");
  ASSERT_EQ(r.status, 0) << r.out;
  std::vector<std::string> lines;
  std::size_t b = 0;
  for (std::size_t e; (e = r.out.find('\n', b)) != std::string::npos; b = e + 1) lines.push_back(r.out.substr(b, e - b));
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[0], "t_s,position_m,velocity_m_per_s,acceleration_m_per_s2,jerk_m_per_s3");
  EXPECT_EQ(lines[1].substr(0, 4), "0,0,");
  EXPECT_EQ(lines[3].substr(0, 6), "0.5,1,");  // halfway there at half time
  EXPECT_EQ(lines[5].substr(0, 4), "1,2,");
}

TEST(Cli, UnknownCommandAndNoCommandExitTwo) {
  EXPECT_EQ(run("frobnicate").status, 2);
  EXPECT_EQ(run("").status, 2);
  EXPECT_EQ(run("--help").status, 0);
}

}  // namespace
