// SPDX-License-Identifier: Apache-2.0
// --eds as every command reads it (app/eds_option.hpp): each deviation the reader tolerated is
// printed as a warning naming the section and key, --strict refuses the file instead, drive
// config does not call a drive whose description needed tolerating "verified", and one EDS
// error gives one exit status (2, bad_eds) in drive info, drive config, stream, plant and
// identify, before anything is sent. The files are hal's settle_drive.eds with one change each.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "run_cli.hpp"
#include "scratch.hpp"

namespace {

using settle::test::CliResult;
using settle::test::run_cli_argv;

bool has(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

// settle_drive.eds with `from` replaced by `to`, written to a file of its own.
std::string variant(const std::string& name, const std::string& from, const std::string& to) {
  std::ifstream in{SETTLE_DRIVE_EDS};
  std::stringstream text;
  text << in.rdbuf();
  std::string eds = text.str();
  const std::size_t at = eds.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) eds.replace(at, from.size(), to);
  return settle::test::write_scratch(name + ".eds", eds);
}

std::vector<std::string> cmd(std::initializer_list<std::string> words, const std::string& eds,
                             std::initializer_list<std::string> more = {}) {
  std::vector<std::string> v{words};
  v.push_back("--eds");
  v.push_back(eds);
  v.insert(v.end(), more.begin(), more.end());
  return v;
}

TEST(CliEds, ToleratedDeviationsArePrintedAsWarningsAndStrictRefusesThem) {
  const std::string eds = variant("subnumber", "[1018]\nParameterName=Identity object\nObjectType=0x9\nSubNumber=5",
                                  "[1018]\nParameterName=Identity object\nObjectType=0x9\nSubNumber=6");
  const CliResult info = run_cli_argv(cmd({"drive", "info", "--bus", "loopback"}, eds));
  ASSERT_EQ(info.status, 0) << info.out;
  EXPECT_TRUE(has(info.stderr_text, "settle drive info: --eds warning: " + eds + ": line 76: [1018] SubNumber: "
                                    "SubNumber 6 but 5 sub-index sections"))
      << info.stderr_text;
  EXPECT_TRUE(has(info.stdout_text, "1 EDS warning(s)")) << info.stdout_text;
  const CliResult json = run_cli_argv(cmd({"drive", "info", "--bus", "loopback", "--json"}, eds));
  ASSERT_EQ(json.status, 0) << json.out;
  const auto j = nlohmann::json::parse(json.stdout_text);
  ASSERT_EQ(j.at("eds_warnings").size(), 1u) << j.dump();
  EXPECT_EQ(j.at("eds_warnings")[0].at("section"), "1018");
  EXPECT_EQ(j.at("eds_warnings")[0].at("key"), "SubNumber");
  EXPECT_EQ(j.at("eds_warnings")[0].at("line"), 76);

  // --strict: the same file is refused in every command, naming the section and key.
  for (const auto& argv : {cmd({"drive", "info", "--bus", "loopback"}, eds, {"--strict"}),
                           cmd({"drive", "config", "--bus", "loopback"}, eds, {"--strict"}),
                           cmd({"stream", "--bus", "loopback", "--profile", "poly345", "--distance", "0.01", "--time", "0.5"}, eds, {"--strict"}),
                           cmd({"plant", "--bus", "no-such-can9"}, eds, {"--strict"})}) {
    const CliResult r = run_cli_argv(argv);
    EXPECT_EQ(r.status, 2) << argv[0] << " " << argv[1] << ": " << r.out;
    EXPECT_TRUE(has(r.stderr_text, "[1018] SubNumber: SubNumber 6 but 5")) << r.stderr_text;
    EXPECT_TRUE(has(r.stderr_text, "--strict")) << r.stderr_text;
  }

  // drive config configures it, but does not call it verified.
  const CliResult config = run_cli_argv(cmd({"drive", "config", "--bus", "loopback"}, eds));
  ASSERT_EQ(config.status, 0) << config.out;
  EXPECT_FALSE(has(config.stdout_text, "verified in")) << config.stdout_text;
  EXPECT_TRUE(has(config.stdout_text, "not verified: its EDS needed 1 deviation(s) tolerated")) << config.stdout_text;
  const CliResult clean = run_cli_argv(cmd({"drive", "config", "--bus", "loopback"}, SETTLE_DRIVE_EDS));
  ASSERT_EQ(clean.status, 0) << clean.out;
  EXPECT_TRUE(has(clean.stdout_text, "configured and verified in")) << clean.stdout_text;
  EXPECT_TRUE(clean.stderr_text.empty()) << clean.stderr_text;
}

TEST(CliEds, OneEdsErrorGivesOneExitStatusInEveryCommand) {
  struct Bad {
    std::string eds;
    std::string words;  // in every command's message
  };
  const std::vector<Bad> bad = {
      // The reader's refusal.
      {variant("pdomapping", "DefaultValue=0x00020192\nPDOMapping=0", "DefaultValue=0x00020192\nPDOMapping=2"),
       "[1000] PDOMapping: 0x1000:0: PDOMapping must be 0 or 1"},
      // A TPDO on the SYNC's identifier.
      {variant("sync", "[1800sub1]\nParameterName=COB-ID used by TPDO\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\n"
                       "DefaultValue=$NODEID+0x180",
               "[1800sub1]\nParameterName=COB-ID used by TPDO\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\n"
               "DefaultValue=0x80"),
       "[1800sub1] DefaultValue: 0x1800:1 (TPDO1 COB-ID 0x080) is SYNC (0x1005)'s identifier"},
      // A max profile velocity of 0.
      {variant("vmax", "LowLimit=1\nHighLimit=0xFFFFFFFF\nDefaultValue=10000000", "DefaultValue=0"),
       "[607F] DefaultValue: 0x607F:0 (max profile velocity) is 0"},
      // A DCF for node 5 used on node 1.
      {variant("dcf", "[DeviceInfo]", "[DeviceComissioning]\nNodeID=5\n\n[DeviceInfo]"),
       "[DeviceComissioning] NodeID: the DCF configures node 5, not node 1"},
  };
  for (const Bad& b : bad) {
    SCOPED_TRACE(b.words);
    for (const auto& argv :
         {cmd({"drive", "info", "--bus", "loopback"}, b.eds), cmd({"drive", "config", "--bus", "loopback"}, b.eds),
          cmd({"stream", "--bus", "loopback", "--profile", "poly345", "--distance", "0.01", "--time", "0.5"}, b.eds),
          cmd({"plant", "--bus", "no-such-can9"}, b.eds),
          cmd({"identify", "--bus", "loopback", "--plant", "modes", "--mode", "25,0.02,1"}, b.eds)}) {
      const CliResult r = run_cli_argv(argv);
      EXPECT_EQ(r.status, 2) << argv[0] << " " << argv[1] << ": " << r.out;
      EXPECT_TRUE(has(r.stderr_text, b.words)) << argv[0] << ": " << r.stderr_text;
      EXPECT_TRUE(has(r.stderr_text, "--eds: ")) << r.stderr_text;
      // Refused before anything was sent: one line.
      EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
    }
    const CliResult j = run_cli_argv(cmd({"drive", "config", "--bus", "loopback", "--json"}, b.eds));
    EXPECT_EQ(j.status, 2);
    EXPECT_EQ(nlohmann::json::parse(j.stdout_text).at("error"), "bad_eds") << j.stdout_text;
  }
  // The DCF on its own node is read.
  const CliResult own = run_cli_argv(cmd({"drive", "info", "--bus", "loopback", "--node", "5"}, bad[3].eds));
  EXPECT_EQ(own.status, 0) << own.out;
}

TEST(CliEds, LoadFeedbackIsRangeCheckedAndMustBeAMappableObjectOfTheEds) {
  const std::vector<std::string> stream{"stream", "--bus", "loopback", "--profile", "poly345", "--distance", "0.01", "--time", "0.5"};
  const auto with = [&](std::initializer_list<std::string> more) {
    std::vector<std::string> v = stream;
    v.insert(v.end(), more.begin(), more.end());
    return run_cli_argv(v);
  };
  const std::string eds = SETTLE_DRIVE_EDS;
  struct Case {
    std::vector<std::string> args;
    std::string words;
  };
  const std::vector<Case> cases = {
      {{"--load-feedback", "0x2000:0"}, "needs --eds"},
      {{"--eds", eds, "--load-feedback", "0x2000"}, "is not INDEX:SUB"},
      {{"--eds", eds, "--load-feedback", "0x0FFF:0"}, "INDEX must be 0x1000..0xFFFF"},
      {{"--eds", eds, "--load-feedback", "0x2000:256"}, "SUB must be 0..255"},
      {{"--eds", eds, "--load-feedback", "0x2100:0"}, "the drive's EDS has no 0x2100:0"},
      {{"--eds", eds, "--load-feedback", "0x6041:0"}, "another data type than INTEGER32"},
      {{"--eds", eds, "--load-feedback", "0x607D:1"}, "be mapped to a TPDO"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> v = stream;
    v.insert(v.end(), c.args.begin(), c.args.end());
    const CliResult r = run_cli_argv(v);
    EXPECT_EQ(r.status, 2) << c.words << ": " << r.out;
    EXPECT_TRUE(has(r.stderr_text, "--load-feedback: " + c.words) || has(r.stderr_text, c.words)) << r.stderr_text;
  }
  // Named explicitly, Settle's own 0x2000 gives the measured residual the mark gives by default.
  const CliResult named = with({"--eds", eds, "--load-feedback", "0x2000:0", "--json"});
  const CliResult marked = with({"--eds", eds, "--json"});
  ASSERT_EQ(named.status, 0) << named.out;
  ASSERT_EQ(marked.status, 0) << marked.out;
  const auto a = nlohmann::json::parse(named.stdout_text);
  const auto b = nlohmann::json::parse(marked.stdout_text);
  EXPECT_FALSE(a.at("residual_can").is_null()) << named.stdout_text;
  EXPECT_EQ(a.at("residual_can"), b.at("residual_can"));
}

// String and domain objects whose bytes are not UTF-8 are given as hex in JSON (never U+FFFD);
// UTF-8 text stays text.
TEST(CliEds, ReadJsonGivesBytesThatAreNotUtf8AsHex) {
  std::ifstream in{SETTLE_DRIVE_EDS};
  std::stringstream text;
  text << in.rdbuf();
  std::string eds = text.str();
  const std::size_t name = eds.find("[1008]");
  ASSERT_NE(name, std::string::npos);
  const std::size_t value = eds.find("DefaultValue=", name) + 13;
  const std::size_t end = eds.find('\n', value);
  eds.replace(value, end - value, "ab\xFF\xC3\x28" "cd");
  const std::string path = settle::test::write_scratch("bytes.eds", eds);
  const CliResult r = run_cli_argv(
      cmd({"drive", "read", "--bus", "loopback", "--index", "0x1008", "--json"}, path));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(nlohmann::json::parse(r.stdout_text).at("value"), nlohmann::json({{"hex", "6162FFC3286364"}}))
      << r.stdout_text;
  const CliResult info = run_cli_argv(cmd({"drive", "info", "--bus", "loopback", "--json"}, path));
  ASSERT_EQ(info.status, 0) << info.out;
  EXPECT_EQ(nlohmann::json::parse(info.stdout_text).at("device_name"), nlohmann::json({{"hex", "6162FFC3286364"}}));
  const CliResult utf8 = run_cli_argv(
      cmd({"drive", "read", "--bus", "loopback", "--index", "0x1008", "--json"}, SETTLE_DRIVE_EDS));
  ASSERT_EQ(utf8.status, 0) << utf8.out;
  EXPECT_TRUE(nlohmann::json::parse(utf8.stdout_text).at("value").is_string()) << utf8.stdout_text;
}

}  // namespace
