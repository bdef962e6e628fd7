// SPDX-License-Identifier: Apache-2.0
// settle tune and --plan-from as a user meets them (issue 15): the tuned plan is printed as
// `settle plan --json` prints a plan, with its band and worst residual; it streams over the
// loopback bus with exactly the setpoints the plan evaluates to; and every bad input is refused
// naming its option.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "refusal.hpp"
#include "run_cli.hpp"
#include "scratch.hpp"

namespace {

using settle::test::Case;
using settle::test::CliResult;
using settle::test::expect_refused;
using settle::test::run_cli;
using Json = nlohmann::json;
namespace fs = std::filesystem;

// The files these tests write, in the process's scratch directory (removed at exit).
const fs::path& scratch() { return settle::test::scratch_dir(); }

std::string write(const std::string& name, const std::string& text) { return settle::test::write_scratch(name, text); }

// What `settle identify --json` prints (issue 15): two modes with their intervals.
const std::string kIdentified = R"({"status":"ok","modes":[
  {"omega":12.566,"zeta":0.03,"gain":1.0,"omega_ci":[12.2,12.9],"zeta_ci":[0.02,0.045]},
  {"omega":44.0,"zeta":0.02,"gain":0.4,"omega_ci":[43.1,45.3],"zeta_ci":[0.012,0.03]}],
  "excitation":{"distance":0.01},"fit":{"order":4,"rms_residual":0.001}})";

const std::string kMove = " --distance 0.1 --vmax 0.5 --amax 5 --jmax 200";

Json run_json(const std::string& args) {
  const CliResult r = run_cli(args + " --json");
  EXPECT_EQ(r.status, 0) << args << "\n" << r.out;
  const Json j = Json::parse(r.stdout_text, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.stdout_text;
  return j;
}

TEST(CliTune, TheChosenPlanIsPrintedAsPlanPrintsItWithItsBand) {
  const std::string file = write("identified.json", kIdentified);
  const Json j = run_json("tune --modes-from " + file + kMove);
  ASSERT_EQ(j.at("status"), "ok");
  // Every key of `settle plan --json`, in its order, then the tuner's own.
  const Json plan = run_json("plan --profile poly345 --distance 0.1 --time 1");
  std::vector<std::string> plan_keys, tune_keys;
  for (auto it = plan.begin(); it != plan.end(); ++it) plan_keys.push_back(it.key());
  for (auto it = j.begin(); it != j.end(); ++it) tune_keys.push_back(it.key());
  for (const std::string& k : plan_keys) EXPECT_TRUE(j.contains(k)) << k;
  for (const char* k : {"robust_band", "worst_residual", "residual_max", "candidate", "request", "alternatives"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  // The band is the identified intervals, sorted by omega, and the worst is within the bound.
  const Json& modes = j.at("robust_band").at("modes");
  ASSERT_EQ(modes.size(), 2u);
  EXPECT_EQ(j.at("robust_band").at("uncertainty"), "ci");
  EXPECT_EQ(modes[0].at("omega_band"), Json::parse("[12.2,12.9]"));
  EXPECT_EQ(modes[1].at("zeta_band"), Json::parse("[0.012,0.03]"));
  EXPECT_LE(j.at("worst_residual").get<double>(), 0.05);
  EXPECT_EQ(j.at("residual_max"), 0.05);
  // Peaks within the limits, and every faster alternative was checked and fails.
  EXPECT_LE(j.at("peaks").at("velocity").get<double>(), 0.5 * (1 + 1e-9));
  EXPECT_LE(j.at("peaks").at("acceleration").get<double>(), 5.0 * (1 + 1e-9));
  EXPECT_LE(j.at("peaks").at("jerk").get<double>(), 200.0 * (1 + 1e-9));
  bool seen_chosen = false;
  for (const Json& a : j.at("alternatives")) {
    if (a.at("chosen") == true) {
      seen_chosen = true;
      EXPECT_DOUBLE_EQ(a.at("duration").get<double>(), j.at("duration").get<double>());
      continue;
    }
    if (!seen_chosen && a.at("planned") == true) {
      EXPECT_TRUE(a.at("evaluated").get<bool>()) << a;
      EXPECT_FALSE(a.at("meets").get<bool>()) << a;
      EXPECT_GT(a.at("worst_residual").get<double>(), 0.05) << a;
      EXPECT_LE(a.at("duration").get<double>(), j.at("duration").get<double>()) << a;
    }
  }
  EXPECT_TRUE(seen_chosen);
}

// With one mode, every family is something `settle plan` can be asked for directly: the profile
// and shaper designed at the family's design point (EI with --vtol = --residual-max). The tuned plan
// must then be exactly what `settle plan --json` prints for that request.
TEST(CliTune, AOneModePlanIsExactlyWhatPlanPrintsForItsDesign) {
  for (const std::string& args : {"--mode 12.566,0.03 --uncertainty 10" + kMove,
                                   std::string{"--mode 30,0.02 --uncertainty 10 --distance 0.2 --time 0.4"},
                                   std::string{"--mode 20,0.05 --uncertainty 25 --distance -0.05 --vmax 0.3 --amax 2"},
                                   std::string{"--mode 9,0.01 --uncertainty 5 --distance 0.3 --time 0.5 --residual-max 0.02"}}) {
    SCOPED_TRACE(args);
    const Json t = run_json("tune " + args);
    const Json& rq = t.at("request");
    const Json& family = t.at("candidate");
    std::string plan = "plan --profile " + rq.at("profile").get<std::string>();
    const std::string shaper = family.at("shaper").get<std::string>();
    // What that move uses (plan refuses the rest): the plain S-curve reads no zeta, a shaper does;
    // only the EI shapers read --vtol.
    const bool zeta_used = rq.at("profile") != "scurve" || shaper != "none";
    ASSERT_EQ(rq.at("modes").size(), 1u);  // one mode, in the request's one list of modes
    const Json& mode = rq.at("modes")[0];
    for (const char* k : {"distance", "time", "vmax", "amax", "jmax", "omega", "zeta"}) {
      const bool of_mode = std::string{k} == "omega" || std::string{k} == "zeta";
      const Json& from = of_mode ? mode : rq;
      if (from.contains(k) && (std::string{k} != "zeta" || zeta_used)) {
        std::ostringstream v;
        v.precision(17);
        v << from.at(k).get<double>();
        plan += std::string{" --"} + k + " " + v.str();
      }
    }
    plan += " --shaper " + family.at("shaper").get<std::string>();
    if (shaper != "none") {
      // The shaper was designed at the family's design point, the same as the profile's.
      EXPECT_EQ(family.at("design_modes")[0].at("omega"), mode.at("omega"));
    }
    if (shaper.rfind("ei", 0) == 0) {
      std::ostringstream v;
      v.precision(17);
      v << t.at("residual_max").get<double>();
      plan += " --vtol " + v.str();
    }
    const Json p = run_json(plan);
    for (auto it = p.begin(); it != p.end(); ++it) {
      // The request is each file's own: a tuned plan's names its shaper in "candidate".
      if (it.key() != "request") {
        EXPECT_EQ(t.at(it.key()), it.value()) << it.key();
      }
    }
  }
}

TEST(CliTune, HereAWiderBandOrATighterBoundCostsTime) {
  const double base = run_json("tune --mode 12.566,0.03 --uncertainty 5" + kMove).at("duration").get<double>();
  const double wider = run_json("tune --mode 12.566,0.03 --uncertainty +-20" + kMove).at("duration").get<double>();
  const double tighter =
      run_json("tune --mode 12.566,0.03 --uncertainty 5 --residual-max 0.01" + kMove).at("duration").get<double>();
  EXPECT_GE(wider, base);
  EXPECT_GE(tighter, base);
  const Json j = run_json("tune --mode 12.566,0.03 --uncertainty 20" + kMove);
  EXPECT_EQ(j.at("robust_band").at("uncertainty"), "+-20%");
  EXPECT_NEAR(j.at("robust_band").at("modes")[0].at("omega_band")[0].get<double>(), 12.566 * 0.8, 1e-12);
  EXPECT_NEAR(j.at("robust_band").at("modes")[0].at("zeta_band")[1].get<double>(), 0.04, 1e-12);
}

TEST(CliTune, TextOutputNamesTheChoiceAndItsWorstResidual) {
  const CliResult r = run_cli("tune --mode 30,0.02 --uncertainty 10 --distance 0.2 --time 0.4");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.stdout_text.find("chosen"), std::string::npos);
  EXPECT_NE(r.stdout_text.find("worst"), std::string::npos);
  EXPECT_NE(r.stdout_text.find("alternatives"), std::string::npos);
}

// The text report lists the alternatives whose residual was checked and counts the others in one
// line; --verbose lists every one. Both are held against the JSON's list of the same run.
TEST(CliTune, TextListsTheCheckedAlternativesAndVerboseListsEveryOne) {
  const std::string cmd = "tune --mode 12.566,0.03 --uncertainty 10 --distance 0.1 --time 0.5";
  const Json j = run_json(cmd);
  std::size_t checked = 0, unchecked = 0, unplanned = 0;
  for (const Json& a : j.at("alternatives")) {
    if (!a.at("planned").get<bool>()) {
      ++unplanned;
    } else if (!a.at("evaluated").get<bool>()) {
      ++unchecked;
    } else {
      ++checked;
    }
  }
  ASSERT_GT(unchecked, 0u);
  ASSERT_GT(unplanned, 0u);
  const auto lines_in = [](const std::string& text) {
    std::vector<std::string> out;
    std::stringstream ss{text};
    bool in = false;
    for (std::string l; std::getline(ss, l);) {
      if (l == "alternatives") {
        in = true;
      } else if (in) {
        out.push_back(l);
      }
    }
    return out;
  };
  const CliResult brief = run_cli(cmd);
  ASSERT_EQ(brief.status, 0) << brief.out;
  const std::vector<std::string> b = lines_in(brief.stdout_text);
  ASSERT_EQ(b.size(), checked + 1) << brief.stdout_text;
  for (std::size_t i = 0; i + 1 < b.size(); ++i) EXPECT_EQ(b[i].find("not "), std::string::npos) << b[i];
  EXPECT_EQ(b.back(), "  (" + std::to_string(unchecked) + " more not checked: slower than the chosen plan; " +
                          std::to_string(unplanned) + " not planned; --verbose lists them)");
  const CliResult all = run_cli(cmd + " --verbose");
  ASSERT_EQ(all.status, 0) << all.out;
  const std::vector<std::string> v = lines_in(all.stdout_text);
  ASSERT_EQ(v.size(), checked + unchecked + unplanned) << all.stdout_text;
  std::size_t said_unchecked = 0, said_unplanned = 0;
  for (const std::string& l : v) {
    said_unchecked += l.find("not checked (slower than the chosen plan)") != std::string::npos ? 1U : 0U;
    said_unplanned += l.find("not planned (") != std::string::npos ? 1U : 0U;
  }
  EXPECT_EQ(said_unchecked, unchecked);
  EXPECT_EQ(said_unplanned, unplanned);
}

// The tick log of `settle stream --log`: target counts of the ticks during which the loop was moving.
std::vector<long long> moving_targets(const std::string& csv) {
  std::ifstream in{csv};
  std::string line;
  std::getline(in, line);  // header: tick,t,target,sent,moving,...
  std::vector<long long> out;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss{line};
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    if (f.size() > 4 && f[4] == "1") out.push_back(std::stoll(f[2]));
  }
  return out;
}

TEST(CliTune, StreamPlanFromStreamsExactlyTheTunedPlan) {
  // Intervals of +-10 %: wide enough that the fastest robust plan is a shaped one.
  const std::string file = write("identified2.json", R"({"status":"ok","modes":[
    {"omega":12.566,"zeta":0.03,"gain":1.0,"omega_ci":[11.31,13.82],"zeta_ci":[0.02,0.04]},
    {"omega":44.0,"zeta":0.02,"gain":0.4,"omega_ci":[39.6,48.4],"zeta_ci":[0.01,0.03]}]})");
  const CliResult t = run_cli("tune --modes-from " + file + kMove + " --json");
  ASSERT_EQ(t.status, 0) << t.out;
  const std::string plan = write("tuned.json", t.stdout_text);
  const Json tuned = Json::parse(t.stdout_text);
  // The plan's own evaluation at every period, printed by sample from the same file.
  const CliResult s = run_cli("sample --plan-from " + plan + " --dt 0.001 --json");
  ASSERT_EQ(s.status, 0) << s.out;
  const Json rows = Json::parse(s.stdout_text).at("rows");
  EXPECT_DOUBLE_EQ(rows.back()[0].get<double>(), tuned.at("duration").get<double>());
  EXPECT_DOUBLE_EQ(rows.back()[1].get<double>(), 0.1);
  const std::string log = (scratch() / "ticks.csv").string();
  const CliResult st = run_cli("stream --bus loopback --plan-from " + plan +
                               " --plant modes --mode 12.566,0.03,1 --mode 44,0.02,0.4 --log " + log + " --json");
  ASSERT_EQ(st.status, 0) << st.out;
  const Json report = Json::parse(st.stdout_text);
  EXPECT_EQ(report.at("profile"), tuned.at("profile"));
  EXPECT_DOUBLE_EQ(report.at("duration").get<double>(), tuned.at("duration").get<double>());
  // One moving tick per period from t = 0 to the end: the setpoint is the plan's position in counts
  // (1e6 counts per unit, the default).
  const std::vector<long long> targets = moving_targets(log);
  ASSERT_EQ(targets.size(), rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(targets[k], std::llround(rows[k][1].get<double>() * 1e6)) << "period " << k;
  }
  // On a plant whose modes sit where the tuner found each one's worst case, the residual measured
  // through the bus is the tuner's prediction: per mode r_j (relative to a step), combined as the
  // plant's PRV combines them, sum g_j r_j s_j / sum g_j s_j with s_j = 1 / sqrt(1 - zeta_j^2).
  std::string corner = "stream --bus loopback --plan-from " + plan + " --plant modes --json";
  double num = 0.0, den = 0.0;
  for (const Json& m : tuned.at("robust_band").at("modes")) {
    const double w = m.at("worst_at").at("omega").get<double>(), z = m.at("worst_at").at("zeta").get<double>();
    const double g = m.at("gain").get<double>(), sz = 1.0 / std::sqrt(1.0 - z * z);
    std::ostringstream mode;
    mode.precision(17);
    mode << w << "," << z << "," << g;
    corner += " --mode " + mode.str();
    num += std::fabs(g) * m.at("worst_residual").get<double>() * sz;
    den += std::fabs(g) * sz;
  }
  const CliResult at_corner = run_cli(corner);
  ASSERT_EQ(at_corner.status, 0) << at_corner.out;
  const Json measured = Json::parse(at_corner.stdout_text);
  EXPECT_NEAR(measured.at("prv_continuous_percent").get<double>(), 100.0 * num / den, 1e-3 * 100.0 * num / den);
  EXPECT_NEAR(measured.at("prv_can_percent").get<double>(), 100.0 * num / den, 2e-2 * 100.0 * num / den);
  EXPECT_LE(measured.at("prv_can_percent").get<double>(), 5.0);
  // The plan is a shaped one (so the shaper's impulses travelled through the file too).
  EXPECT_GT(tuned.at("shaper").at("impulses").size(), 1u);
  EXPECT_NE(tuned.at("candidate").at("shaper"), "none");
}

// A modes file from an earlier `settle identify --json`, which also gave each mode's frequency in
// Hz, tunes to the very same plan as one that states omega once.
TEST(CliTune, AModesFileWithTheEarlierFrequencyInHzTunesTheSame) {
  const std::string mode = R"("omega":12.566,"zeta":0.03,"gain":1.0,"omega_ci":[11.31,13.82],"zeta_ci":[0.02,0.04])";
  const std::string now = write("modes_now.json", R"({"status":"ok","modes":[{)" + mode + "}]}");
  const std::string before =
      write("modes_before.json", R"({"status":"ok","modes":[{)" + mode + R"(,"gain_sd":0.01,"frequency_hz":2.0}]})");
  const CliResult a = run_cli("tune --modes-from " + now + kMove + " --json");
  const CliResult b = run_cli("tune --modes-from " + before + kMove + " --json");
  ASSERT_EQ(a.status, 0) << a.out;
  EXPECT_EQ(b.status, 0) << b.out;
  EXPECT_EQ(a.stdout_text, b.stdout_text);
}

// A plan file written before the request held one list of modes (`settle tune --json` for three
// identified modes: the first as "omega"/"zeta", the others as "extra_modes") still reads, as that
// same list: it plans the very same move (plan_mismatch if a mode were lost or reordered).
TEST(CliTune, APlanFileOfThreeModesFromAnEarlierSettleStillLoads) {
  const std::string plan = std::string{SETTLE_SOURCE_DIR} + "/tests/app/data/plan_three_modes_first_format.json";
  std::ifstream in{plan};
  const Json file = Json::parse(in);
  ASSERT_EQ(file.at("request").at("extra_modes").size(), 2u);
  const CliResult s = run_cli("sample --plan-from " + plan + " --dt 0.001 --json");
  ASSERT_EQ(s.status, 0) << s.out;
  const Json rows = Json::parse(s.stdout_text).at("rows");
  EXPECT_DOUBLE_EQ(rows.back()[0].get<double>(), file.at("duration").get<double>());
  EXPECT_DOUBLE_EQ(rows.back()[1].get<double>(), file.at("distance").get<double>());
}

TEST(CliTune, PngDrawsTheChosenPlanAndTheOnesItBeat) {
  const fs::path png = scratch() / "tune.png";
  const CliResult r = run_cli("tune --mode 12.566,0.03 --uncertainty 10" + kMove + " --png " + png.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::exists(scratch() / "tune.gp"));
  std::ifstream csv{scratch() / "tune.csv"};
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("frequency_error_pct,residual_", 0), 0u) << header;
  EXPECT_GE(std::count(header.begin(), header.end(), ','), 2) << "the chosen plan and at least one it beat";
  if (r.stderr_text.find("gnuplot not found") == std::string::npos) {
    EXPECT_TRUE(fs::exists(png));
  }
}

TEST(CliTune, BadInputsExitTwoNamingTheOption) {
  const std::string ok_modes = write("ok.json", kIdentified);
  const std::string m = "tune --mode 12.566,0.03 --uncertainty 10" + kMove;
  const std::string f = "tune --modes-from " + ok_modes + kMove;
  auto file = [&](const std::string& name, const std::string& text) {
    return "tune --modes-from " + write(name, text) + kMove;
  };
  std::string big(2 << 20, ' ');
  big[0] = '{';
  const std::vector<Case> cases = {
      {"tune" + kMove, "--mode", "missing_option"},
      {f + " --mode 10,0.1 --uncertainty 10", "--mode", "conflicting_options"},
      {"tune --mode 12.566,0.03" + kMove, "--uncertainty", "missing_interval"},
      {"tune --mode 12.566,0.03 --uncertainty abc" + kMove, "--uncertainty", "bad_uncertainty"},
      {"tune --mode 12.566,0.03 --uncertainty 0" + kMove, "--uncertainty", "bad_uncertainty"},
      {"tune --mode 12.566,0.03 --uncertainty 95" + kMove, "--uncertainty", "bad_uncertainty"},
      {"tune --mode 12.566,0.03 --uncertainty nan" + kMove, "--uncertainty", "bad_uncertainty"},
      {"tune --mode 12.566,0.03 --uncertainty -10" + kMove, "--uncertainty", "bad_uncertainty"},
      {"tune --mode 0,0.1 --uncertainty 10" + kMove, "--mode", "out_of_range"},
      {"tune --mode 10 --uncertainty 10" + kMove, "--mode", "bad_list"},
      {"tune --mode 10,1.0 --uncertainty 10" + kMove, "--mode", "out_of_range"},
      {"tune --mode 10,0.1,1,2 --uncertainty 10" + kMove, "--mode", "bad_list"},
      {"tune --mode 10,nan --uncertainty 10" + kMove, "--mode", "non_finite_input"},
      {"tune --mode 10,0.1 --mode 11,0.1 --mode 12,0.1 --mode 13,0.1 --mode 14,0.1 --uncertainty 10" + kMove,
       "--mode", "too_many_values"},
      {m + " --residual-max 0", "--residual-max", "out_of_range"},
      {m + " --residual-max 1", "--residual-max", "out_of_range"},
      {m + " --residual-max nan", "--residual-max", "non_finite_input"},
      {m + " --zeta-pm 0.6", "--zeta-pm", "out_of_range"},
      {"tune --mode 12.566,0.03 --uncertainty 10 --vmax 1", "--distance", "missing_option"},
      {"tune --mode 12.566,0.03 --uncertainty 10 --distance 0 --time 1", "--distance", "out_of_range"},
      {"tune --mode 12.566,0.03 --uncertainty 10 --distance 0.1", "--time", "missing_option"},
      {m + " --time 1", "--time", "conflicting_options"},
      {"tune --mode 12.566,0.03 --uncertainty 10 --distance 0.1 --time 0", "--time", "out_of_range"},
      {"tune --mode 12.566,0.03 --uncertainty 10 --distance 0.1 --vmax -1", "--vmax", "out_of_range"},
      {m + " --png out.svg", "--png", "bad_png"},
      // No plan meets the bound: a wide band and a tiny bound.
      {"tune --mode 20,0.01 --uncertainty 60 --distance 0.1 --time 0.2 --residual-max 0.001", "--residual-max",
       "no_feasible_plan"},
      // A search too fine to bound: a fast mode under a long move.
      {"tune --mode 1e4,0.01 --uncertainty 50 --distance 1 --time 100", "--mode", "too_much_work"},
      // --modes-from: the file and each field.
      {"tune --modes-from " + (scratch() / "absent.json").string() + kMove, "--modes-from", "cannot_read"},
      {"tune --modes-from " + scratch().string() + kMove, "--modes-from", "cannot_read"},
      {file("big.json", big), "--modes-from", "file_too_large"},
      {file("notjson.json", "modes: 1"), "--modes-from", "bad_modes_file"},
      {file("array.json", "[1,2]"), "--modes-from", "bad_modes_file"},
      {file("failed.json", R"({"status":"error","error":"drive_never_enabled"})"), "--modes-from", "bad_modes_file"},
      {file("nomodes.json", R"({"status":"ok"})"), "--modes-from", "bad_modes_file"},
      {file("empty.json", R"({"status":"ok","modes":[]})"), "--modes-from", "bad_modes_file"},
      {file("five.json", R"({"status":"ok","modes":[{"omega":1,"zeta":0},{"omega":2,"zeta":0},{"omega":3,"zeta":0},
        {"omega":4,"zeta":0},{"omega":5,"zeta":0}]})"), "--modes-from", "bad_modes_file"},
      {file("noomega.json", R"({"status":"ok","modes":[{"zeta":0.1,"omega_ci":[1,2],"zeta_ci":[0,0.2]}]})"),
       "--modes-from", "bad_modes_file"},
      {file("strzeta.json", R"({"status":"ok","modes":[{"omega":10,"zeta":"0.1"}]})"), "--modes-from",
       "bad_modes_file"},
      {file("badzeta.json", R"({"status":"ok","modes":[{"omega":10,"zeta":1.5,"omega_ci":[9,11],"zeta_ci":[0,0.2]}]})"),
       "--modes-from", "bad_modes_file"},
      {file("noci.json", R"({"status":"ok","modes":[{"omega":10,"zeta":0.1}]})"), "--modes-from", "bad_modes_file"},
      {file("ciout.json", R"({"status":"ok","modes":[{"omega":10,"zeta":0.1,"omega_ci":[11,12],"zeta_ci":[0,0.2]}]})"),
       "--modes-from", "bad_modes_file"},
      {file("zci.json", R"({"status":"ok","modes":[{"omega":10,"zeta":0.1,"omega_ci":[9,11],"zeta_ci":[0.2,0.3]}]})"),
       "--modes-from", "bad_modes_file"},
      {file("ci3.json", R"({"status":"ok","modes":[{"omega":10,"zeta":0.1,"omega_ci":[9,10,11],"zeta_ci":[0,0.2]}]})"),
       "--modes-from", "bad_modes_file"},
      {file("gain.json", R"({"status":"ok","modes":[{"omega":10,"zeta":0.1,"gain":1e9,"omega_ci":[9,11],"zeta_ci":[0,0.2]}]})"),
       "--modes-from", "bad_modes_file"},
      // A value nested 120 000 deep before the modes (a 240 kB file): refused before it is parsed.
      {file("deep.json", "{\"x\":" + std::string(120000, '[') + std::string(120000, ']') + R"(,"status":"ok","modes":[{"omega":10,"zeta":0.1}]})"),
       "--modes-from", "bad_modes_file"},
  };
  for (const Case& c : cases) expect_refused(c);
  // A damping interval reaching below 0 is clipped at 0 (a symmetric CI around a small zeta).
  const CliResult clipped = run_cli(file("negzeta.json", R"({"status":"ok","modes":[{"omega":30,"zeta":0.004,
    "omega_ci":[29.5,30.5],"zeta_ci":[-0.003,0.011]}]})") + " --json");
  ASSERT_EQ(clipped.status, 0) << clipped.out;
  EXPECT_EQ(Json::parse(clipped.stdout_text).at("robust_band").at("modes")[0].at("zeta_band")[0], 0.0);
  // Without intervals the file is fine with a percentage band.
  const CliResult r = run_cli(file("noci2.json", R"({"status":"ok","modes":[{"omega":30,"zeta":0.1}]})") +
                              " --uncertainty 10");
  EXPECT_EQ(r.status, 0) << r.out;
}

TEST(CliTune, PlanFromRefusesWhatIsNotThePlanItClaims) {
  const CliResult t = run_cli("tune --mode 12.566,0.03 --uncertainty 10" + kMove + " --json");
  ASSERT_EQ(t.status, 0) << t.out;
  const Json tuned = Json::parse(t.stdout_text);
  const std::string plan = write("plan_ok.json", t.stdout_text);
  Json edited = tuned;
  edited["params"].begin().value() = edited["params"].begin().value().get<double>() * 1.01 + 1e-3;
  Json longer = tuned;
  longer["duration"] = tuned["duration"].get<double>() + 0.1;
  Json no_request = tuned;
  no_request.erase("request");
  Json bad_profile = tuned;
  bad_profile["request"]["profile"] = "warp";
  Json bad_shaper = tuned;
  bad_shaper["shaper"]["impulses"][0]["amplitude"] = 5.0;
  // Impulses that still sum to 1 but steer the axis past its target (3 and -2: 1.86 times the
  // distance), and a shaper kind the impulses were not designed as.
  Json steering = tuned;
  const double t0 = tuned["shaper"]["impulses"][0]["time"].get<double>();
  steering["shaper"]["impulses"] = Json::array({Json{{"amplitude", 3.0}, {"time", t0}},
                                                Json{{"amplitude", -2.0}, {"time", t0 + 0.05}}});
  Json steering_same_count = tuned;
  for (auto& i : steering_same_count["shaper"]["impulses"]) i["time"] = i["time"].get<double>() * 1.5 + 0.01;
  Json other_kind = tuned;
  other_kind["candidate"]["shaper"] = other_kind["candidate"]["shaper"] == "zv" ? "zvd" : "zv";
  Json no_candidate = tuned;
  no_candidate.erase("candidate");
  // A value nested 120 000 deep before the keys the reader looks for (a 240 kB file).
  const std::string deep = "{\"x\":" + std::string(120000, '[') + std::string(120000, ']') + "," + t.stdout_text.substr(1);
  const std::string sample = "sample --dt 0.01 --plan-from ";
  const std::string stream = "stream --bus loopback --plan-from ";
  const std::vector<Case> cases = {
      {sample + write("edited.json", edited.dump()), "--plan-from", "plan_mismatch"},
      {sample + write("longer.json", longer.dump()), "--plan-from", "plan_mismatch"},
      {stream + write("norequest.json", no_request.dump()), "--plan-from", "bad_plan_file"},
      {stream + write("badprofile.json", bad_profile.dump()), "--plan-from", "bad_plan_file"},
      {stream + write("badshaper.json", bad_shaper.dump()), "--plan-from", "bad_plan_file"},
      {stream + write("garbage.json", "not json"), "--plan-from", "bad_plan_file"},
      {stream + write("steering.json", steering.dump()), "--plan-from", "plan_mismatch"},
      {sample + write("steering.json", steering.dump()), "--plan-from", "plan_mismatch"},
      {sample + write("steering2.json", steering_same_count.dump()), "--plan-from", "plan_mismatch"},
      {sample + write("otherkind.json", other_kind.dump()), "--plan-from", "plan_mismatch"},
      // Without its candidate a tuned file reads as a planned one, whose request names no shaper.
      {sample + write("nocandidate.json", no_candidate.dump()), "--plan-from", "plan_mismatch"},
      {stream + write("deep.json", deep), "--plan-from", "bad_plan_file"},
      {sample + write("deep.json", deep), "--plan-from", "bad_plan_file"},
      {stream + (scratch() / "missing.json").string(), "--plan-from", "cannot_read"},
      {stream + plan + " --distance 0.1", "--distance", "conflicting_options"},
      {stream + plan + " --profile poly345", "--profile", "conflicting_options"},
      {sample + plan + " --shaper zv", "--shaper", "conflicting_options"},
      {stream + plan + " --halt-at 0.1", "--halt-at", "conflicting_options"},
      {stream + plan + " --retarget-at 0.1:0.2", "--retarget-at", "conflicting_options"},
  };
  for (const Case& c : cases) expect_refused(c);
}

// What `settle plan --json` prints is a plan file: every profile and shaper option a request can
// carry comes back through --plan-from as the move planned from the options themselves.
TEST(CliPlanFrom, APlannedMoveOfEveryProfileLoadsAsTheMoveItsOptionsPlan) {
  const std::vector<std::string> moves = {
      "--profile scurve --distance 0.1 --time 0.5 --omega 22",
      "--profile scurve-damped --distance 0.1 --time 0.5 --omega 22 --zeta 0.1",
      "--profile poly345 --distance 0.1 --time 0.5 --shaper zv --omega 22 --zeta 0.05",
      "--profile trapezoid --distance 0.1 --vmax 0.5 --amax 5 --shaper zvd --omega 30",
      "--profile jerk-limited --distance 0.1 --vmax 0.5 --amax 5 --jmax 200 --shaper ei --omega 22 --vtol 0.03",
      "--profile pseudopoly --distance 0.1 --time 0.5 --gammas 3,4,5",
      "--profile ramp-versine --distance 0.1 --time 0.5 --y 0.2,0.5,0.3",
      "--profile fastest --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 22 --zeta 0.02 --omega 60 --zeta 0.01",
  };
  int n = 0;
  for (const std::string& move : moves) {
    const CliResult p = run_cli("plan " + move + " --json");
    ASSERT_EQ(p.status, 0) << move << "\n" << p.out;
    const std::string file = write("planned_" + std::to_string(n++) + ".json", p.stdout_text);
    const CliResult direct = run_cli("sample " + move + " --dt 0.002 --json");
    const CliResult loaded = run_cli("sample --plan-from " + file + " --dt 0.002 --json");
    ASSERT_EQ(direct.status, 0) << move << "\n" << direct.out;
    ASSERT_EQ(loaded.status, 0) << move << "\n" << loaded.out;
    EXPECT_EQ(loaded.stdout_text, direct.stdout_text) << move;
  }
}

// The request holds one list of modes, in the order given, each with its omega and zeta, and no
// other spelling of them; a request without modes has none. Read back beside the writer: every
// malformed list is refused naming the field, and so is a file that spells its modes both ways.
TEST(CliPlanFrom, TheRequestHoldsOneListOfModes) {
  const CliResult p = run_cli(
      "plan --profile fastest --distance 0.1 --vmax 1 --amax 20 --jmax 800 --omega 22 --zeta 0.02 --omega 60 "
      "--zeta 0.01 --omega 95 --zeta 0 --json");
  ASSERT_EQ(p.status, 0) << p.out;
  const Json planned = Json::parse(p.stdout_text);
  const Json& rq = planned.at("request");
  EXPECT_EQ(rq.at("modes"), Json::parse(R"([{"omega":22.0,"zeta":0.02},{"omega":60.0,"zeta":0.01},{"omega":95.0,"zeta":0.0}])"));
  for (const char* k : {"omega", "zeta", "extra_modes"}) EXPECT_FALSE(rq.contains(k)) << k;
  const Json plain = Json::parse(run_cli("plan --profile trapezoid --distance 0.1 --vmax 0.5 --amax 5 --json").stdout_text);
  EXPECT_FALSE(plain.at("request").contains("modes"));
  // Every mode of the list is read: with one left out, the file's move is not what it plans.
  Json dropped = planned;
  dropped["request"]["modes"].erase(2);
  Json not_a_list = planned;
  not_a_list["request"]["modes"] = Json{{"omega", 22.0}, {"zeta", 0.02}};
  Json too_many = planned;
  for (int k = 0; k < 2; ++k) too_many["request"]["modes"].push_back(Json{{"omega", 120.0 + k}, {"zeta", 0.0}});
  Json no_zeta = planned;
  no_zeta["request"]["modes"][1].erase("zeta");
  Json both = planned;
  both["request"]["omega"] = 22.0;
  Json extra_alone = planned;
  extra_alone["request"].erase("modes");
  extra_alone["request"]["extra_modes"] = Json::array({Json{{"omega", 60.0}, {"zeta", 0.01}}});
  const std::string sample = "sample --dt 0.01 --plan-from ";
  expect_refused({sample + write("m_dropped.json", dropped.dump()), "--plan-from", "plan_mismatch"});
  const std::pair<Json, std::string> malformed[] = {
      {not_a_list, "request.modes must be an array of at most 4 modes"},
      {too_many, "request.modes must be an array of at most 4 modes"},
      {no_zeta, "every mode of request.modes needs finite numbers \"omega\" and \"zeta\""},
      {both, "request.modes and request.omega/extra_modes are both given"},
      {extra_alone, "request.extra_modes needs request.omega"},
  };
  int n = 0;
  for (const auto& [file, why] : malformed) {
    const std::string args = sample + write("m_bad_" + std::to_string(n++) + ".json", file.dump());
    expect_refused({args, "--plan-from", "bad_plan_file"});
    const CliResult r = run_cli(args);
    EXPECT_NE(r.stderr_text.find(why), std::string::npos) << r.stderr_text;
  }
  const CliResult loaded = run_cli(sample + write("m_ok.json", planned.dump()));
  EXPECT_EQ(loaded.status, 0) << loaded.out;
}

// The shaper of a planned file is designed again from its request: impulses that are not what the
// request designs, or a request that names another shaper, are refused.
TEST(CliPlanFrom, APlannedFileWhoseShaperWasEditedIsRefused) {
  const CliResult p = run_cli("plan --profile poly345 --distance 0.1 --time 0.5 --shaper zv --omega 22 --json");
  ASSERT_EQ(p.status, 0) << p.out;
  const Json planned = Json::parse(p.stdout_text);
  ASSERT_EQ(planned["request"]["shaper"], "zv");
  Json steering = planned;
  steering["shaper"]["impulses"][0]["amplitude"] = 3.0;
  steering["shaper"]["impulses"][1]["amplitude"] = -2.0;
  Json other = planned;
  other["request"]["shaper"] = "zvd";
  Json unknown = planned;
  unknown["request"]["shaper"] = "magic";
  Json bad_gammas = planned;
  bad_gammas["request"]["gammas"] = Json::array();
  Json bad_y = planned;
  bad_y["request"]["y"] = Json::array({0.2, 0.5});
  Json both = planned;
  both["candidate"] = Json{{"shaper", "zv"}, {"design_modes", Json::array()}};
  const std::string sample = "sample --dt 0.01 --plan-from ";
  const std::vector<Case> cases = {
      {sample + write("p_steering.json", steering.dump()), "--plan-from", "plan_mismatch"},
      {sample + write("p_other.json", other.dump()), "--plan-from", "plan_mismatch"},
      {sample + write("p_unknown.json", unknown.dump()), "--plan-from", "bad_plan_file"},
      {sample + write("p_gammas.json", bad_gammas.dump()), "--plan-from", "bad_plan_file"},
      {sample + write("p_y.json", bad_y.dump()), "--plan-from", "bad_plan_file"},
      {sample + write("p_both.json", both.dump()), "--plan-from", "bad_plan_file"},
  };
  for (const Case& c : cases) expect_refused(c);
}

}  // namespace
