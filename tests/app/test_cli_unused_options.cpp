// SPDX-License-Identifier: Apache-2.0
// An option the move would ignore is refused (exit 2, unused_option, naming the option) exactly
// when the profile (or shaper) does not use it, in every command that takes a move. What each
// profile and shaper uses is stated here on its own, from what each one is (its paper, its
// kinematics), not read from core's registry, so that a registry line that lies fails this test.
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "refusal.hpp"
#include "run_cli.hpp"

using settle::test::Case;
using settle::test::expect_refused;
using settle::test::run_cli;

namespace {

using Options = std::map<std::string, std::string>;

struct ProfileUse {
  std::string name;
  Options base;                // a request it plans
  std::set<std::string> uses;  // the design options it reads
};

// time: every profile but fastest (which chooses the shortest). Limits: met or checked, except
// where the profile has no finite peak to keep (trapezoid: acceleration steps, no jerk;
// ramp-versine: velocity steps, neither acceleration nor jerk). The mode: the S-curves,
// ramp-versine (its Y designed for it) and fastest; its damping not the plain S-curve (undamped
// design). gammas: pseudopoly's own exponents (poly345's are fixed); y: ramp-versine's fractions;
// robust: fastest's band. vtol: no profile (the EI shapers' tolerance).
const std::vector<ProfileUse> kProfiles = {
    {"scurve", {{"--distance", "0.1"}, {"--time", "0.5"}, {"--omega", "22"}},
     {"--time", "--vmax", "--amax", "--jmax", "--omega"}},
    {"scurve-damped", {{"--distance", "0.1"}, {"--time", "0.5"}, {"--omega", "22"}},
     {"--time", "--vmax", "--amax", "--jmax", "--omega", "--zeta"}},
    {"ramp-versine", {{"--distance", "0.1"}, {"--time", "0.5"}, {"--omega", "22"}},
     {"--time", "--vmax", "--omega", "--zeta", "--y"}},
    {"pseudopoly", {{"--distance", "0.1"}, {"--time", "0.5"}, {"--gammas", "3,5,7,9"}},
     {"--time", "--vmax", "--amax", "--jmax", "--gammas"}},
    {"poly345", {{"--distance", "0.1"}, {"--time", "0.5"}}, {"--time", "--vmax", "--amax", "--jmax"}},
    {"trapezoid", {{"--distance", "0.1"}, {"--time", "0.5"}}, {"--time", "--vmax", "--amax"}},
    {"jerk-limited", {{"--distance", "0.1"}, {"--vmax", "1"}, {"--amax", "20"}, {"--jmax", "800"}},
     {"--time", "--vmax", "--amax", "--jmax"}},
    {"fastest", {{"--distance", "0.1"}, {"--vmax", "1"}, {"--amax", "20"}, {"--jmax", "800"}, {"--omega", "22"}},
     {"--vmax", "--amax", "--jmax", "--omega", "--zeta", "--robust"}},
};

// Every design option, with a value each profile that uses it accepts.
const Options kValues = {{"--time", "0.5"},        {"--vmax", "10"},          {"--amax", "1000"},
                         {"--jmax", "1e6"},        {"--omega", "22"},         {"--zeta", "0.05"},
                         {"--gammas", "3,5,7,9"},  {"--y", "0.2,0.5,0.3"},    {"--robust", "10"},
                         {"--vtol", "0.1"}};

std::string args_of(const std::string& command, const std::string& profile, Options o) {
  std::string s = command + " --profile " + profile;
  for (const auto& [k, v] : o) s += " " + k + " " + v;
  return s;
}

// The JSON a command prints, and whether it refused an option as unused.
nlohmann::json json_of(const std::string& args) {
  const auto r = run_cli(args + " --json");
  const auto j = nlohmann::json::parse(r.stdout_text, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << args << "\n" << r.out;
  return j;
}
bool refused_as_unused(const nlohmann::json& j) { return j.value("error", "") == "unused_option"; }

// The request of profile p with option o added: the base (the option's own value replacing the
// base's), without the mode when o is --y (ramp-versine designs for no mode with its fractions),
// and with --omega when o is --zeta and the profile designs for a mode (a damping ratio belongs to one).
Options with_option(const ProfileUse& p, const std::string& o) {
  Options req = p.base;
  if (o == "--y") req.erase("--omega");
  if (o == "--zeta" && p.uses.count("--omega") != 0) req["--omega"] = "22";
  req[o] = kValues.at(o);
  return req;
}

}  // namespace

TEST(CliUnusedOptions, EveryProfileRefusesExactlyTheOptionsItDoesNotUse) {
  for (const ProfileUse& p : kProfiles) {
    ASSERT_EQ(json_of(args_of("plan", p.name, p.base)).value("status", ""), "ok") << p.name;
    for (const auto& [o, value] : kValues) {
      const std::string args = args_of("plan", p.name, with_option(p, o));
      SCOPED_TRACE(args);
      if (p.uses.count(o) != 0) {
        const auto j = json_of(args);
        EXPECT_FALSE(refused_as_unused(j)) << j.dump();
        EXPECT_EQ(j.value("status", ""), "ok") << j.dump();  // each value above is one it can plan with
      } else {
        expect_refused({args, o, "unused_option"});
        // The message names the profile and the ones that use the option.
        const std::string msg = json_of(args).value("message", "");
        EXPECT_NE(msg.find("profile " + p.name), std::string::npos) << msg;
        for (const ProfileUse& q : kProfiles) {
          if (q.uses.count(o) != 0) {
            EXPECT_NE(msg.find(q.name), std::string::npos) << q.name << ": " << msg;
          }
        }
      }
    }
  }
}

// A shaper designs for the mode (omega, zeta); the EI shapers also read their tolerance. On a
// profile that reads none of the three (poly345), each is refused exactly when the shaper does not.
TEST(CliUnusedOptions, EveryShaperRefusesExactlyTheOptionsItDoesNotUse) {
  const std::map<std::string, std::set<std::string>> shapers = {
      {"none", {}},
      {"zv", {"--omega", "--zeta"}},
      {"zvd", {"--omega", "--zeta"}},
      {"zvdd", {"--omega", "--zeta"}},
      {"ei", {"--omega", "--zeta", "--vtol"}},
      {"ei2", {"--omega", "--zeta", "--vtol"}},
      {"ei3", {"--omega", "--zeta", "--vtol"}},
  };
  for (const auto& [shaper, uses] : shapers) {
    for (const std::string o : {"--omega", "--zeta", "--vtol"}) {
      Options req = {{"--distance", "0.1"}, {"--time", "0.5"}, {"--shaper", shaper}, {o, kValues.at(o)}};
      // The mode a shaper needs (omega) is given unless omega is the option refused.
      if (o != "--omega" && !uses.empty()) req["--omega"] = "22";
      if (o == "--zeta") req["--omega"] = "22";
      const std::string args = args_of("plan", "poly345", req);
      SCOPED_TRACE(args);
      if (uses.count(o) != 0) {
        EXPECT_EQ(json_of(args).value("status", ""), "ok");
      } else {
        expect_refused({args, o == "--zeta" && shaper == "none" ? "--omega" : o, "unused_option"});
      }
    }
  }
}

// ramp-versine with its fractions given designs for no mode: --omega and --zeta are then refused.
TEST(CliUnusedOptions, RampVersineWithItsFractionsRefusesTheMode) {
  const std::string base = "plan --profile ramp-versine --distance 0.1 --time 0.5 --y 0.2,0.5,0.3";
  EXPECT_EQ(json_of(base).value("status", ""), "ok");
  expect_refused({base + " --omega 22", "--omega", "unused_option"});
  expect_refused({base + " --omega 22 --zeta 0.1", "--omega", "unused_option"});
  // A shaper designs for the mode: then it is used.
  EXPECT_EQ(json_of(base + " --omega 22 --zeta 0.1 --shaper zv").value("status", ""), "ok");
}

// A zeta without an omega would be dropped where there is no mode to pair it with (plan, sample);
// simulate and stream pair it with the plant's fundamental when the move designs for a mode.
TEST(CliUnusedOptions, ZetaWithoutOmegaIsRefusedWhereNoModeTakesIt) {
  expect_refused({"plan --profile scurve-damped --distance 0.1 --time 0.5 --zeta 0.1", "--zeta", "unused_option"});
  expect_refused({"sample --profile scurve-damped --distance 0.1 --time 0.5 --zeta 0.1 --dt 0.01", "--zeta",
                  "unused_option"});
  expect_refused({"plan --axes 2 --profile scurve-damped --distance 0.1,0.2 --time 0.5 --zeta 0.1,0.1", "--zeta",
                  "unused_option"});
  const auto sim = json_of("simulate --plant sdof --profile scurve-damped --distance 0.1 --time 0.5 --zeta 0.05");
  EXPECT_EQ(sim.value("status", ""), "ok") << sim.dump();
  EXPECT_EQ(sim.value("designed_zeta", -1.0), 0.05);
  // A move that designs for no mode: the zeta would pair with nothing (a halt takes the plant's).
  expect_refused({"simulate --plant sdof --profile poly345 --distance 0.1 --time 0.5 --zeta 0.05 --halt-at 0.2",
                  "--zeta", "unused_option"});
}

// Every command that takes a move refuses the same way, before anything is planned or sent; the
// case the refusal was made for first (scurve given a damping ratio it ignores, on simulate).
TEST(CliUnusedOptions, EveryMoveCommandRefuses) {
  const std::string move = " --profile scurve --distance 0.1 --time 0.5 --omega 22 --zeta 0.1";
  for (const std::string c : {"plan", "sample --dt 0.01", "simulate --plant modes --mode 22,0.1,1",
                              "stream --bus loopback --plant sdof"}) {
    expect_refused({c + move, "--zeta", "unused_option"});
  }
  expect_refused({"simulate --plant modes --mode 22,0.1,1 --profile poly345 --distance 0.1 --time 0.5 --gammas 3,5,7",
                  "--gammas", "unused_option"});
  expect_refused({"stream --bus loopback --plant sdof --profile trapezoid --distance 0.1 --time 0.5 --jmax 1e6",
                  "--jmax", "unused_option"});
}

// What a command uses besides the planner: a change mid-way keeps the design mode at rest (its
// zeta too), and with --axes the coordination shapes each axis for its mode when the profile
// designs for none. The plain S-curve's zeta on --axes is still refused (axis 1's move ignores it).
TEST(CliUnusedOptions, WhatTheCommandUsesItselfIsNotRefused) {
  const auto halt = json_of(
      "simulate --plant sdof --profile scurve --distance 0.1 --time 0.5 --omega 28.28 --zeta 0.159 --halt-at 0.2");
  EXPECT_EQ(halt.value("status", ""), "ok") << halt.dump();
  const auto axes = json_of(
      "plan --axes 2 --profile jerk-limited --distance 0.1,0.2 --vmax 1 --amax 20 --jmax 800 --omega 22,30 "
      "--zeta 0.05,0.1");
  EXPECT_EQ(axes.value("status", ""), "ok") << axes.dump();
  expect_refused({"plan --axes 2 --profile scurve --distance 0.1,0.2 --time 0.5 --omega 22,30 --zeta 0.05,0.1",
                  "--zeta", "unused_option"});
  expect_refused({"plan --axes 2 --profile jerk-limited --distance 0.1,0.2 --vmax 1 --amax 20 --jmax 800 "
                  "--gammas 3,5,7",
                  "--gammas", "unused_option"});
}

// The design of the move that simulate reports names the zeta only when the move uses it: the
// plain S-curve designed for the plant's fundamental reports its omega alone.
TEST(CliUnusedOptions, SimulateReportsTheZetaOnlyWhenTheMoveUsesIt) {
  const auto plain = json_of("simulate --plant sdof --profile scurve --distance 0.1 --time 0.5");
  EXPECT_TRUE(plain.contains("designed_omega")) << plain.dump();
  EXPECT_FALSE(plain.contains("designed_zeta")) << plain.dump();
  const auto text = run_cli("simulate --plant sdof --profile scurve --distance 0.1 --time 0.5");
  EXPECT_EQ(text.stdout_text.find(", zeta"), std::string::npos) << text.stdout_text;
  const auto damped = json_of("simulate --plant sdof --profile scurve-damped --distance 0.1 --time 0.5");
  EXPECT_GT(damped.value("designed_zeta", 0.0), 0.1) << damped.dump();
}

// --mode has one arity in every command: OMEGA,ZETA[,GAIN], the gain 1 when left out (tune's and
// the plant's alike): the plant given two numbers is the one given the gain 1.
TEST(CliModeArity, ThePlantsModeTakesTheGainAsTunesDoes) {
  const std::string move = " --profile scurve-damped --distance 0.1 --time 0.5 --omega 22 --zeta 0.1";
  const auto two = json_of("simulate --plant modes --mode 22,0.1" + move);
  const auto three = json_of("simulate --plant modes --mode 22,0.1,1" + move);
  ASSERT_EQ(two.value("status", ""), "ok") << two.dump();
  EXPECT_EQ(two.at("modes"), three.at("modes"));
  EXPECT_EQ(two.at("residual_amplitude"), three.at("residual_amplitude"));
  const auto other = json_of("simulate --plant modes --mode 22,0.1,2" + move);
  EXPECT_NE(two.at("modes"), other.at("modes"));
}
