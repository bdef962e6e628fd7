// SPDX-License-Identifier: Apache-2.0
// settle simulate --halt-at / --retarget-at (issue 17): the change's residual measured offline by
// the simulator's own exact stepping (not core's formulas), the blend's end where it should be,
// and every bad value refused with exit 2 naming the option and its range.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.hpp"

namespace {

using settle::test::CliResult;
using settle::test::run_cli;

// The sdof plant's own mode is what simulate designs for by default (omega 28.28, zeta 0.159).
const std::string kMove = "simulate --plant sdof --profile scurve --distance 0.1 --time 0.5 ";

nlohmann::json run_json(const std::string& args) {
  const CliResult r = run_cli(args + " --json");
  EXPECT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.stdout_text, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.stdout_text;
  return j;
}

TEST(CliOnline, SimulateHaltEndsAtRestWithoutResidualOnTheDesignMode) {
  for (const char* at : {"0.05", "0.2", "0.33", "0.49"}) {
    SCOPED_TRACE(at);
    const auto j = run_json(kMove + "--halt-at " + at);
    EXPECT_EQ(j.at("online").at("kind"), "halt");
    EXPECT_DOUBLE_EQ(j.at("online").at("at").get<double>(), std::stod(at));
    EXPECT_GT(j.at("online").at("blend_duration").get<double>(), 0.0);
    EXPECT_LE(j.at("residual_amplitude").get<double>(), 1e-9 * 0.1);
    EXPECT_GT(j.at("online").at("end_position").get<double>(), 0.0);
  }
}

TEST(CliOnline, TheResidualAfterAHaltIsMeasuredNotAssumed) {
  // The same halt on a plant whose mode is not the one the halt was designed for rings.
  const auto j = run_json(kMove + "--omega 20 --halt-at 0.2");
  EXPECT_GT(j.at("residual_amplitude").get<double>(), 1e-5);
}

TEST(CliOnline, SimulateRetargetEndsOnTheNewDistanceAtRest) {
  const auto j = run_json(kMove + "--retarget-at 0.2:0.03");
  EXPECT_EQ(j.at("online").at("kind"), "retarget");
  EXPECT_NEAR(j.at("online").at("end_position").get<double>(), 0.03, 1e-12);
  EXPECT_LE(j.at("residual_amplitude").get<double>(), 1e-9 * 0.1);
  // The text output says the same.
  const CliResult t = run_cli(kMove + "--retarget-at 0.2:-0.05");
  EXPECT_EQ(t.status, 0) << t.out;
  EXPECT_NE(t.stdout_text.find("retarget           at 0.2 s"), std::string::npos) << t.stdout_text;
}

void expect_refused(const std::string& args, const std::string& param, const std::string& code) {
  SCOPED_TRACE(args);
  const CliResult text = run_cli(args);
  EXPECT_EQ(text.status, 2) << text.out;
  EXPECT_TRUE(text.stdout_text.empty()) << text.stdout_text;
  EXPECT_NE(text.stderr_text.find(param + ":"), std::string::npos) << text.stderr_text;
  const CliResult json = run_cli(args + " --json");
  EXPECT_EQ(json.status, 2) << json.out;
  const auto j = nlohmann::json::parse(json.stdout_text, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << json.stdout_text;
  EXPECT_EQ(j.at("parameter"), param);
  if (!code.empty()) {
    EXPECT_EQ(j.at("error"), code);
  }
}

TEST(CliOnline, BadChangesExitTwoNamingTheOptionAndItsRange) {
  expect_refused(kMove + "--halt-at 0.7", "--halt-at", "out_of_range");  // after the move's 0.5 s
  expect_refused(kMove + "--halt-at -1", "--halt-at", "out_of_range");
  expect_refused(kMove + "--halt-at nan", "--halt-at", "");
  expect_refused(kMove + "--retarget-at 0.2", "--retarget-at", "bad_number");
  expect_refused(kMove + "--retarget-at 0.2:x", "--retarget-at", "bad_number");
  expect_refused(kMove + "--retarget-at 0.2:inf", "--retarget-at", "non_finite_input");
  expect_refused(kMove + "--retarget-at 0.2:2e6", "--retarget-at", "out_of_range");
  expect_refused(kMove + "--retarget-at 0.6:0.1", "--retarget-at", "out_of_range");
  expect_refused(kMove + "--halt-at 0.2 --retarget-at 0.2:0.1", "--retarget-at", "conflicting_options");
  // A velocity step (ramp-versine) has no acceleration a blend could continue.
  expect_refused("simulate --plant sdof --profile ramp-versine --distance 0.1 --time 0.5 --halt-at 0.2", "--halt-at",
                 "unsupported_request");
}

TEST(CliOnline, ATrapezoidHaltsWithTheDocumentedJerkLimit) {
  const auto j = run_json("simulate --plant sdof --profile trapezoid --shaper zvd --distance 0.1 --time 0.5 "
                          "--halt-at 0.2");
  EXPECT_LE(j.at("residual_amplitude").get<double>(), 1e-9 * 0.1);
}

}  // namespace

namespace {

// The same changes streamed by the servo loop to the simulated drive (loopback, virtual time): the
// loop's halt()/retarget() + service(), switched in at T, every setpoint applied once in order
// (the feedback aligns with the offline replay of the changed setpoints), and the continuous
// reference of the changed command at rest.
// The zeta is the change's: the plain S-curve does not read it (refused without a change).
const std::string kStreamPlain = "stream --bus loopback --plant sdof --profile scurve --distance 0.1 --time 0.5 "
                                 "--omega 28.284271247461902 ";
const std::string kStreamMove = kStreamPlain + "--zeta 0.15909902576697318 ";

TEST(CliOnline, StreamHaltAndRetargetAreSwitchedInByTheLoop) {
  const auto plain = run_json(kStreamPlain);
  for (const char* change : {"--halt-at 0.2", "--retarget-at 0.2:0.03", "--halt-at 0.0004"}) {
    SCOPED_TRACE(change);
    const auto j = run_json(kStreamMove + change);
    EXPECT_EQ(j.at("outcome"), "completed");
    EXPECT_TRUE(j.at("aligned").get<bool>());
    EXPECT_NE(j.at("setpoints").get<int>(), plain.at("setpoints").get<int>());
    EXPECT_EQ(j.at("step_guard_trips").get<int>(), 0);
    EXPECT_LE(j.at("residual_continuous").get<double>(), 1e-9 * 0.1);
  }
  expect_refused(kStreamMove + "--halt-at 0.9", "--halt-at", "out_of_range");
}

// In float and fixed point the loop streams the blend in its own scalar: the replay of those
// setpoints (the move's and then the blend's, as the evaluation gives them) aligns with the CAN
// feedback, and they stay within a count of the double evaluation's.
TEST(CliOnline, StreamChangesInFloatAndFixedPointToo) {
  for (const char* scalar : {"float", "fixed"}) {
    for (const char* change : {"--halt-at 0.2", "--retarget-at 0.2:0.03"}) {
      SCOPED_TRACE(std::string{scalar} + " " + change);
      const auto j = run_json(kStreamMove + change + " --scalar " + scalar);
      EXPECT_EQ(j.at("outcome"), "completed");
      EXPECT_TRUE(j.at("aligned").get<bool>());
      EXPECT_EQ(j.at("step_guard_trips").get<int>(), 0);
      EXPECT_LE(j.at("setpoints_vs_double_max_counts").get<int>(), 1);
      EXPECT_LE(j.at("residual_continuous").get<double>(), 1e-9 * 0.1);
    }
  }
}

}  // namespace
