// SPDX-License-Identifier: Apache-2.0
// gnuplot and every other helper program run without a shell (spawn.hpp): an argument vector,
// the script on standard input, the exit status checked. A directory named like a shell
// injection, or with spaces and double quotes, gets its plots and nothing else happens.
#include <gtest/gtest.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "settle/papers/figures.hpp"
#include "settle/papers/reproduce.hpp"
#include "settle/testbed/spawn.hpp"

namespace settle::papers {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream f{p, std::ios::binary};
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// A fresh directory, which is also the working directory while the test runs: a shell would
// have run `touch X` here.
class InScratch : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    base_ = fs::temp_directory_path() / ("settle_figures_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(base_);
    fs::create_directories(base_);
    old_ = fs::current_path();
    fs::current_path(base_);
  }
  void TearDown() override {
    fs::current_path(old_);
    fs::remove_all(base_);
  }
  // Nothing in the scratch directory but `expected`.
  void expect_only(const std::vector<std::string>& expected) const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(base_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    std::vector<std::string> want = expected;
    std::sort(want.begin(), want.end());
    EXPECT_EQ(names, want);
  }
  fs::path base_, old_;
};

using Spawn = InScratch;

TEST_F(Spawn, ExitStatusIsChecked) {
  EXPECT_EQ(testbed::run_program({"true"}, {}).status, testbed::SpawnStatus::ok);
  const testbed::SpawnResult r = testbed::run_program({"false"}, {});
  EXPECT_EQ(r.status, testbed::SpawnStatus::exit_nonzero);
  EXPECT_EQ(r.exit_code, 1);
}

TEST_F(Spawn, MissingProgramIsNotFoundWithoutAShell) {
  const testbed::SpawnResult r = testbed::run_program({"settle-no-such-program-7f3a"}, {});
  EXPECT_EQ(r.status, testbed::SpawnStatus::not_found);
  EXPECT_EQ(testbed::run_program({}, {}).status, testbed::SpawnStatus::bad_request);
  testbed::SpawnOptions o;
  o.workdir = (base_ / "missing").string();
  EXPECT_EQ(testbed::run_program({"true"}, o).status, testbed::SpawnStatus::bad_request);
}

TEST_F(Spawn, ArgumentsAndInputAreBytesNotShellText) {
  const std::string hostile = "a'; touch X; '\"b\" $(touch Y) `touch Z`";
  // The argument names one file, literally.
  ASSERT_EQ(testbed::run_program({"touch", hostile}, {}).status, testbed::SpawnStatus::ok);
  EXPECT_TRUE(fs::exists(base_ / hostile));
  // The input reaches standard input unchanged, in the working directory given.
  const std::string dir = "dir '\"; touch W; \"'";
  fs::create_directories(base_ / dir / "sub dir");
  testbed::SpawnOptions o;
  o.workdir = (base_ / dir / "sub dir").string();
  o.input = hostile + "\nsecond line\n";
  o.output = testbed::SpawnOutput::discard;
  ASSERT_EQ(testbed::run_program({"tee", "copy"}, o).status, testbed::SpawnStatus::ok);
  EXPECT_EQ(slurp(base_ / dir / "sub dir" / "copy"), o.input);
  expect_only({hostile, dir});
}

TEST_F(Spawn, AProgramThatStopsReadingDoesNotKillTheCaller) {
  // `true` exits without reading 4 MB: the write fails with EPIPE (SIGPIPE is blocked and
  // consumed) and the result says the input was not taken.
  const std::string big(4 << 20, 'x');
  testbed::SpawnOptions o;
  o.input = big;
  EXPECT_EQ(testbed::run_program({"true"}, o).status, testbed::SpawnStatus::input_failed);
  o.input = "";
  EXPECT_EQ(testbed::run_program({"true"}, o).status, testbed::SpawnStatus::ok);
}

TEST_F(Spawn, OutputAndErrorGoToTheirFiles) {
  // tee copies its input to standard output and to its standard error.
  testbed::SpawnOptions o;
  o.input = "line one\nline 'two'\n";
  o.output = testbed::SpawnOutput::to_file;
  o.output_file = (base_ / "out file").string();
  o.error_file = (base_ / "err file").string();
  ASSERT_EQ(testbed::run_program({"tee", "/dev/stderr"}, o).status, testbed::SpawnStatus::ok);
  EXPECT_EQ(slurp(base_ / "out file"), o.input);
  EXPECT_EQ(slurp(base_ / "err file"), o.input);
  // A file that cannot be created is told apart from a missing program.
  o.output_file = (base_ / "missing" / "out").string();
  const testbed::SpawnResult r = testbed::run_program({"true"}, o);
  EXPECT_EQ(r.status, testbed::SpawnStatus::output_failed);
  EXPECT_EQ(r.error, ENOENT);
  o.output_file.clear();
  EXPECT_EQ(testbed::run_program({"true"}, o).status, testbed::SpawnStatus::bad_request);
}

TEST_F(Spawn, ABackgroundChildRunsUntilSignalledAndNeverOutlivesItsOwner) {
  testbed::ChildProcess sleeper;
  ASSERT_EQ(testbed::start_program({"sleep", "60"}, {}, sleeper).status, testbed::SpawnStatus::ok);
  EXPECT_TRUE(sleeper.running());
  sleeper.signal(SIGTERM);
  const testbed::SpawnResult r = sleeper.wait();
  EXPECT_EQ(r.status, testbed::SpawnStatus::killed);
  EXPECT_EQ(r.signal, SIGTERM);
  EXPECT_FALSE(sleeper.running());
  EXPECT_EQ(sleeper.wait().signal, SIGTERM);  // the same result again
  // One that ends by itself: its status once it has.
  testbed::ChildProcess quick;
  ASSERT_EQ(testbed::start_program({"false"}, {}, quick).status, testbed::SpawnStatus::ok);
  EXPECT_EQ(quick.wait().status, testbed::SpawnStatus::exit_nonzero);
  // Destroyed while running: killed and reaped, so its pid names no process any more.
  int pid = -1;
  {
    testbed::ChildProcess orphan;
    ASSERT_EQ(testbed::start_program({"sleep", "60"}, {}, orphan).status, testbed::SpawnStatus::ok);
    pid = orphan.pid();
    ASSERT_GT(pid, 0);
    ASSERT_EQ(::kill(pid, 0), 0);
  }
  EXPECT_EQ(::kill(pid, 0), -1);
  EXPECT_EQ(errno, ESRCH);
  EXPECT_EQ(testbed::ChildProcess{}.wait().status, testbed::SpawnStatus::bad_request);
}

TEST(GnuplotString, DoublesSingleQuotesAndFlattensLineBreaks) {
  EXPECT_EQ(gnuplot_string("plain.csv"), "'plain.csv'");
  EXPECT_EQ(gnuplot_string("it's"), "'it''s'");
  EXPECT_EQ(gnuplot_string("a\"b\\c"), "'a\"b\\c'");
  EXPECT_EQ(gnuplot_string("two\nlines"), "'two lines'");
}

// gnuplot itself reads the quoted string back as the original text.
TEST_F(Spawn, GnuplotReadsTheQuotedStringBack) {
  if (testbed::run_program({"gnuplot", "--version"}, testbed::SpawnOptions{"", "", testbed::SpawnOutput::discard}).status != testbed::SpawnStatus::ok) {
    GTEST_SKIP() << "gnuplot is not installed";
  }
  const std::string text = "D'; touch X; ' \"q\" back\\slash";
  testbed::SpawnOptions o;
  o.input = "set print " + gnuplot_string("out.txt") + "\nprint " + gnuplot_string(text) + "\n";
  ASSERT_EQ(testbed::run_program({"gnuplot"}, o).status, testbed::SpawnStatus::ok);
  EXPECT_EQ(slurp(base_ / "out.txt"), text + "\n");
}

using Figures = InScratch;

TEST_F(Figures, HostileDirectoryNamesGetTheirPlotsAndNothingElseHappens) {
  Options001 o;
  o.grids = false;
  o.history = true;
  Result001 r;
  ASSERT_EQ(reproduce_001(o, r), plant::SimStatus::ok);
  const std::vector<std::string> dirs = {"DIR'; touch X; '", "with spaces and \"double quotes\""};
  for (const std::string& d : dirs) {
    FigureFiles files;
    ASSERT_EQ(write_figures_001(r, (base_ / d).string(), files), plant::SimStatus::ok) << d;
    ASSERT_FALSE(files.csv.empty());
    for (const auto& f : files.csv) EXPECT_TRUE(fs::exists(f)) << f;
    EXPECT_TRUE(fs::exists(base_ / d / "001_responses.gp"));
    if (files.gnuplot) {
      ASSERT_EQ(files.png.size(), 1u) << d;
      EXPECT_EQ(fs::path{files.png[0]}, base_ / d / "001_responses.png");
      EXPECT_GT(fs::file_size(files.png[0]), 1000u);
    }
  }
  expect_only(dirs);  // no X, nothing else
}

TEST_F(Figures, WithoutGnuplotTheDataAndScriptsAreStillWritten) {
  Options001 o;
  o.grids = false;
  Result001 r;
  ASSERT_EQ(reproduce_001(o, r), plant::SimStatus::ok);
  // posix_spawnp searches this PATH: an empty directory, so no gnuplot (and no shell either).
  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path != nullptr ? old_path : "";
  fs::create_directories(base_ / "empty-bin");
  ASSERT_EQ(::setenv("PATH", (base_ / "empty-bin").c_str(), 1), 0);
  FigureFiles files;
  const plant::SimStatus st = write_figures_001(r, (base_ / "out").string(), files);
  ::setenv("PATH", saved.c_str(), 1);
  ASSERT_EQ(st, plant::SimStatus::ok);
  EXPECT_FALSE(files.gnuplot);
  EXPECT_TRUE(files.png.empty());
  EXPECT_FALSE(files.csv.empty());
  EXPECT_TRUE(fs::exists(base_ / "out" / "001_responses.gp"));
  EXPECT_FALSE(fs::exists(base_ / "out" / "001_responses.png"));
}

#ifdef SETTLE_CLI
// The reproduction, through the command: `settle reproduce 001 --out "DIR'; touch X; '"`.
TEST_F(Figures, ReproduceCommandWithAnInjectionDirectory) {
  const std::string d = "DIR'; touch X; '";
  testbed::SpawnOptions o;
  o.output = testbed::SpawnOutput::discard;
  ASSERT_EQ(testbed::run_program({SETTLE_CLI, "reproduce", "001", "--out", d}, o).status, testbed::SpawnStatus::ok);
  EXPECT_TRUE(fs::exists(base_ / d / "001_slices.csv"));
  if (testbed::run_program({"gnuplot", "--version"}, o).status == testbed::SpawnStatus::ok) {
    EXPECT_TRUE(fs::exists(base_ / d / "001_responses.png"));
    EXPECT_TRUE(fs::exists(base_ / d / "001_robust_slices.png"));
  }
  const std::string q = "a \"quoted\" dir";
  ASSERT_EQ(testbed::run_program({SETTLE_CLI, "reproduce", "001", "--out", q}, o).status, testbed::SpawnStatus::ok);
  EXPECT_TRUE(fs::exists(base_ / q / "001_slices.csv"));
  expect_only({d, q});
}

// gnuplot runs an output name that starts with '|' and a data name that starts with '<' through
// /bin/sh (`settle tune --png '|id > P.txt; true .png'` wrote root's id into P.txt): every command
// whose figure the user names writes it under exactly that name, and nothing runs.
TEST_F(Figures, UserChosenFigureNamesReachNoShell) {
  testbed::SpawnOptions o;
  o.output = testbed::SpawnOutput::discard;
  const bool gnuplot = testbed::run_program({"gnuplot", "--version"}, o).status == testbed::SpawnStatus::ok;
  const std::vector<std::string> stems = {"|touch PIPED; true ", "<touch PIPED; true ", "it's \"quoted\"",
                                          "two\nlines", "with spaces"};
  std::vector<std::string> expected;
  auto expect_figure = [&](const std::string& stem, const std::vector<std::string>& data) {
    for (const std::string& ext : data) {
      EXPECT_TRUE(fs::exists(base_ / (stem + ext))) << stem << ext;
      expected.push_back(stem + ext);
    }
    if (gnuplot) {
      ASSERT_TRUE(fs::exists(base_ / (stem + ".png"))) << stem;
      EXPECT_GT(fs::file_size(base_ / (stem + ".png")), 1000u) << stem;
      expected.push_back(stem + ".png");
    }
  };
  // `command` (settle's arguments before --png) draws its figure as <stem>.png, with `data` beside it.
  const auto draw = [&](std::vector<std::string> command, const std::string& stem, const std::vector<std::string>& data) {
    command.insert(command.begin(), SETTLE_CLI);
    command.insert(command.end(), {"--png", stem + ".png"});
    EXPECT_EQ(testbed::run_program(command, o).status, testbed::SpawnStatus::ok) << stem;
    expect_figure(stem, data);
  };
  for (const std::string& stem : stems) {
    draw({"tune", "--mode", "12.566,0.03", "--uncertainty", "10", "--distance", "0.1", "--time", "0.5"}, stem,
         {".csv", ".gp"});
  }
  draw({"identify", "--bus", "loopback", "--plant", "modes", "--mode", "25,0.02,1"}, "<touch PIPED; true identify",
       {".gp", "_time.csv", "_spectrum.csv"});
  for (const std::string& stem : {std::string{"|touch PIPED; true simulate"}, std::string{"<touch PIPED; true sim"}}) {
    draw({"simulate", "--plant", "sdof", "--profile", "scurve", "--distance", "0.1", "--time", "0.5"}, stem,
         {".gp", ".csv"});
  }
  draw({"plan", "--profile", "scurve", "--distance", "0.1", "--time", "0.5", "--omega", "22"},
       "|touch PIPED; true plan", {".gp", ".csv"});
  draw({"sample", "--profile", "scurve", "--distance", "0.1", "--time", "0.5", "--omega", "22", "--dt", "0.01"},
       "<touch PIPED; true sample", {".gp", ".csv"});
  expect_only(expected);  // no PIPED
}
#endif

}  // namespace
}  // namespace settle::papers
