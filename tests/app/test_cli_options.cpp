// SPDX-License-Identifier: Apache-2.0
// The CLI's option layer as a user meets it (issue 12 item 4, issue 13 "A CLI that explains
// itself"): every bad value exits 2 with one line naming the right option and nothing on stdout
// (or, with --json, only the JSON error object); sizes are refused before any work; every
// option a command accepts is in its help.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "move_options.hpp"
#include "options.hpp"
#include "refusal.hpp"
#include "run_cli.hpp"
#include "settle/plant/move_vocabulary.hpp"

namespace {

using settle::test::CliResult;
using settle::test::run_cli;
using settle::test::run_cli_argv;
using settle::test::Case;
using settle::test::expect_refused;

// A move, a plant and a bus that are valid for stream and plant, so that the one bad option of
// each case is the only thing wrong. The interface does not exist: nothing here opens a bus.
const std::string kStream = "stream --bus loopback --profile poly345 --distance 0.01 --time 0.1 ";
const std::string kPlant = "plant --bus settle-no-such-can ";
const std::string kPlan = "plan --profile poly345 --distance 0.1 --time 1 ";
const std::string kSimulate = "simulate --profile poly345 --distance 0.1 --time 1 ";

// Issue 12 item 4, case by case.
TEST(CliOptions, StreamAndPlantIntegersAreCheckedNotCast) {
  const Case cases[] = {
      {kStream + "--node 0", "--node", "out_of_range"},
      {kStream + "--node 128", "--node", "out_of_range"},
      {kStream + "--node NaN", "--node", "non_finite_input"},
      {kStream + "--node -1", "--node", "out_of_range"},
      {kStream + "--node 1.5", "--node", "not_an_integer"},
      {kStream + "--node 99999999999999999999999", "--node", ""},
      {kStream + "--axis-vmax 0", "--axis-vmax", "out_of_range"},
      {kStream + "--heartbeat-ms -1", "--heartbeat-ms", "out_of_range"},
      {kStream + "--heartbeat-ms NaN", "--heartbeat-ms", "non_finite_input"},
      {kStream + "--heartbeat-ms 70000", "--heartbeat-ms", "out_of_range"},
      {kStream + "--sdo-timeout-ms -1", "--sdo-timeout-ms", "out_of_range"},
      {kStream + "--feedback-timeout-periods 65536", "--feedback-timeout-periods", "out_of_range"},
      {kStream + "--feedback-timeout-periods 2.5", "--feedback-timeout-periods", "not_an_integer"},
      {kStream + "--rt-priority 1e10", "--rt-priority", ""},
      {kStream + "--rt-priority 100", "--rt-priority", "out_of_range"},
      {kStream + "--pm-qos maybe", "--pm-qos", ""},
      {kStream + "--bitrate 9999", "--bitrate", "out_of_range"},
      {kStream + "--bitrate 1000001", "--bitrate", "out_of_range"},
      {kStream + "--bitrate NaN", "--bitrate", "non_finite_input"},
      {kStream + "--bitrate 5e5.5", "--bitrate", ""},
      {kPlant + "--sync-loss-periods 0", "--sync-loss-periods", "out_of_range"},
      {kPlant + "--sync-loss-periods 300", "--sync-loss-periods", "out_of_range"},
      {kPlant + "--duration -1", "--duration", "out_of_range"},
      {kPlant + "--duration NaN", "--duration", "non_finite_input"},
      {kPlant + "--node 128", "--node", "out_of_range"},
      {kPlant + "--heartbeat-ms 70000", "--heartbeat-ms", "out_of_range"},
  };
  for (const Case& c : cases) expect_refused(c);
}

// One axis on Settle's default mapping needs 420 bits per SYNC period with worst-case stuffing
// (SYNC 55, RPDO1 115, TPDO1 115, TPDO2 135; hal/canopen/bus_load.hpp), 348 without: a period that
// holds fewer is refused before anything is sent, naming the numbers; one that holds 420 runs.
TEST(CliOptions, StreamRefusesAPeriodTheBusCannotCarry) {
  const Case cases[] = {
      {kStream + "--period-us 400", "--bitrate", "bus_overload"},
      {kStream + "--bitrate 125000", "--bitrate", "bus_overload"},
      {kStream + "--bitrate 419000", "--bitrate", "bus_overload"},
  };
  for (const Case& c : cases) expect_refused(c);
  const CliResult r = run_cli(kStream + "--bitrate 125000");
  EXPECT_NE(r.stderr_text.find("--bitrate: 1 axis needs 420 bits per SYNC period with worst-case bit stuffing (348 "
                               "without), 125 available: 125000 bit/s x 1000 us"),
            std::string::npos)
      << r.stderr_text;
  const CliResult p = run_cli(kStream + "--period-us 400");
  EXPECT_NE(p.stderr_text.find("400 available: 1000000 bit/s x 400 us"), std::string::npos) << p.stderr_text;
  // Exactly the bits needed: accepted, and the move streams (loopback).
  const CliResult ok = run_cli(kStream + "--bitrate 420000 --settle-time 0.1");
  EXPECT_EQ(ok.status, 0) << ok.out;
}

TEST(CliOptions, NumbersOutsideTheirRangeNeverPrintInfOrNan) {
  const Case cases[] = {
      {"plan --profile poly345 --time 1 --distance 1e308", "--distance", "out_of_range"},
      {kSimulate + "--plant sdof --stiffness 1e308", "--stiffness", "out_of_range"},
      {kPlan + "--vmax inf", "--vmax", "non_finite_input"},
      {kPlan + "--omega -inf", "--omega", "non_finite_input"},
      {"plan --profile poly345 --time 1 --distance 1e400", "--distance", "non_finite_input"},
      {kPlan + "--zeta 1", "--zeta", "out_of_range"},
      {"plan --profile poly345 --time 1 --distance 1x", "--distance", "bad_number"},
      {"plan --profile poly345 --time 1 --distance ''", "--distance", "bad_number"},
      {kSimulate + "--plant beam --modes 2.5", "--modes", "not_an_integer"},
  };
  for (const Case& c : cases) expect_refused(c);
  // At the edge of every range the result is finite, or refused: never inf or nan with exit 0.
  for (const std::string args :
       {"plan --profile poly345 --distance 1e6 --time 1e-6 --json", "plan --profile poly345 --distance -1e6 --time 3600 --json",
        "plan --profile trapezoid --distance 1e6 --vmax 1e9 --amax 1e12 --json",
        "plan --profile scurve --distance 1e-300 --time 1e-6 --omega 1e6 --json"}) {
    const CliResult r = run_cli(args);
    EXPECT_TRUE(r.status == 0 || r.status == 2) << args << "\n" << r.out;
    if (r.status == 0) {
      // The JSON writer prints a non-finite number as null, so the values themselves are checked:
      // the move's duration, distance, every parameter and the velocity peak are finite numbers.
      const nlohmann::json j = nlohmann::json::parse(r.stdout_text);
      for (const char* key : {"duration", "distance", "profile_duration"}) {
        ASSERT_TRUE(j.contains(key) && j[key].is_number()) << args << ": " << key << "\n" << r.out;
        EXPECT_TRUE(std::isfinite(j[key].get<double>())) << args << ": " << key;
      }
      ASSERT_TRUE(j.contains("params") && j["params"].is_object()) << args;
      for (const auto& [k, v] : j["params"].items()) {
        EXPECT_TRUE(v.is_number() && std::isfinite(v.get<double>())) << args << ": params." << k << " = " << v;
      }
      EXPECT_TRUE(j["peaks"]["velocity"].is_number()) << args << "\n" << r.out;
    }
  }
}

TEST(CliOptions, DuplicatesListsAndUnknownOptions) {
  const Case cases[] = {
      {kPlan + "--time 2", "--time", "duplicate_option"},
      {kStream + "--node 1 --node 2", "--node", "duplicate_option"},
      {kSimulate + "--sensitivity --sensitivity", "--sensitivity", "duplicate_option"},
      {"plan --profile pseudopoly --distance 1 --time 1 --gammas 3,4,5,", "--gammas", "bad_list"},
      {"plan --profile pseudopoly --distance 1 --time 1 --gammas ,3,4", "--gammas", "bad_list"},
      {"plan --profile pseudopoly --distance 1 --time 1 --gammas 3,,4", "--gammas", "bad_list"},
      {"plan --profile pseudopoly --distance 1 --time 1 --gammas 3,4,5,6,7,8,9,10,11", "--gammas", "bad_list"},
      {"plan --profile ramp-versine --distance 1 --time 1 --omega 20 --y 1,2", "--y", "bad_list"},
      {kSimulate + "--plant modes --mode 10", "--mode", "bad_list"},
      {kPlan + "--distnce 1", "--distnce", "bad_option"},
      {kPlan + "--time", "--time", ""},  // duplicate, or a missing value: --time is named either way
      {"plan --profile poly345 --distance 0.1 --time", "--time", "missing_value"},
      {"plan --profile poly345 --distance --time 1", "--distance", "missing_value"},
      {kPlan + "stray", "--time", "bad_option"},
  };
  for (const Case& c : cases) expect_refused(c);
  // The unknown option's error names the nearest valid one.
  const CliResult r = run_cli(kPlan + "--distnce 1");
  EXPECT_NE(r.stderr_text.find("did you mean --distance"), std::string::npos) << r.stderr_text;
  const CliResult s = run_cli(kStream + "--heartbeat 100");
  EXPECT_NE(s.stderr_text.find("did you mean --heartbeat-ms"), std::string::npos) << s.stderr_text;
  // An empty value is refused, naming the option.
  const CliResult e = run_cli_argv({"plan", "--profile", "poly345", "--time", "1", "--distance", ""});
  EXPECT_EQ(e.status, 2);
  EXPECT_NE(e.stderr_text.find("--distance: '' is not a number"), std::string::npos) << e.stderr_text;
  // --mode is documented as repeatable: twice is fine.
  EXPECT_EQ(run_cli(kSimulate + "--plant modes --mode 20,0.01,1 --mode 90,0.02,0.3").status, 0);
  // A value that starts with '-' is a value, not an option.
  EXPECT_EQ(run_cli("plan --profile poly345 --distance -0.1 --time 1").status, 0);
  EXPECT_EQ(run_cli("plan --profile poly345 --distance=-0 --time=1").status, 0);
}

// settle drive: the bus options, the object's index, sub-index and type, and a value that is
// missing; each refused naming the option, before any bus is opened (the interface does not exist).
TEST(CliOptions, DriveOptionsAreChecked) {
  const std::string read = "drive read --bus settle-no-such-can --index 0x6041 --type u16 ";
  const Case cases[] = {
      {"drive info --bus settle-no-such-can --node 0", "--node", "out_of_range"},
      {"drive info --bus settle-no-such-can --node 128", "--node", "out_of_range"},
      {"drive info --bus settle-no-such-can --node nan", "--node", "non_finite_input"},
      {"drive info --bus settle-no-such-can --timeout-ms 0", "--timeout-ms", "out_of_range"},
      {"drive info --bus settle-no-such-can --timeout-ms 60001", "--timeout-ms", "out_of_range"},
      {"drive info --bus settle-no-such-can --timeout-ms 1e400", "--timeout-ms", "non_finite_input"},
      {"drive scan --bus settle-no-such-can --timeout-ms -5", "--timeout-ms", "out_of_range"},
      {"drive scan --bus settle-no-such-can --node 1", "--node", "bad_option"},
      {"drive read --bus settle-no-such-can --type u16", "--index", "missing_option"},
      {"drive read --bus settle-no-such-can --index 0x2100", "--type", "missing_option"},
      {"drive write --bus settle-no-such-can --index 0x6041 --type u16", "--value", "missing_option"},
      {read + "--index 0x6042", "--index", "duplicate_option"},
      {"drive read --type u16 --index 0", "--index", "out_of_range"},
      {"drive read --type u16 --index 0x10000", "--index", "out_of_range"},
      {"drive read --type u16 --index 99999999999999999999", "--index", "out_of_range"},
      {"drive read --type u16 --index 0xZZ", "--index", "bad_number"},
      {"drive read --type u16 --index 0x", "--index", "bad_number"},
      {"drive read --type u16 --index -0x10", "--index", "out_of_range"},
      {"drive read --type u16 --index 0x1p3", "--index", "not_an_integer"},
      {"drive read --type u16 --index NaN", "--index", "non_finite_input"},
      {read + "--sub 256", "--sub", "out_of_range"},
      {read + "--sub 0x100", "--sub", "out_of_range"},
      {read + "--sub -1", "--sub", "out_of_range"},
      {"drive read --index 0x6041 --type float", "--type", "unknown_type"},
      {"drive write --index 0x6041 --type u16 --value", "--value", "missing_value"},
      {"drive info --bus", "--bus", "missing_value"},
      {"drive info --bus loopback --eds", "--eds", "missing_value"},
      {"drive info --bus loopback --eds /nonexistent/x.eds", "--eds", "bad_eds"},
      {"drive config --bus loopback", "--eds", "missing_option"},
      {"drive config --bus loopback --eds /nonexistent/x.eds", "--eds", "bad_eds"},
      {kStream + "--eds /nonexistent/x.eds", "--eds", "bad_eds"},
      {"drive info --bus settle-no-such-can --eds /nonexistent/x.eds", "--eds", "bad_eds"},
      {"drive scan - --bus loopback", "--drive-scan", "bad_option"},  // a stray argument, one word
  };
  for (const Case& c : cases) expect_refused(c);
}

// The wrong-option cases of the issue: each error names the option the user should change.
TEST(CliOptions, ErrorsBlameTheRightOption) {
  const Case cases[] = {
      {kSimulate + "--plant sdof --stiffness nan", "--stiffness", "non_finite_input"},
      {kSimulate + "--plant sdof --mass 1e-12", "--mass", "out_of_range"},
      // In range, but with the default damping the plant is overdamped: the option changed is blamed.
      {kSimulate + "--plant sdof --mass 1e-4", "--mass", "not_underdamped"},
      {kSimulate + "--plant sdof --damping 1e6", "--damping", "not_underdamped"},
      {kSimulate + "--plant belt --belt-damping 1e8", "--belt-damping", "not_underdamped"},
      {kStream + "--drive servo --servo-damping 1", "--servo-damping", "out_of_range"},
      {kStream + "--scalar half", "--scalar", "unknown_scalar"},
      {kStream + "--scalar", "--scalar", ""},
      // A limit too small for any move to fit is that limit's fault, not another's (a denormal once
      // made the planner blame --vmax for --amax, identify --distance for --jmax).
      {"plan --profile jerk-limited --distance 0.1 --vmax 1 --amax 1e-320 --jmax 100", "--amax", "too_long"},
      {"plan --profile scurve --omega 20 --distance 0.1 --vmax 1 --amax 1e-320", "--amax", "too_long"},
      {"plan --profile jerk-limited --distance 0.1 --vmax 1 --amax 1 --jmax 1e-300", "--jmax", "too_long"},
      {"plan --profile jerk-limited --distance 0.1 --vmax 1e-5 --amax 1 --jmax 100", "--vmax", "too_long"},
      {"identify --bus loopback --jmax 1e-300", "--jmax", "too_long"},
      {"identify --bus loopback --amax 1e-300", "--amax", "too_long"},
      // A mode never given is required, not "must be positive"; a profile planned from its limits
      // given only a time is told which limits it needs (not "give a time or the limits").
      {"plan --profile scurve --distance 0.1 --time 0.5", "--omega", ""},
      {"plan --profile jerk-limited --distance 0.1 --time 0.5", "--vmax", ""},
      {"plan --profile jerk-limited --distance 0.1 --time 0.5 --vmax 1 --amax 10", "--jmax", ""},
      // A retarget that makes the command long is the retarget's fault, not the move's --time.
      {"stream --bus loopback --plant sdof --profile jerk-limited --distance 0.1 --vmax 0.001 --amax 10 --jmax 100 "
       "--retarget-at 50:1e6",
       "--retarget-at", "too_long"},
  };
  for (const Case& c : cases) expect_refused(c);
  // A plan without a shaper that does not converge is not blamed on --shaper.
  settle::core::MoveRequest limits{};
  limits.limits.vmax = 1.0;
  EXPECT_STREQ(settle::plant::option_of(settle::core::Status::no_solution, limits), "--vmax");
  settle::core::MoveRequest timed{};
  timed.time = 1.0;
  EXPECT_STREQ(settle::plant::option_of(settle::core::Status::no_solution, timed), "--time");
  settle::core::MoveRequest shaped{};
  shaped.shaper = settle::core::ShaperKind::ei;
  EXPECT_STREQ(settle::plant::option_of(settle::core::Status::no_solution, shaped), "--shaper");
  // fastest: no move for the modes given.
  settle::core::MoveRequest fastest{};
  fastest.profile = settle::core::ProfileKind::fastest;
  fastest.limits.vmax = 1.0;
  EXPECT_STREQ(settle::plant::option_of(settle::core::Status::no_solution, fastest), "--omega");
}

// The messages of those two say what is wrong: the mode is required; the limits are needed.
TEST(CliOptions, AMissingModeOrMissingLimitsAreSaidSo) {
  const CliResult omega = run_cli("plan --profile scurve --distance 0.1 --time 0.5");
  EXPECT_NE(omega.stderr_text.find("--omega: required"), std::string::npos) << omega.stderr_text;
  const CliResult limits = run_cli("plan --profile jerk-limited --distance 0.1 --time 0.5");
  EXPECT_NE(limits.stderr_text.find("give --vmax, --amax, --jmax"), std::string::npos) << limits.stderr_text;
  EXPECT_EQ(limits.stderr_text.find("give either a move time"), std::string::npos) << limits.stderr_text;
}

// One error contract for every command with --json: a runtime failure (here a bus that does not
// exist) is the error object on stdout, exit 1, as drive info --json prints it; without --json one
// line on stderr naming the command, and nothing on stdout.
TEST(CliOptions, ARuntimeFailureIsTheJsonErrorObjectWithJson) {
  for (const std::string& args :
       {std::string{"stream --bus settle-no-such-can --profile poly345 --distance 0.01 --time 0.1"},
        std::string{"drive info --bus settle-no-such-can"},
        std::string{"simulate --plant sdof --profile scurve --distance 0.1 --time 0.5 --csv /dev/full"}}) {
    SCOPED_TRACE(args);
    const CliResult json = run_cli(args + " --json");
    EXPECT_EQ(json.status, 1) << json.out;
    const auto j = nlohmann::json::parse(json.stdout_text, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << json.stdout_text;
    EXPECT_EQ(j.at("status"), "error");
    EXPECT_FALSE(j.at("error").get<std::string>().empty());
    EXPECT_FALSE(j.at("message").get<std::string>().empty());
    EXPECT_EQ(std::count(json.stdout_text.begin(), json.stdout_text.end(), '\n'), 1) << json.stdout_text;
    const CliResult text = run_cli(args);
    EXPECT_EQ(text.status, 1) << text.out;
    EXPECT_TRUE(text.stdout_text.empty()) << text.stdout_text;
    EXPECT_EQ(text.stderr_text.rfind("settle " + args.substr(0, args.find(' ')), 0), 0u) << text.stderr_text;
  }
}

// Issue 12 item 3: sizes are refused before anything is allocated or printed, naming the option.
TEST(CliOptions, SizesAreBoundedBeforeAnyWork) {
  const std::string csv = ::testing::TempDir() + "settle_cli_size.csv";
  const Case cases[] = {
      {"sample --profile poly345 --distance 1 --time 1 --dt 5e-9", "--dt", "too_many_samples"},
      {kSimulate + "--plant sdof --tail 1e6 --csv " + csv, "--tail", "out_of_range"},
      {kSimulate + "--plant sdof --tail 1e300", "--tail", "out_of_range"},
      {"simulate --profile poly345 --distance 0.1 --time 3000 --plant sdof --tail 3000 --csv " + csv, "--tail",
       "too_long"},
      {kSimulate + "--plant sdof --dt 1e-7 --csv " + csv, "--dt", "too_many_samples"},
      {"simulate --profile poly345 --distance 0.1 --time 3000 --plant sdof --dt 1e-4", "--dt", "too_many_samples"},
      {"simulate --profile poly345 --distance 0.1 --time 1 --plant beam --modes 40 --dt 1e-5", "--dt",
       "too_many_samples"},
      {"sample --profile poly345 --distance 1 --time 3 --dt 1e-6", "--dt", "too_many_samples"},
      {"stream --bus loopback --profile poly345 --distance 0.01 --time 1e5", "--time", "out_of_range"},
      {"stream --bus loopback --profile poly345 --distance 0.01 --time 3600", "--time", "too_long"},
      {"stream --bus loopback --profile poly345 --distance 0.01 --time 3000", "--time", "too_many_samples"},
      {"stream --bus loopback --profile poly345 --distance 0.01 --time 1 --settle-time 200 --period-us 100",
       "--settle-time", "too_many_samples"},
      {"stream --bus loopback --profile poly345 --distance 1000 --time 1", "--counts-per-unit", "out_of_range"},
      {"plan --profile scurve --distance 1 --vmax 1e-9 --amax 1 --omega 20", "--vmax", "too_long"},
  };
  for (const Case& c : cases) expect_refused(c);
  // 2000 --mode options: refused as too many, naming --mode.
  std::vector<std::string> args{"simulate", "--plant", "modes", "--profile", "poly345", "--distance", "0.1", "--time", "1"};
  for (int i = 0; i < 2000; ++i) {
    args.emplace_back("--mode");
    args.emplace_back("10,0.01,1");
  }
  const CliResult r = run_cli_argv(args);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.stderr_text.find("--mode: at most 64"), std::string::npos) << r.stderr_text;
  EXPECT_TRUE(r.stdout_text.empty());
  std::vector<std::string> ok{"simulate", "--plant", "modes", "--profile", "poly345", "--distance", "0.1", "--time", "1"};
  for (int i = 0; i < 64; ++i) {
    ok.emplace_back("--mode");
    ok.emplace_back(std::to_string(10 + i) + ",0.01,1");
  }
  EXPECT_EQ(run_cli_argv(ok).status, 0) << "64 modes are allowed";
}

// ---- help ----------------------------------------------------------------------------------

std::set<std::string> options_in_help(const std::string& help) {
  std::set<std::string> names;
  // An option's own line starts two spaces in; its wrapped description lines further in.
  const std::regex option_line{R"(^  (?:-h,)?(--[A-Za-z][A-Za-z0-9-]*))"};
  std::size_t b = 0;
  for (std::size_t e; (e = help.find('\n', b)) != std::string::npos; b = e + 1) {
    std::smatch m;
    const std::string line = help.substr(b, e - b);
    if (std::regex_search(line, m, option_line)) names.insert(m[1]);
  }
  return names;
}

// From the option table: every option of every command is in `settle <command> --help` and
// in `settle help <command>`, with its range, and both exit 0.
TEST(CliHelp, EveryOptionOfTheTableIsInItsCommandsHelp) {
  for (const settle::app::CommandSpec& c : settle::app::commands()) {
    SCOPED_TRACE(c.name);
    const CliResult h = run_cli(c.name + " --help");
    ASSERT_EQ(h.status, 0) << h.out;
    const CliResult h2 = run_cli("help " + c.name);
    ASSERT_EQ(h2.status, 0) << h2.out;
    EXPECT_EQ(h.stdout_text, h2.stdout_text);
    const std::set<std::string> listed = options_in_help(h.stdout_text);
    std::set<std::string> names;
    for (const settle::app::OptionSpec* o : settle::app::options_of(c)) {
      EXPECT_TRUE(names.insert(o->name).second) << o->name << " declared twice for " << c.name;
      EXPECT_EQ(listed.count(o->name), 1u) << o->name << " missing from\n" << h.stdout_text;
      if (o->kind == settle::app::Kind::real || o->kind == settle::app::Kind::integer) {
        // The range as the table states it appears on the option's line.
        const std::string range = o->kind == settle::app::Kind::integer
                                      ? settle::app::format_number(o->range.lo) + ".." +
                                            settle::app::format_number(o->range.hi)
                                      : o->range.text();
        const std::string line = settle::test::help_entry(h.stdout_text, o->name);
        ASSERT_FALSE(line.empty()) << o->name;
        EXPECT_NE(line.find(range), std::string::npos) << line;
        if (!o->unit.empty()) {
          EXPECT_NE(line.find(o->unit), std::string::npos) << line;
        }
      }
    }
  }
}

// Every command's --help reads at a glance: no line over 100 columns, the options under topic
// headings (Output last), and an example to copy that works. Each example runs in a scratch
// directory holding what examples read (a tuned plan, the drive's EDS): exit 0, or, where it names
// a CAN interface this host need not have, accepted as a command line (exit 1 on the bus, never the
// refusal's exit 2).
TEST(CliHelp, EveryCommandFitsAHundredColumnsAndHasAnExampleThatRuns) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path{::testing::TempDir()} / ("settle help examples " + std::to_string(::getpid()));
  fs::create_directories(dir);
  const CliResult tuned = run_cli("tune --mode 12.566,0.03 --uncertainty 10 --distance 0.1 --time 0.5 --json");
  ASSERT_EQ(tuned.status, 0) << tuned.out;
  std::ofstream{dir / "tune.json"} << tuned.stdout_text;
  fs::copy_file(SETTLE_DRIVE_EDS, dir / "settle_drive.eds", fs::copy_options::overwrite_existing);
  const fs::path here = fs::current_path();
  fs::current_path(dir);
  for (const settle::app::CommandSpec& c : settle::app::commands()) {
    std::vector<std::string> help_args;
    std::istringstream name{c.name};
    for (std::string w; name >> w;) help_args.push_back(w);
    help_args.push_back("--help");
    const CliResult h = run_cli_argv(help_args);
    ASSERT_EQ(h.status, 0) << c.name;
    std::istringstream lines{h.stdout_text};
    for (std::string line; std::getline(lines, line);) EXPECT_LE(line.size(), 100u) << c.name << ": " << line;
    EXPECT_NE(h.stdout_text.find("\nOutput:\n"), std::string::npos) << c.name << "\n" << h.stdout_text;
    EXPECT_EQ(h.stdout_text.find("\nOPTIONS:\n"), std::string::npos) << c.name;
    const std::size_t at = h.stdout_text.find("\nExample:\n  settle " + c.name + " ");
    ASSERT_NE(at, std::string::npos) << c.name << "\n" << h.stdout_text;
    // The example as printed (continued lines joined) is the one the table holds.
    std::string printed = h.stdout_text.substr(at + 12);
    for (std::size_t k; (k = printed.find(" \\\n")) != std::string::npos;) printed.replace(k, 3, " ");
    EXPECT_EQ(settle::test::collapse_whitespace(printed).rfind(c.example, 0), 0u) << printed;
    std::vector<std::string> args;
    std::istringstream words{c.example};
    for (std::string w; words >> w;) args.push_back(w);
    ASSERT_EQ(args.front(), "settle");
    args.erase(args.begin());
    const CliResult r = run_cli_argv(args);
    const bool on_can = c.example.find("--bus vcan0") != std::string::npos;
    if (on_can) {
      EXPECT_NE(r.status, 2) << c.example << "\n" << r.out;
    } else {
      EXPECT_EQ(r.status, 0) << c.example << "\n" << r.out;
    }
  }
  fs::current_path(here);
  fs::remove_all(dir);
}

// From an independent list, written by hand: what each command accepts is exactly what its help
// lists, and each listed option is accepted (not refused as unknown).
TEST(CliHelp, HelpListsExactlyTheAcceptedOptions) {
  const std::vector<std::string> move{"--profile", "--distance", "--time",   "--vmax", "--amax", "--jmax",
                                      "--omega",   "--zeta",     "--gammas", "--y",    "--shaper", "--vtol",
                                      "--robust"};
  const std::vector<std::string> plant{"--plant",     "--mass",      "--stiffness",     "--damping",
                                       "--length",    "--modulus",   "--thickness",     "--width",
                                       "--beam-mass", "--tip-mass",  "--modes",         "--modal-damping",
                                       "--inertia",   "--belt-stiffness", "--belt-damping", "--pulley-r",
                                       "--pulley-R",  "--ratio",     "--mode"};
  const std::vector<std::string> drive{"--period-us", "--counts-per-unit", "--load-counts-per-unit", "--interp",
                                       "--drive",     "--bandwidth",       "--servo-damping"};
  auto join = [](std::initializer_list<std::vector<std::string>> parts) {
    std::set<std::string> s{"--help", "--json"};
    for (const auto& p : parts) s.insert(p.begin(), p.end());
    return s;
  };
  const std::vector<std::pair<std::string, std::set<std::string>>> expected = {
      {"plan", join({move, {"--unit", "--axes", "--sync", "--png"}})},
      {"sample", join({move, {"--unit", "--axes", "--sync", "--dt", "--plan-from", "--png"}})},
      {"simulate", join({move, plant, {"--unit", "--axes", "--sync", "--csv", "--png", "--dt", "--band", "--tail", "--sensitivity", "--halt-at", "--retarget-at"}})},
      {"reproduce", join({{"--out"}})},
      {"plant", join({plant, drive, {"--unit", "--bus", "--timing", "--node", "--heartbeat-ms", "--sync-loss-periods", "--eds", "--strict", "--load-feedback", "--log", "--duration",
                                     "--noise", "--seed"}})},
      {"stream", join({move, plant, drive,
                       {"--axes", "--sync", "--nodes", "--plan-from", "--bus", "--timing", "--scalar", "--node", "--axis-vmax", "--settle-time", "--rt-priority", "--eds", "--strict", "--load-feedback", "--pm-qos", "--heartbeat-ms",
                        "--bitrate", "--sdo-timeout-ms", "--feedback-timeout-periods", "--log", "--candump", "--feedback-log",
                        "--halt-at", "--retarget-at"}})},
      {"tune", join({{"--distance", "--time", "--vmax", "--amax", "--jmax", "--modes-from", "--mode", "--residual-max",
                      "--uncertainty", "--zeta-pm", "--png", "--verbose"}})},
      {"export", join({{"--plan-from", "--scalar", "--name", "--counts-per-unit", "--period-us"}})},
      {"identify", join({plant, drive,
                         {"--bus", "--timing", "--node", "--eds", "--strict", "--load-feedback", "--heartbeat-ms", "--sdo-timeout-ms", "--feedback-timeout-periods",
                          "--rt-priority", "--pm-qos",
                          "--candump", "--max-modes", "--distance", "--vmax", "--amax", "--jmax", "--train", "--hold", "--noise",
                          "--seed", "--png", "--unit"}})},
      {"demo", join({{"--bus", "--out", "--list"}})},
      {"drive info", join({{"--bus", "--timeout-ms", "--eds", "--strict", "--node"}})},
      {"drive read", join({{"--bus", "--timeout-ms", "--eds", "--strict", "--node", "--index", "--sub", "--type"}})},
      {"drive write", join({{"--bus", "--timeout-ms", "--eds", "--strict", "--node", "--index", "--sub", "--type", "--value"}})},
      {"drive config", join({{"--bus", "--timeout-ms", "--eds", "--strict", "--node"}})},
      {"drive nmt", join({{"--bus", "--timeout-ms", "--eds", "--strict", "--node"}})},
      {"drive scan", join({{"--bus", "--timeout-ms", "--eds", "--strict"}})},
  };
  ASSERT_EQ(expected.size(), settle::app::commands().size());
  for (const auto& [cmd, options] : expected) {
    SCOPED_TRACE(cmd);
    const CliResult h = run_cli(cmd + " --help");
    ASSERT_EQ(h.status, 0);
    EXPECT_EQ(options_in_help(h.stdout_text), options);
    for (const std::string& o : options) {
      if (o == "--help") continue;
      // Given with a value that may be wrong, an accepted option is never "unknown".
      std::vector<std::string> argv;  // "drive info" is two arguments
      for (std::size_t b = 0, e = 0; e != std::string::npos; b = e + 1) {
        e = cmd.find(' ', b);
        argv.push_back(cmd.substr(b, e == std::string::npos ? e : e - b));
      }
      argv.insert(argv.end(), {o, "1"});
      const CliResult r = run_cli_argv(argv);
      EXPECT_EQ(r.stderr_text.find("unknown option"), std::string::npos) << o << ": " << r.stderr_text;
    }
  }
}

TEST(CliHelp, ProgramHelpAndUnknownCommands) {
  const CliResult h = run_cli("--help");
  EXPECT_EQ(h.status, 0);
  for (const settle::app::CommandSpec& c : settle::app::commands()) {
    EXPECT_NE(h.stdout_text.find("  " + c.name + " "), std::string::npos) << c.name;
  }
  EXPECT_EQ(run_cli("help").status, 0);
  EXPECT_EQ(run_cli("help frobnicate").status, 2);
  EXPECT_EQ(run_cli("reproduce --help").status, 0);
}

// Issue 13: --scalar is in stream's help with its three evaluations and its default.
TEST(CliHelp, StreamHelpListsTheScalars) {
  const CliResult h = run_cli("stream --help");
  ASSERT_EQ(h.status, 0);
  const std::string line = settle::test::help_entry(h.stdout_text, "--scalar");
  ASSERT_FALSE(line.empty()) << h.stdout_text;
  EXPECT_NE(line.find("default double"), std::string::npos) << line;
  EXPECT_NE(line.find("double, float, fixed"), std::string::npos) << line;
}

// A paper scenario's `settle stream` options (plant, move, --axis-vmax), from the one table the
// demo and the end-to-end tests stream (`settle demo --list --json`).
std::vector<std::string> scenario(const std::string& id) {
  const CliResult list = run_cli("demo --list --json");
  EXPECT_EQ(list.status, 0) << list.out;
  const auto j = nlohmann::json::parse(list.stdout_text, nullptr, false);
  if (j.is_discarded()) return {};
  for (const auto& s : j.at("scenarios")) {
    if (s.at("id") != id) continue;
    std::vector<std::string> args = s.at("plant").get<std::vector<std::string>>();
    for (const auto& m : s.at("move")) args.push_back(m.get<std::string>());
    args.push_back("--axis-vmax");
    args.push_back(settle::app::format_number(s.at("axis_vmax").get<double>()));
    return args;
  }
  ADD_FAILURE() << "no scenario " << id << " in " << list.stdout_text;
  return {};
}

nlohmann::json stream_json(const std::string& scalar, const std::vector<std::string>& scenario_args) {
  std::vector<std::string> argv{"stream", "--bus", "loopback", "--scalar", scalar};
  argv.insert(argv.end(), scenario_args.begin(), scenario_args.end());
  argv.push_back("--json");
  const CliResult res = run_cli_argv(argv);
  EXPECT_EQ(res.status, 0) << res.out;
  const auto j = nlohmann::json::parse(res.stdout_text, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << res.stdout_text;
  return j.is_discarded() ? nlohmann::json::object() : j;
}

// Issue 13: `stream --scalar double|float|fixed` over the loopback bus on two paper scenarios
// (000-poly345-1.75, the beam, and 004-poly345, the belt at ~1e6 counts).
// Each run is proven against the replay of the setpoints its own evaluation produces (status ok =
// the CAN feedback matched them exactly), and agrees with the double evaluator's setpoints within
// one count and with the double run's residual within 1 %. Float and fixed really ran: each has a
// scenario whose setpoints are not bit-identical to double's, so a run that evaluated in double
// instead would not have aligned with its replay.
TEST(StreamScalar, EveryEvaluationAgreesWithDoubleOverLoopback) {
  const std::vector<std::string> beam = scenario("000-poly345-1.75");
  const std::vector<std::string> belt = scenario("004-poly345");
  struct Run {
    std::string scalar;
    const std::vector<std::string>& scenario;
    bool differs;  // its setpoints are not bit-identical to double's on this scenario
  };
  const Run runs[] = {{"double", beam, false}, {"float", beam, true}, {"fixed", beam, false}, {"fixed", belt, true}};
  for (const Run& r : runs) {
    SCOPED_TRACE(r.scalar + " " + (&r.scenario == &beam ? "000-poly345-1.75" : "004-poly345"));
    const nlohmann::json j = stream_json(r.scalar, r.scenario);
    ASSERT_TRUE(j.contains("status")) << j.dump();
    EXPECT_EQ(j.at("status"), "ok");
    EXPECT_EQ(j.at("scalar"), r.scalar);
    EXPECT_EQ(j.at("evaluation"), "ok");
    EXPECT_TRUE(j.at("aligned").get<bool>());
    EXPECT_LE(j.at("setpoints_vs_double_max_counts").get<long long>(), 1);
    EXPECT_EQ(j.at("setpoints_differing_from_double").get<long long>() > 0, r.differs);
    EXPECT_LE(j.at("residual_vs_double_percent").get<double>(), 1.0);
    EXPECT_GT(j.at("residual_double").get<double>(), 0.0);
  }
}

// Seed 004's optimised pseudo-polynomial (004-optimised): its non-integer exponents need the
// fixed-point motion's piecewise-quintic form (core::fixed::PolyMotion), which the stream's fixed
// evaluation has room for. Its residual is at the measurement's floor (under one load count), where
// a one-count setpoint difference moves it by more than 1 %: there the residuals agree within half
// a load count, the resolution of the load encoder.
TEST(StreamScalar, FixedStreamsThePseudoPolynomial) {
  const nlohmann::json j = stream_json("fixed", scenario("004-optimised"));
  ASSERT_TRUE(j.contains("status")) << j.dump();
  EXPECT_EQ(j.at("profile"), "pseudopoly");
  EXPECT_EQ(j.at("evaluation"), "ok");
  EXPECT_TRUE(j.at("aligned").get<bool>());
  EXPECT_LE(j.at("setpoints_vs_double_max_counts").get<long long>(), 1);
  EXPECT_GT(j.at("setpoints_differing_from_double").get<long long>(), 0);
  EXPECT_LT(j.at("residual_double").get<double>() * 1e6, 1.0);  // under one load count
  EXPECT_LE(j.at("residual_vs_double_load_counts").get<double>(), 0.5);
}

}  // namespace

// The int32 reach check stream and identify share: (2 |reach| + 1) x scale within 2e9, the motor's
// scale named first. Over a seeded grid against the 32-bit bound itself.
TEST(CountsReach, NamesTheScaleWhoseCountsTheMoveLeaves) {
  std::uint64_t seed = 33;
  const auto uniform = [&seed] {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(seed >> 11) / 9007199254740992.0;
  };
  for (int i = 0; i < 2000; ++i) {
    const double reach = (uniform() - 0.5) * 2e4;
    const double motor = std::pow(10.0, uniform() * 12.0 - 3.0);
    const double load = std::pow(10.0, uniform() * 12.0 - 3.0);
    const auto fits = [&](double scale) { return (2.0 * std::fabs(reach) + 1.0) * scale <= 2e9; };
    const char* who = settle::app::counts_reach_exceeded(reach, motor, load);
    const std::string expected = !fits(motor) ? "--counts-per-unit" : !fits(load) ? "--load-counts-per-unit" : "";
    EXPECT_EQ(who == nullptr ? std::string{} : std::string{who}, expected) << reach << " " << motor << " " << load;
  }
  EXPECT_EQ(settle::app::counts_reach_exceeded(999.5, 1e6, 1.0), nullptr);  // exactly 2e9 counts: fits
  EXPECT_STREQ(settle::app::counts_reach_exceeded(999.5000001, 1e6, 1.0), "--counts-per-unit");
}
