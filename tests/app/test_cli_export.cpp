// SPDX-License-Identifier: Apache-2.0
// settle export as a user meets it: a plan file becomes a header in the namespace --name, for each
// --scalar; bad names and bad files are refused naming the option, before anything is printed.
// (That the header streams within one count of `settle sample`: tests/core/test_exported_plan.cpp
// for the tables, package.export_host and package.example.exported_plan for the printed header.)
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "refusal.hpp"
#include "run_cli.hpp"
#include "scratch.hpp"

namespace {

using settle::test::Case;
using settle::test::CliResult;
using settle::test::expect_refused;
using settle::test::run_cli;

std::string write(const std::string& name, const std::string& text) {
  return settle::test::write_scratch("export_" + name, text);
}

// Plan files as `settle tune --json` writes them (tune prints what plan prints, plus the request):
// a 50 mm move, and a 5 m one (5e9 counts at --counts-per-unit 1e9, beyond 32 bits).
std::string tuned(const std::string& distance, const std::string& time, const std::string& name) {
  const CliResult r = run_cli("tune --mode 22,0.05 --uncertainty 10 --distance " + distance + " --time " + time + " --json");
  EXPECT_EQ(r.status, 0) << r.out;
  return write(name, r.stdout_text);
}
std::string plan_file() {
  static const std::string path = tuned("0.05", "0.6", "tune.json");
  return path;
}
std::string long_plan_file() {
  static const std::string path = tuned("5", "2", "long.json");
  return path;
}

TEST(CliExport, EachScalarPrintsAHeaderInTheNamedNamespace) {
  for (const char* scalar : {"double", "float", "fixed"}) {
    SCOPED_TRACE(scalar);
    const CliResult r = run_cli("export --plan-from " + plan_file() + " --scalar " + scalar + " --name axis_x");
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_TRUE(r.stderr_text.empty()) << r.stderr_text;
    const std::string& h = r.stdout_text;
    EXPECT_NE(h.find("#pragma once\n#include \"settle/core/exported_plan.hpp\""), std::string::npos) << h;
    EXPECT_NE(h.find("namespace axis_x {"), std::string::npos);
    EXPECT_NE(h.find("}  // namespace axis_x\n"), std::string::npos);
    EXPECT_NE(h.find("inline constexpr settle::core::"), std::string::npos);
    const std::string stream = std::string{scalar} == "fixed" ? "FixedExportedStream;"
                                                              : std::string{"ExportedStream<"} + scalar + ">;";
    EXPECT_NE(h.find("using Stream = settle::core::" + stream), std::string::npos) << h;
    // --json: the same header as one string of one object.
    const CliResult j = run_cli("export --plan-from " + plan_file() + " --scalar " + scalar + " --name axis_x --json");
    ASSERT_EQ(j.status, 0) << j.out;
    const auto doc = nlohmann::json::parse(j.stdout_text);
    EXPECT_EQ(doc.at("status"), "ok");
    EXPECT_EQ(doc.at("header").get<std::string>(), h);
  }
}

TEST(CliExport, BadNamesAndFilesAreRefusedNamingTheOption) {
  const std::string plan = " --plan-from " + plan_file();
  const std::string not_plan = write("not_plan.json", R"({"status":"ok","profile":"scurve"})");
  const std::string garbage = write("garbage.json", "this is not JSON");
  std::string big(2u << 20, ' ');
  const std::string too_big = write("too_big.json", big);
  for (const Case& c : std::initializer_list<Case>{
           {"export", "--plan-from", "missing_option"},
           {"export --plan-from " + settle::test::scratch_path("nosuch.json"), "--plan-from", ""},
           {"export --plan-from " + not_plan, "--plan-from", ""},
           {"export --plan-from " + garbage, "--plan-from", ""},
           {"export --plan-from " + too_big, "--plan-from", ""},
           {"export" + plan + " --name 1axis", "--name", "bad_name"},
           {"export" + plan + " --name axis-x", "--name", "bad_name"},
           {"export" + plan + " --name class", "--name", "bad_name"},
           {"export" + plan + " --name std", "--name", "bad_name"},
           {"export" + plan + " --name settle", "--name", "bad_name"},
           {"export" + plan + " --name a__b", "--name", "bad_name"},
           {"export" + plan + " --name _Axis", "--name", "bad_name"},
           {"export" + plan + " --name _axis", "--name", "bad_name"},
           {"export" + plan + " --name " + std::string(65, 'a'), "--name", "bad_name"},
           {"export" + plan + " --scalar half", "--scalar", ""},
           {"export" + plan + " --counts-per-unit 1e12", "--counts-per-unit", ""},
           {"export --plan-from " + long_plan_file() + " --counts-per-unit 1e9", "--counts-per-unit",
            "target_out_of_range"},
           {"export" + plan + " --period-us 50", "--period-us", ""},
       }) {
    expect_refused(c);
  }
}

TEST(CliExport, NamesThatAreIdentifiersAreAccepted) {
  for (const char* name : {"a", "x_", "Axis_X2", "plan_float", "std_plan", "settle2"}) {
    const CliResult r = run_cli("export --plan-from " + plan_file() + " --name " + name);
    EXPECT_EQ(r.status, 0) << name << ": " << r.out;
  }
  const CliResult r = run_cli("export --plan-from " + plan_file() + " --name " + std::string(64, 'a'));
  EXPECT_EQ(r.status, 0) << r.out;
}

}  // namespace
