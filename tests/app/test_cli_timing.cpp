// SPDX-License-Identifier: Apache-2.0
// Issue 37 item 2 and issue 33 ("defaults stated once"): the timeouts' --timing preset (sim, the
// default: the simulated drive and the master on one loaded, non-real-time host; drive: a real
// drive on a real-time bus), each option given overriding its preset value; every default read
// from the option table (no call site repeats one); and the demo passing no timing options.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "options.hpp"
#include "run_cli.hpp"
#include "settle/runtime/servo_loop.hpp"
#include "settle/testbed/stream.hpp"

namespace {

using settle::app::ParsedArgs;
using settle::test::CliResult;
using settle::test::run_cli_argv;

ParsedArgs parsed(const std::string& command, std::vector<std::string> args) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  ParsedArgs out;
  settle::app::RequestError err;
  const settle::app::CommandSpec* c = settle::app::find_command(command);
  EXPECT_NE(c, nullptr);
  EXPECT_EQ(settle::app::parse_command(*c, static_cast<int>(argv.size()), argv.data(), out, err),
            settle::app::ParseOutcome::ok)
      << err.message;
  return out;
}

struct Loop {
  long long heartbeat, sdo, feedback;
};
Loop loop_of(const ParsedArgs& a) {
  return {a.integer("--heartbeat-ms"), a.integer("--sdo-timeout-ms"), a.integer("--feedback-timeout-periods")};
}

TEST(Timing, SimIsTheDefaultAndDriveTheTightPreset) {
  for (const char* cmd : {"stream", "identify"}) {
    SCOPED_TRACE(cmd);
    const Loop sim = loop_of(parsed(cmd, {}));
    EXPECT_EQ(sim.heartbeat, 2000);
    EXPECT_EQ(sim.sdo, 5000);
    EXPECT_EQ(sim.feedback, 250);
    EXPECT_EQ(loop_of(parsed(cmd, {"--timing", "sim"})).feedback, 250);
    const Loop drive = loop_of(parsed(cmd, {"--timing", "drive"}));
    EXPECT_EQ(drive.heartbeat, 500);
    EXPECT_EQ(drive.sdo, 1000);
    EXPECT_EQ(drive.feedback, 10);
  }
  EXPECT_EQ(parsed("plant", {}).integer("--sync-loss-periods"), 250);
  EXPECT_EQ(parsed("plant", {"--timing", "drive"}).integer("--sync-loss-periods"), 3);
  // The drive's heartbeat producer period is not a timeout: the same under both presets.
  EXPECT_EQ(parsed("plant", {}).integer("--heartbeat-ms"), 100);
  EXPECT_EQ(parsed("plant", {"--timing", "drive"}).integer("--heartbeat-ms"), 100);
}

TEST(Timing, AnOptionGivenOverridesItsPresetValue) {
  const Loop a = loop_of(parsed("stream", {"--timing", "drive", "--heartbeat-ms", "700"}));
  EXPECT_EQ(a.heartbeat, 700);
  EXPECT_EQ(a.feedback, 10);
  const Loop b = loop_of(parsed("identify", {"--feedback-timeout-periods", "42"}));
  EXPECT_EQ(b.feedback, 42);
  EXPECT_EQ(b.heartbeat, 2000);
  EXPECT_EQ(parsed("plant", {"--sync-loss-periods", "7"}).integer("--sync-loss-periods"), 7);
}

// The drive preset is the library's own defaults (the loop's and the stream spec's): the tight
// values a real drive is configured with, stated in the table and checked against the code.
TEST(Timing, TheDrivePresetIsTheLibrarysDefaults) {
  const Loop drive = loop_of(parsed("stream", {"--timing", "drive"}));
  const settle::testbed::StreamSpec spec{};
  EXPECT_EQ(drive.feedback, settle::runtime::kDefaultFeedbackTimeoutPeriods);
  EXPECT_EQ(drive.heartbeat, spec.heartbeat_ms);
  EXPECT_EQ(drive.sdo * 1000, spec.sdo_timeout_us);
}

// Every default the table states as a number is what a call site reads when the option is not
// given: the table is the one place (a call site that still passed a fallback of its own would
// not be reading this; the values used are checked end to end by the JSON test below).
TEST(Timing, EveryNumericTableDefaultIsWhatTheAccessorReturns) {
  for (const settle::app::CommandSpec& c : settle::app::commands()) {
    if (!c.positional_choices.empty()) continue;  // reproduce: needs its experiment
    SCOPED_TRACE(c.name);
    std::vector<std::string> words;
    const ParsedArgs a = parsed(c.name, words);
    for (const settle::app::OptionSpec* o : settle::app::options_of(c)) {
      double v = 0.0;
      if (o->kind == settle::app::Kind::flag || !settle::app::parse_real(o->def, v)) continue;
      SCOPED_TRACE(o->name);
      EXPECT_EQ(a.real_or_default(o->name), v);
      if (o->kind == settle::app::Kind::integer) {
        EXPECT_EQ(a.integer(o->name), static_cast<long long>(v));
      }
    }
  }
}

TEST(Timing, HelpShowsBothPresetsAndWhatEachSets) {
  const CliResult h = run_cli_argv({"stream", "--help"});
  ASSERT_EQ(h.status, 0);
  for (const char* want :
       {"default 2000 (--timing drive: 500)", "default 5000 (--timing drive: 1000)",
        "default 250 (--timing drive: 10)", "--heartbeat-ms 2000, --sdo-timeout-ms 5000, --feedback-timeout-periods 250",
        "--heartbeat-ms 500, --sdo-timeout-ms 1000, --feedback-timeout-periods 10", "default sim"}) {
    EXPECT_NE(settle::test::collapse_whitespace(h.stdout_text).find(want), std::string::npos) << want << "\n"
                                                                                              << h.stdout_text;
  }
  const CliResult p = run_cli_argv({"plant", "--help"});
  const std::string plant_help = settle::test::collapse_whitespace(p.stdout_text);
  EXPECT_NE(plant_help.find("default 250 (--timing drive: 3)"), std::string::npos) << p.stdout_text;
  EXPECT_NE(plant_help.find("(--sync-loss-periods 250)"), std::string::npos) << p.stdout_text;
}

// What settle stream used, from its JSON: the preset's values, or the option given.
TEST(Timing, StreamReportsTheTimeoutsItUsed) {
  const std::vector<std::string> base{"stream", "--bus", "loopback", "--profile", "poly345", "--distance", "0.01",
                                      "--time", "0.2", "--settle-time", "0.1", "--json"};
  const auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    const CliResult r = run_cli_argv(a);
    EXPECT_EQ(r.status, 0) << r.out;
    const auto j = nlohmann::json::parse(r.stdout_text, nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << r.out;
    return j.is_discarded() ? nlohmann::json::object() : j;
  };
  const auto sim = run({});
  EXPECT_EQ(sim.value("heartbeat_ms", 0), 2000);
  EXPECT_EQ(sim.value("sdo_timeout_ms", 0), 5000);
  EXPECT_EQ(sim.value("feedback_timeout_periods", 0), 250);
  const auto drive = run({"--timing", "drive"});
  EXPECT_EQ(drive.value("heartbeat_ms", 0), 500);
  EXPECT_EQ(drive.value("sdo_timeout_ms", 0), 1000);
  EXPECT_EQ(drive.value("feedback_timeout_periods", 0), 10);
  const auto both = run({"--timing", "drive", "--feedback-timeout-periods", "42"});
  EXPECT_EQ(both.value("heartbeat_ms", 0), 500);
  EXPECT_EQ(both.value("feedback_timeout_periods", 0), 42);
}

// The demo runs settle plant, stream and identify with their defaults: it passes none of the
// timing options (it used to add the tolerant values without saying so).
TEST(Timing, TheDemoPassesNoHiddenTimingOptions) {
  for (const char* file : {"app/demo.cpp", "app/paper_scenarios.cpp", "app/cmd_demo.cpp"}) {
    std::ifstream f{std::string{SETTLE_SOURCE_DIR} + "/" + file};
    ASSERT_TRUE(f) << file;
    std::stringstream ss;
    ss << f.rdbuf();
    const std::string text = ss.str();
    for (const char* option : {"\"--heartbeat-ms\"", "\"--sync-loss-periods\"", "\"--feedback-timeout-periods\"",
                               "\"--sdo-timeout-ms\"", "\"--timing\"", "kTolerant"}) {
      EXPECT_EQ(text.find(option), std::string::npos) << file << " passes " << option;
    }
  }
}

}  // namespace
