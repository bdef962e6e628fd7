// SPDX-License-Identifier: Apache-2.0
// Every CSV file a settle command writes names each column <quantity>_<unit> with a unit from the
// list docs/csv.md documents (which must be the code's plant::kUnitSuffixes), as an identifier that
// numpy, pandas and csv.DictReader keep; --unit rad changes the names and not one byte of the data;
// a bad --unit is refused before anything is written.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "run_cli.hpp"
#include "settle/plant/csv_columns.hpp"
#include "settle/testbed/sync_log.hpp"

namespace {

namespace fs = std::filesystem;
using settle::test::CliResult;
using settle::test::run_cli_argv;

std::string read(const fs::path& p) {
  std::ifstream f{p, std::ios::binary};
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

fs::path scratch() {
  const fs::path d = fs::path{::testing::TempDir()} / "settle_csv_units";
  fs::create_directories(d);
  return d;
}

// The header line and the rest of a CSV text.
std::pair<std::string, std::string> split(const std::string& csv) {
  const std::size_t nl = csv.find('\n');
  if (nl == std::string::npos) return {csv, {}};
  return {csv.substr(0, nl), csv.substr(nl + 1)};
}

std::vector<std::string> columns(const std::string& header) {
  std::vector<std::string> c;
  std::stringstream s{header};
  for (std::string name; std::getline(s, name, ',');) c.push_back(name);
  return c;
}

// The suffixes docs/csv.md lists: the first cell of each row of its "Unit suffixes" table.
std::vector<std::string> documented_suffixes() {
  const std::string doc = read(fs::path{SETTLE_SOURCE_DIR} / "docs" / "csv.md");
  const std::size_t from = doc.find("## Unit suffixes");
  const std::size_t to = doc.find("\n## ", from + 1);
  std::vector<std::string> out;
  if (from == std::string::npos) return out;
  const std::string table = doc.substr(from, to == std::string::npos ? std::string::npos : to - from);
  const std::regex row{R"(\n\| `([a-z0-9_]+)` \|)"};
  for (auto it = std::sregex_iterator(table.begin(), table.end(), row); it != std::sregex_iterator(); ++it) {
    out.push_back((*it)[1]);
  }
  return out;
}

// Every column an identifier that ends in _<a documented suffix>; `what` names the file.
void expect_units(const std::string& header, const std::string& what) {
  const std::vector<std::string> suffixes = documented_suffixes();
  ASSERT_FALSE(suffixes.empty()) << "docs/csv.md lists no suffix";
  const std::regex ident{"[a-z][a-z0-9_]*"};
  const std::vector<std::string> cols = columns(header);
  ASSERT_GE(cols.size(), 2u) << what << ": " << header;
  std::set<std::string> seen;
  for (const std::string& c : cols) {
    EXPECT_TRUE(std::regex_match(c, ident)) << what << ": column '" << c << "' is not an identifier";
    EXPECT_TRUE(seen.insert(c).second) << what << ": column '" << c << "' twice";
    const bool has_unit = std::any_of(suffixes.begin(), suffixes.end(), [&](const std::string& s) {
      return c.size() > s.size() + 1 && c.compare(c.size() - s.size() - 1, std::string::npos, "_" + s) == 0;
    });
    EXPECT_TRUE(has_unit) << what << ": column '" << c << "' carries no documented unit suffix";
  }
}

const std::vector<std::string> kMove{"--profile", "scurve", "--distance", "0.1", "--time", "0.5", "--omega", "22"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

CliResult run(const std::vector<std::string>& args) { return run_cli_argv(args); }

TEST(CsvUnits, TheDocumentedSuffixesAreTheCodes) {
  const std::vector<std::string> doc = documented_suffixes();
  const std::vector<std::string> code(settle::plant::kUnitSuffixes.begin(), settle::plant::kUnitSuffixes.end());
  EXPECT_EQ(doc, code) << "docs/csv.md's table and plant::kUnitSuffixes differ";
}

TEST(CsvUnits, ColumnRefusesAnUndocumentedUnitOrAName) {
  EXPECT_EQ(settle::plant::column("position", "m"), "position_m");
  EXPECT_THROW((void)settle::plant::column("position", "mm"), std::logic_error);
  EXPECT_THROW((void)settle::plant::column("a b", "m"), std::logic_error);
  EXPECT_THROW((void)settle::plant::column("1st", "m"), std::logic_error);
  EXPECT_EQ(settle::plant::identifier("scurve-damped+zv"), "scurve_damped_zv");
}

// sample (stdout, one axis and --axes 2), plan and sample --png, simulate --csv on each plant,
// and the history next to simulate --png.
TEST(CsvUnits, PlanSampleAndSimulateName) {
  const fs::path d = scratch();
  const CliResult s = run(with({"sample"}, with(kMove, {"--dt", "0.1"})));
  ASSERT_EQ(s.status, 0) << s.out;
  expect_units(split(s.stdout_text).first, "sample");
  EXPECT_EQ(split(s.stdout_text).first, "t_s,position_m,velocity_m_per_s,acceleration_m_per_s2,jerk_m_per_s3");
  const CliResult a = run({"sample", "--axes", "2", "--profile", "jerk-limited", "--distance", "0.1,0.2", "--vmax", "1",
                           "--amax", "10", "--jmax", "100", "--dt", "0.1"});
  ASSERT_EQ(a.status, 0) << a.out;
  expect_units(split(a.stdout_text).first, "sample --axes 2");
  EXPECT_EQ(columns(split(a.stdout_text).first).size(), 9u);
  EXPECT_EQ(columns(split(a.stdout_text).first)[5], "position_2_m");
  const CliResult sp = run(with({"sample", "--dt", "0.01", "--png", (d / "sampled.png").string()}, kMove));
  ASSERT_EQ(sp.status, 0) << sp.out;
  expect_units(split(read(d / "sampled.csv")).first, "sample --png");
  const CliResult pp = run(with({"plan", "--png", (d / "planned.png").string()}, kMove));
  ASSERT_EQ(pp.status, 0) << pp.out;
  expect_units(split(read(d / "planned.csv")).first, "plan --png");
  for (const char* plant : {"sdof", "beam", "belt", "modes"}) {
    const fs::path csv = d / (std::string{plant} + ".csv");
    std::vector<std::string> args{"simulate", "--plant", plant, "--profile", "poly345", "--distance", "0.1", "--time", "0.5",
                                  "--csv", csv.string()};
    if (std::string{plant} == "modes") args = with(args, {"--mode", "22,0.02,1"});
    const CliResult r = run(args);
    ASSERT_EQ(r.status, 0) << r.out;
    const std::string header = split(read(csv)).first;
    expect_units(header, std::string{"simulate --plant "} + plant);
    const std::string energy = std::string{plant} == "modes" ? "j_per_kg" : "j";
    const std::string unit = std::string{plant} == "belt" ? "rad" : "m";
    EXPECT_NE(header.find(",kinetic_energy_" + energy + ",potential_energy_" + energy), std::string::npos) << header;
    EXPECT_EQ(header.rfind("t_s,command_position_" + unit + ",", 0), 0u) << header;
  }
  const CliResult p = run(with({"simulate", "--plant", "beam", "--png", (d / "sim.png").string()}, kMove));
  ASSERT_EQ(p.status, 0) << p.out;
  expect_units(split(read(d / "sim.csv")).first, "simulate --png");
}

// stream's two logs on the loopback bus, identify's two CSVs and tune's.
TEST(CsvUnits, StreamIdentifyAndTuneName) {
  const fs::path d = scratch();
  const CliResult s = run(with({"stream", "--bus", "loopback", "--plant", "beam", "--axis-vmax", "1", "--log",
                                (d / "tick.csv").string(), "--feedback-log", (d / "feedback.csv").string()},
                               kMove));
  ASSERT_EQ(s.status, 0) << s.out;
  expect_units(split(read(d / "tick.csv")).first, "stream --log");
  expect_units(split(read(d / "feedback.csv")).first, "stream --feedback-log");
  EXPECT_NE(read(d / "tick.csv").find("velocity_actual_drive_velocity_units"), std::string::npos);
  const CliResult i = run({"identify", "--bus", "loopback", "--plant", "modes", "--mode", "25,0.02,1", "--png",
                           (d / "id.png").string()});
  ASSERT_EQ(i.status, 0) << i.out;
  expect_units(split(read(d / "id_time.csv")).first, "identify --png (time)");
  expect_units(split(read(d / "id_spectrum.csv")).first, "identify --png (spectrum)");
  EXPECT_EQ(split(read(d / "id_spectrum.csv")).first, "frequency_hz,measured_amplitude_m,fitted_amplitude_m");
  const CliResult t = run({"tune", "--mode", "12.566,0.03", "--uncertainty", "10", "--distance", "0.1", "--time", "0.5",
                           "--png", (d / "tune.png").string()});
  ASSERT_EQ(t.status, 0) << t.out;
  expect_units(split(read(d / "tune.csv")).first, "tune --png");
}

// The header under --unit rad is the header under m with each position unit m -> rad; the data
// rows are the same bytes.
void expect_relabelled(const std::string& m, const std::string& rad, const std::string& what) {
  const auto [hm, rows_m] = split(m);
  const auto [hr, rows_rad] = split(rad);
  EXPECT_FALSE(rows_m.empty()) << what;
  EXPECT_EQ(rows_m, rows_rad) << what << ": --unit changed the numbers";
  expect_units(hr, what + " --unit rad");
  const std::vector<std::string> cm = columns(hm);
  const std::vector<std::string> cr = columns(hr);
  ASSERT_EQ(cm.size(), cr.size()) << what;
  std::size_t relabelled = 0;
  for (std::size_t k = 0; k < cm.size(); ++k) {
    const std::string expected = std::regex_replace(cm[k], std::regex{"_m(_per_s[23]?)?$"}, "_rad$1");
    const std::string energy = std::regex_replace(cm[k], std::regex{"_j_per_kg$"}, "_j_per_kg_m2");
    EXPECT_TRUE(cr[k] == expected || cr[k] == energy) << what << ": " << cm[k] << " -> " << cr[k];
    if (cr[k] != cm[k]) ++relabelled;
  }
  EXPECT_GE(relabelled, 2u) << what << ": --unit rad changed no label\n" << hm << "\n" << hr;
}

TEST(CsvUnits, UnitRadChangesTheLabelsNotTheNumbers) {
  const fs::path d = scratch();
  std::string out[2];
  std::string files[2][4];
  const char* units[2] = {"m", "rad"};
  for (int k = 0; k < 2; ++k) {
    const std::string u = units[k];
    const CliResult s = run(with({"sample", "--unit", u, "--dt", "0.01"}, kMove));
    ASSERT_EQ(s.status, 0) << s.out;
    out[k] = s.stdout_text;
    const CliResult p = run(with({"plan", "--unit", u, "--png", (d / ("plan_" + u + ".png")).string()}, kMove));
    ASSERT_EQ(p.status, 0) << p.out;
    files[k][0] = read(d / ("plan_" + u + ".csv"));
    const CliResult m = run(with({"simulate", "--plant", "modes", "--mode", "22,0.1,1", "--unit", u, "--csv",
                                  (d / ("sim_" + u + ".csv")).string()},
                                 kMove));
    ASSERT_EQ(m.status, 0) << m.out;
    files[k][1] = read(d / ("sim_" + u + ".csv"));
    const CliResult i = run({"identify", "--bus", "loopback", "--plant", "modes", "--mode", "25,0.02,1", "--unit", u,
                             "--png", (d / ("id_" + u + ".png")).string(), "--json"});
    ASSERT_EQ(i.status, 0) << i.out;
    EXPECT_NE(i.stdout_text.find("\"unit\":\"" + u + "\""), std::string::npos) << i.stdout_text;
    files[k][2] = read(d / ("id_" + u + "_time.csv"));
    files[k][3] = read(d / ("id_" + u + "_spectrum.csv"));
  }
  expect_relabelled(out[0], out[1], "sample");
  const char* what[4] = {"plan --png", "simulate --csv", "identify (time)", "identify (spectrum)"};
  for (int f = 0; f < 4; ++f) expect_relabelled(files[0][f], files[1][f], what[f]);
  EXPECT_NE(split(files[1][1]).first.find("kinetic_energy_j_per_kg_m2"), std::string::npos) << files[1][1];
}

// settle plant --log runs only on a CAN bus: its writer (testbed::SyncCsvLog, what the command
// opens with its --unit) with one record, in m and in rad.
TEST(CsvUnits, PlantLogNamesAndRelabels) {
  std::string text[2];
  const settle::plant::PositionUnit units[2] = {settle::plant::PositionUnit::m, settle::plant::PositionUnit::rad};
  for (int k = 0; k < 2; ++k) {
    const fs::path path = scratch() / ("plant_" + std::to_string(k) + ".csv");
    settle::testbed::SyncCsvLog log;
    ASSERT_TRUE(log.open(path.string(), units[k]));
    settle::testbed::SyncRecord r{};
    r.sync = 3;
    r.time_us = 4000;
    r.following = true;
    r.target = 12;
    r.feedback.position_actual = 11;
    r.feedback.velocity_actual = -5;
    r.feedback.load_position = 10;
    r.load = 1e-5;
    r.base = 1.1e-5;
    log.on_record(r);
    ASSERT_TRUE(log.close());
    text[k] = read(path);
  }
  expect_units(split(text[0]).first, "plant --log");
  expect_relabelled(text[0], text[1], "plant --log");
}

TEST(CsvUnits, JsonSaysTheUnitOnce) {
  for (const std::vector<std::string>& args : {with({"sample", "--unit", "rad", "--json", "--dt", "0.1"}, kMove),
                                               with({"sample", "--axes", "2", "--unit", "rad", "--json", "--dt", "0.1",
                                                     "--profile", "poly345", "--distance", "0.1,0.2", "--time", "0.5"},
                                                    {})}) {
    const CliResult j = run(args);
    ASSERT_EQ(j.status, 0) << j.out;
    EXPECT_NE(j.stdout_text.find("\"unit\":\"rad\""), std::string::npos) << j.stdout_text;
    EXPECT_NE(j.stdout_text.find("\"columns\":[\"t\",\"position"), std::string::npos) << "the JSON's names stay";
  }
  const CliResult s = run(with({"simulate", "--plant", "modes", "--mode", "22,0.1,1", "--unit", "rad", "--json"}, kMove));
  ASSERT_EQ(s.status, 0) << s.out;
  EXPECT_NE(s.stdout_text.find("\"units\":\"rad\""), std::string::npos) << s.stdout_text;
  EXPECT_NE(s.stdout_text.find("\"energy_units\":\"J/(kg m^2)\""), std::string::npos) << s.stdout_text;
  // The text says the same: a mode without mass has no energy in J.
  const std::regex energy{"\nfinal energy +[0-9.e+-]+ (.+)\n"};
  std::smatch m;
  const CliResult modes = run(with({"simulate", "--plant", "modes", "--mode", "22,0.1,1"}, kMove));
  ASSERT_TRUE(std::regex_search(modes.stdout_text, m, energy)) << modes.out;
  EXPECT_EQ(m[1], "J/kg");
  const CliResult beam = run(with({"simulate", "--plant", "beam"}, kMove));
  ASSERT_TRUE(std::regex_search(beam.stdout_text, m, energy)) << beam.out;
  EXPECT_EQ(m[1], "J");
}

// A unit that is not m or rad, or one a physical plant contradicts: exit 2 naming --unit, and no
// file written, nothing on stdout.
TEST(CsvUnits, BadUnitIsRefusedAndNothingWritten) {
  const fs::path d = scratch();
  const fs::path csv = d / "never.csv";
  const fs::path png = d / "never.png";
  fs::remove(csv);
  fs::remove(d / "never_time.csv");
  const std::vector<std::vector<std::string>> cases = {
      with({"sample", "--unit", "mm", "--dt", "0.1"}, kMove),
      with({"plan", "--unit", "deg", "--png", png.string()}, kMove),
      with({"simulate", "--plant", "modes", "--mode", "22,0.1,1", "--unit", "ft", "--csv", csv.string()}, kMove),
      with({"simulate", "--plant", "beam", "--unit", "rad", "--csv", csv.string()}, kMove),
      with({"simulate", "--plant", "belt", "--unit", "m", "--csv", csv.string()}, kMove),
      {"identify", "--bus", "loopback", "--plant", "modes", "--mode", "25,0.02,1", "--unit", "inch", "--png", png.string()},
      {"plant", "--bus", "settle-no-such-can", "--plant", "modes", "--mode", "25,0.02,1", "--unit", "yd", "--log",
       csv.string()},
      {"plant", "--bus", "settle-no-such-can", "--plant", "sdof", "--unit", "rad", "--log", csv.string()},
  };
  for (const auto& args : cases) {
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 2) << args[0] << ": " << r.out;
    EXPECT_NE(r.stderr_text.find("--unit"), std::string::npos) << r.out;
    EXPECT_TRUE(r.stdout_text.empty()) << r.stdout_text;
    EXPECT_FALSE(fs::exists(csv)) << args[0];
    EXPECT_FALSE(fs::exists(d / "never_time.csv")) << args[0];
  }
  const CliResult r = run(with({"sample", "--unit", "mm", "--dt", "0.1"}, kMove));
  EXPECT_NE(r.stderr_text.find("--unit: unknown unit 'mm'; expected one of m, rad [unknown_unit]"), std::string::npos)
      << r.stderr_text;
  const CliResult b = run(with({"simulate", "--plant", "beam", "--unit", "rad"}, kMove));
  EXPECT_NE(b.stderr_text.find("the beam plant's positions are in m"), std::string::npos) << b.stderr_text;
  EXPECT_NE(b.stderr_text.find("[conflicting_options]"), std::string::npos) << b.stderr_text;
}

}  // namespace
