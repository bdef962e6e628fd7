// SPDX-License-Identifier: Apache-2.0
// settle drive info|read|write|scan|nmt against the simulated drive in the settle process
// (--bus loopback): what each prints, in text and JSON, checked against hal's drive (its default
// configuration, its strings, its default PDO mapping); SDO aborts with their CiA 301 code and
// meaning and exit 1; values checked against --type before anything is sent (exit 2).
#include <gtest/gtest.h>

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "run_cli.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/sdo_abort.hpp"

namespace {

using settle::test::CliResult;
using settle::test::run_cli;
using settle::test::run_cli_argv;
namespace co = settle::hal::canopen;

nlohmann::json json_of(const CliResult& r) {
  const auto j = nlohmann::json::parse(r.stdout_text, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.out;
  return j.is_discarded() ? nlohmann::json::object() : j;
}

bool has(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

TEST(CliDrive, InfoShowsIdentityStringsAndPdoConfiguration) {
  const co::DriveNodeConfig defaults{};
  const CliResult t = run_cli("drive info --bus loopback --node 3");
  ASSERT_EQ(t.status, 0) << t.out;
  EXPECT_TRUE(has(t.stdout_text, "device type        0x00020192 (profile 402")) << t.stdout_text;
  EXPECT_TRUE(has(t.stdout_text, std::string{"\""} + co::drive_device_name + "\"")) << t.stdout_text;
  EXPECT_TRUE(has(t.stdout_text, std::string{"\""} + co::drive_software_version + "\"")) << t.stdout_text;
  EXPECT_TRUE(has(t.stdout_text, "RPDO1  COB-ID 0x00000203 (enabled), transmission type 1, mapping: 0x6040:0/16 "
                                 "0x607A:0/32\n"))
      << t.stdout_text;
  EXPECT_TRUE(has(t.stdout_text, "RPDO2  absent (0x1401)")) << t.stdout_text;
  EXPECT_TRUE(has(t.stdout_text, "TPDO2  COB-ID 0x00000283 (enabled), transmission type 1, mapping: 0x2000:0/32 "
                                 "0x606C:0/32\n"))
      << t.stdout_text;
  EXPECT_TRUE(has(t.stdout_text, "TPDO4  absent (0x1803)")) << t.stdout_text;

  const CliResult r = run_cli("drive info --bus loopback --node 3 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = json_of(r);
  EXPECT_EQ(j.at("status"), "ok");
  EXPECT_EQ(j.at("node"), 3);
  EXPECT_EQ(j.at("device_type"), co::cia402_device_type);
  EXPECT_EQ(j.at("profile"), 402);
  EXPECT_EQ(j.at("identity").at("vendor_id"), defaults.vendor_id);
  EXPECT_EQ(j.at("identity").at("product_code"), defaults.product_code);
  EXPECT_EQ(j.at("identity").at("revision"), defaults.revision);
  EXPECT_EQ(j.at("identity").at("serial"), defaults.serial);
  EXPECT_EQ(j.at("device_name"), co::drive_device_name);
  EXPECT_EQ(j.at("hardware_version"), co::drive_hardware_version);
  EXPECT_EQ(j.at("software_version"), co::drive_software_version);
  const auto& rpdos = j.at("rpdos");
  const auto& tpdos = j.at("tpdos");
  ASSERT_EQ(rpdos.size(), 4u);
  ASSERT_EQ(tpdos.size(), 4u);
  EXPECT_EQ(rpdos[0].at("cob_id"), 0x203);
  EXPECT_EQ(rpdos[0].at("enabled"), true);
  EXPECT_EQ(rpdos[0].at("transmission_type"), 1);
  EXPECT_EQ(rpdos[0].at("mapping"), nlohmann::json::parse(R"([{"index":24640,"sub":0,"bits":16},
                                                               {"index":24698,"sub":0,"bits":32}])"));
  EXPECT_EQ(tpdos[0].at("mapping"), nlohmann::json::parse(R"([{"index":24641,"sub":0,"bits":16},
                                                               {"index":24676,"sub":0,"bits":32}])"));
  EXPECT_EQ(tpdos[1].at("cob_id"), 0x283);
  // What the drive does not have is absent, not an error.
  for (const std::size_t i : {1U, 2U, 3U}) EXPECT_EQ(rpdos[i].at("present"), false) << i;
  for (const std::size_t i : {2U, 3U}) EXPECT_EQ(tpdos[i].at("present"), false) << i;
  EXPECT_TRUE(j.at("errors").empty()) << j.dump();
}

TEST(CliDrive, ReadsIntegersAndSegmentedStrings) {
  const CliResult name = run_cli("drive read --bus loopback --index 0x1008 --type string");
  ASSERT_EQ(name.status, 0) << name.out;
  EXPECT_EQ(name.stdout_text, std::string{"0x1008:0 = \""} + co::drive_device_name + "\"\n");
  const CliResult id = run_cli("drive read --bus loopback --index 0x1018 --sub 2 --type u32 --json");
  ASSERT_EQ(id.status, 0) << id.out;
  const nlohmann::json j = json_of(id);
  EXPECT_EQ(j.at("value"), co::DriveNodeConfig{}.product_code);
  EXPECT_EQ(j.at("index"), 0x1018);
  EXPECT_EQ(j.at("sub"), 2);
  EXPECT_EQ(j.at("type"), "u32");
  // Signed types read signed: 0x60C2:2, the interpolation period's index, is -3.
  const CliResult ip = run_cli("drive read --bus loopback --index 0x60C2 --sub 2 --type i8");
  ASSERT_EQ(ip.status, 0) << ip.out;
  EXPECT_EQ(ip.stdout_text, "0x60C2:2 = -3 (0xFD)\n");
  // The type must fit the object: a u16 read of the drive's own 32-bit load position (a
  // manufacturer object no standard types, so only the answer's size can tell) is refused, exit 1.
  const CliResult wrong = run_cli("drive read --bus loopback --index 0x2000 --type u16");
  EXPECT_EQ(wrong.status, 1) << wrong.out;
  EXPECT_TRUE(has(wrong.stderr_text, "0x2000:0 holds 4 bytes; --type u16 reads 2")) << wrong.out;
}

TEST(CliDrive, AnAbortPrintsItsCodeAndMeaningAndExitsOne) {
  const CliResult t = run_cli("drive read --bus loopback --index 0x2100 --type u32");
  EXPECT_EQ(t.status, 1) << t.out;
  EXPECT_TRUE(t.stdout_text.empty());
  EXPECT_EQ(t.stderr_text,
            "settle drive read: node 1, 0x2100:0: SDO abort 0x06020000 (object does not exist in the object "
            "dictionary)\n");
  const CliResult j = run_cli("drive read --bus loopback --index 0x1018 --sub 9 --type u32 --json");
  EXPECT_EQ(j.status, 1) << j.out;
  const nlohmann::json d = json_of(j);
  EXPECT_EQ(d.at("status"), "error");
  EXPECT_EQ(d.at("error"), "sdo_abort");
  EXPECT_EQ(d.at("abort_code"), "0x06090011");
  EXPECT_EQ(d.at("meaning"), co::abort_meaning(0x0609'0011));
  // A read-only object refuses a write, an integer one and a string one (segmented download).
  const CliResult ro = run_cli("drive write --bus loopback --index 0x1000 --type u32 --value 5");
  EXPECT_EQ(ro.status, 1) << ro.out;
  EXPECT_TRUE(has(ro.stderr_text, "SDO abort 0x06010002 (attempt to write a read only object)")) << ro.out;
  const CliResult s = run_cli_argv({"drive", "write", "--bus", "loopback", "--index", "0x1008", "--type", "string",
                                    "--value", "a name longer than four bytes"});
  EXPECT_EQ(s.status, 1) << s.out;
  EXPECT_TRUE(has(s.stderr_text, "0x1008:0: SDO abort 0x06010002")) << s.out;
}

TEST(CliDrive, WriteChecksTheValueAgainstTheTypeThenReadsBack) {
  const CliResult w = run_cli("drive write --bus loopback --index 0x6065 --type u32 --value 4294967295 --json");
  ASSERT_EQ(w.status, 0) << w.out;
  EXPECT_EQ(json_of(w).at("read_back"), 4294967295LL);
  const CliResult t = run_cli("drive write --bus loopback --index 0x607A --type i32 --value -2147483648");
  ASSERT_EQ(t.status, 0) << t.out;
  EXPECT_EQ(t.stdout_text, "0x607A:0 = -2147483648 (0x80000000) (written and read back)\n");
  const CliResult h = run_cli("drive write --bus loopback --index 0x6066 --type u16 --value 0x00FF");
  ASSERT_EQ(h.status, 0) << h.out;
  EXPECT_EQ(h.stdout_text, "0x6066:0 = 255 (0x00FF) (written and read back)\n");
  // Out of the type's range: refused before the bus is even opened (this interface does not
  // exist: a value that got that far would exit 1 "cannot open").
  struct Bad {
    const char* type;
    const char* value;
    const char* code;
  };
  const Bad bad[] = {{"u8", "256", "out_of_range"},       {"u8", "-1", "out_of_range"},
                     {"i8", "-129", "out_of_range"},      {"i8", "128", "out_of_range"},
                     {"u16", "65536", "out_of_range"},    {"i16", "0x8000", "out_of_range"},
                     {"u32", "4294967296", "out_of_range"}, {"i32", "2147483648", "out_of_range"},
                     {"u32", "99999999999999999999", "out_of_range"}, {"u8", "nan", "non_finite_input"},
                     {"i32", "-inf", "non_finite_input"}, {"u16", "1.5", "not_an_integer"},
                     {"u16", "0x", "bad_number"},         {"u16", "abc", "bad_number"}};
  for (const Bad& b : bad) {
    SCOPED_TRACE(std::string{b.type} + " " + b.value);
    // 0x2100: an index no standard types, so --type is the only type there is.
    const CliResult r = run_cli_argv({"drive", "write", "--bus", "settle-no-such-can", "--index", "0x2100", "--type",
                                      b.type, "--value", b.value, "--json"});
    EXPECT_EQ(r.status, 2) << r.out;
    const nlohmann::json j = json_of(r);
    EXPECT_EQ(j.at("parameter"), "--value");
    EXPECT_EQ(j.at("error"), b.code);
    EXPECT_TRUE(has(j.at("message").get<std::string>(), std::string{"--type "} + b.type)) << j.dump();
  }
}

TEST(CliDrive, ScanFindsTheDriveAndItsDeviceType) {
  const CliResult t = run_cli("drive scan --bus loopback --timeout-ms 20");
  ASSERT_EQ(t.status, 0) << t.out;
  EXPECT_EQ(t.stdout_text, "1 node(s) answered on loopback\nnode   1  device type 0x00020192 (profile 402)\n");
  const CliResult j = run_cli("drive scan --bus loopback --timeout-ms 20 --json");
  ASSERT_EQ(j.status, 0) << j.out;
  EXPECT_EQ(json_of(j).at("nodes"), nlohmann::json::parse(R"([{"node":1,"device_type":131474}])"));
}

TEST(CliDrive, SubcommandsAndHelp) {
  const CliResult h = run_cli("drive --help");
  EXPECT_EQ(h.status, 0);
  for (const char* s : {"info", "read", "write", "config", "scan", "nmt"}) EXPECT_TRUE(has(h.stdout_text, std::string{"  "} + s)) << s;
  EXPECT_EQ(run_cli("help drive").stdout_text, h.stdout_text);
  EXPECT_EQ(run_cli("help drive read").stdout_text, run_cli("drive read --help").stdout_text);
  EXPECT_EQ(run_cli("help drive read").status, 0);
  for (const char* args : {"drive", "drive frob"}) {
    const CliResult r = run_cli(args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_TRUE(r.stdout_text.empty()) << args;
    EXPECT_TRUE(has(r.stderr_text, "settle: error: drive: ")) << r.stderr_text;
  }
}

// settle drive nmt: each CiA 301 command, and the state the simulated drive's heartbeat (0x1017:
// 100 ms) then carries, in text and JSON; a reset is confirmed by the boot-up message it sends.
TEST(CliDrive, NmtReportsTheStateTheNodesHeartbeatThenCarries) {
  struct Case {
    const char* word;
    unsigned command;
    const char* state;
    unsigned state_byte;
  };
  for (const Case c : {Case{"stop", 0x02, "stopped", 0x04}, Case{"start", 0x01, "operational", 0x05},
                       Case{"preop", 0x80, "pre-operational", 0x7F}, Case{"reset", 0x81, "boot-up", 0x00},
                       Case{"reset-comm", 0x82, "boot-up", 0x00}}) {
    const CliResult j = run_cli(std::string{"drive nmt "} + c.word + " --bus loopback --node 5 --json");
    ASSERT_EQ(j.status, 0) << j.out;
    const nlohmann::json o = json_of(j);
    EXPECT_EQ(o.at("status"), "ok");
    EXPECT_EQ(o.at("bus"), "loopback");
    EXPECT_EQ(o.at("node"), 5);
    EXPECT_EQ(o.at("command"), c.word);
    EXPECT_EQ(o.at("command_byte"), c.command);
    EXPECT_EQ(o.at("confirmed"), true);
    EXPECT_EQ(o.at("state"), c.state) << c.word;
    EXPECT_EQ(o.at("state_byte"), c.state_byte) << c.word;
    // A heartbeat comes within one producer period; a boot-up at once.
    EXPECT_LE(o.at("waited_ms").get<double>(), c.state_byte == 0 ? 0.0 : 100.0) << c.word;
  }
  const CliResult stop = run_cli("drive nmt stop --bus loopback");
  ASSERT_EQ(stop.status, 0) << stop.out;
  EXPECT_EQ(stop.stdout_text, "node 1: NMT stop sent; its heartbeat says stopped (after 100.0 ms)\n");
  const CliResult reset = run_cli("drive nmt reset --bus loopback");
  EXPECT_TRUE(has(reset.stdout_text, "node 1: NMT reset sent; its boot-up message came: the reset is done")) << reset.out;
}

// Within --timeout-ms no heartbeat (the drive's period is 100 ms): the state is not confirmed, and
// the drive's power-on boot-up message, sent before the command, is not taken for an answer.
TEST(CliDrive, NmtWithoutAHeartbeatSaysTheStateWasNotConfirmed) {
  const CliResult j = run_cli("drive nmt stop --bus loopback --timeout-ms 50 --json");
  ASSERT_EQ(j.status, 0) << j.out;
  const nlohmann::json o = json_of(j);
  EXPECT_EQ(o.at("confirmed"), false);
  EXPECT_TRUE(o.at("state").is_null()) << o;
  EXPECT_TRUE(o.at("state_byte").is_null()) << o;
  const CliResult t = run_cli("drive nmt stop --bus loopback --timeout-ms 50");
  ASSERT_EQ(t.status, 0) << t.out;
  EXPECT_TRUE(has(t.stdout_text, "node 1: NMT stop sent; state not confirmed: no heartbeat within 50 ms")) << t.out;
}

// Refused (exit 2, the option or the command named) before the bus is opened: a bus that does
// not exist would otherwise exit 1.
TEST(CliDrive, NmtRefusesABadCommandOrNodeBeforeSending) {
  struct Case {
    const char* args;
    const char* parameter;
    const char* error;
  };
  for (const Case c : {Case{"drive nmt halt --bus settle-no-such-can", "command", "unknown_command"},
                       Case{"drive nmt --bus settle-no-such-can", "command", "missing_command"},
                       Case{"drive nmt START --bus settle-no-such-can", "command", "unknown_command"},
                       Case{"drive nmt stop --bus settle-no-such-can --node 0", "--node", "out_of_range"},
                       Case{"drive nmt stop --bus settle-no-such-can --node 128", "--node", "out_of_range"},
                       Case{"drive nmt stop start --bus settle-no-such-can", "--drive-nmt", "bad_option"}}) {
    const CliResult t = run_cli(c.args);
    EXPECT_EQ(t.status, 2) << c.args << "\n" << t.out;
    EXPECT_TRUE(t.stdout_text.empty()) << c.args;
    EXPECT_TRUE(has(t.stderr_text, std::string{"settle: error: "} + c.parameter + ": ")) << t.stderr_text;
    const CliResult j = run_cli(std::string{c.args} + " --json");
    EXPECT_EQ(j.status, 2) << c.args;
    const nlohmann::json o = json_of(j);
    EXPECT_EQ(o.value("status", ""), "error") << c.args;
    EXPECT_EQ(o.value("parameter", ""), c.parameter) << c.args;
    EXPECT_EQ(o.value("error", ""), c.error) << c.args;
  }
  const CliResult h = run_cli("drive nmt --help");
  ASSERT_EQ(h.status, 0) << h.out;
  EXPECT_TRUE(has(h.stdout_text, "start|stop|preop|reset|reset-comm")) << h.stdout_text;
  EXPECT_TRUE(has(h.stdout_text, "settle drive nmt stop --bus loopback --node 1")) << h.stdout_text;
}

// With --eds the loopback drive is the one the description describes: its own identity and
// strings, and (split_rpdo_drive) its own default mapping, RPDO1 controlword only.
TEST(CliDrive, TheLoopbackDriveIsTheOneTheEdsDescribes) {
  const CliResult t = run_cli(std::string{"drive info --bus loopback --eds "} + SETTLE_EDS_DIR + "/split_rpdo_drive.eds");
  ASSERT_EQ(t.status, 0) << t.out;
  EXPECT_TRUE(has(t.stdout_text, "RPDO1  COB-ID 0x00000201 (enabled), transmission type 1, mapping: 0x6040:0/16 (Controlword)\n"))
      << t.stdout_text;
  EXPECT_TRUE(has(t.stdout_text, "RPDO2  COB-ID 0x00000301 (enabled), transmission type 1, mapping: 0x607A:0/32 (Target position)\n"))
      << t.stdout_text;
  EXPECT_FALSE(has(t.stdout_text, co::drive_device_name)) << t.stdout_text;
}

// drive config: each bundled drive configured and verified from its EDS; what streaming needs
// written and read back (dynamic mapping where the EDS says it is writable, the static one read
// and checked otherwise), the drive left pre-operational; a drive without 0x60C2 refused by name.
TEST(CliDrive, ConfigAppliesAndVerifiesWhatStreamingNeedsForEachBundledDrive) {
  struct Case {
    const char* eds;
    const char* mapping;
    bool changes;  // its default mapping is not what streaming needs
  };
  for (const Case& c : {Case{"settle_drive", "static (read and checked)", false},
                        Case{"split_rpdo_drive", "dynamic", true},
                        Case{"velocity_feedback_drive", "dynamic", true},
                        Case{"static_mapping_drive", "static (read and checked)", false}}) {
    SCOPED_TRACE(c.eds);
    const CliResult r =
        run_cli(std::string{"drive config --bus loopback --json --eds "} + SETTLE_EDS_DIR + "/" + c.eds + ".eds");
    ASSERT_EQ(r.status, 0) << r.out;
    const nlohmann::json j = json_of(r);
    EXPECT_EQ(j["status"], "ok");
    EXPECT_EQ(j["pdo_mapping"], c.mapping);
    EXPECT_EQ(j["objects_changed"].get<int>() > 0, c.changes) << j.dump();
    // The mode and the interpolation period are written whatever the mapping.
    bool mode = false;
    for (const auto& w : j["writes"]) mode = mode || w["object"] == "0x6060:0";
    EXPECT_TRUE(mode) << j.dump();
  }
  const CliResult split = run_cli(std::string{"drive config --bus loopback --eds "} + SETTLE_EDS_DIR +
                                  "/split_rpdo_drive.eds");
  ASSERT_EQ(split.status, 0) << split.out;
  // RPDO1's mapping grows from the controlword alone to controlword + target position.
  EXPECT_TRUE(has(split.stdout_text, "0x1600:0  0x00000001   -> 0x00000002   changed")) << split.stdout_text;
  EXPECT_TRUE(has(split.stdout_text, "0x1600:2  0x00000000   -> 0x607A0020   changed")) << split.stdout_text;

  // A drive without 0x60C2 takes the period from 0x1006: configured without writing 0x60C2, and
  // the object list says the master does without it.
  const CliResult none = run_cli(std::string{"drive config --bus loopback --eds "} + SETTLE_TEST_EDS_DIR +
                                 "/no_interpolation_period_drive.eds --json");
  ASSERT_EQ(none.status, 0) << none.out;
  const nlohmann::json nj = json_of(none);
  for (const auto& w : nj.at("writes")) EXPECT_NE(w.at("object"), "0x60C2:1") << nj.dump();
  bool listed = false;
  for (const auto& o : nj.at("objects")) {
    if (o.at("object") != "0x60C2:1") continue;
    listed = true;
    EXPECT_EQ(o.at("found"), false);
    EXPECT_TRUE(o.at("use").is_null());
    EXPECT_EQ(o.at("without"), "the drive takes the period from 0x1006");
  }
  EXPECT_TRUE(listed) << nj.dump();
}

// Issue 35: CiA 301 asks 0x1006 only of the SYNC producer. A drive whose EDS lacks it (the
// simulated one then lacks it too: writing it would abort 0x06020000) is configured without the
// write, and the report says it was skipped and why.
TEST(CliDrive, ConfigSkips1006WhenTheDrivesEdsHasNone) {
  const std::string eds = std::string{SETTLE_TEST_EDS_DIR} + "/no_cycle_period_drive.eds";
  const CliResult r = run_cli("drive config --bus loopback --json --eds " + eds);
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = json_of(r);
  EXPECT_EQ(j["status"], "ok");
  for (const auto& w : j["writes"]) EXPECT_NE(w["object"], "0x1006:0") << j.dump();
  ASSERT_EQ(j["skipped"].size(), 1U) << j.dump();
  EXPECT_TRUE(has(j["skipped"][0].get<std::string>(), "0x1006:0 not written: the drive's EDS has no 0x1006"))
      << j.dump();
  const CliResult text = run_cli("drive config --bus loopback --eds " + eds);
  ASSERT_EQ(text.status, 0) << text.out;
  EXPECT_TRUE(has(text.stdout_text, "  0x1006:0 not written: the drive's EDS has no 0x1006")) << text.stdout_text;
  // Settle's own drive has 0x1006: written, nothing skipped.
  const CliResult own = run_cli(std::string{"drive config --bus loopback --json --eds "} + SETTLE_DRIVE_EDS);
  ASSERT_EQ(own.status, 0) << own.out;
  const nlohmann::json o = json_of(own);
  bool written = false;
  for (const auto& w : o["writes"]) written = written || w["object"] == "0x1006:0";
  EXPECT_TRUE(written) << o.dump();
  EXPECT_TRUE(o["skipped"].empty()) << o.dump();
}

// Issue 35: settle stream to a drive without a load position (its EDS has no 0x2000) streams and
// checks every setpoint, but does not claim a residual it did not measure.
TEST(CliDrive, StreamToADriveWithoutALoadPositionSaysTheResidualIsNotMeasured) {
  const std::string move = " --bus loopback --plant beam --profile poly345 --distance 0.01 --time 0.5 --settle-time 0.2";
  const CliResult r = run_cli("stream" + move + " --json --eds " + SETTLE_TEST_EDS_DIR + "/no_load_position_drive.eds");
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = json_of(r);
  EXPECT_EQ(j["aligned"], true) << j.dump();
  EXPECT_TRUE(j["residual_can"].is_null()) << j.dump();
  EXPECT_TRUE(j["prv_can_percent"].is_null()) << j.dump();
  EXPECT_EQ(j["rest_measured"], false) << j.dump();
  EXPECT_EQ(j["residual_can_note"], "not measured (the drive reports no load position)") << j.dump();
  const CliResult text = run_cli("stream" + move + " --eds " + SETTLE_TEST_EDS_DIR + "/no_load_position_drive.eds");
  ASSERT_EQ(text.status, 0) << text.out;
  EXPECT_TRUE(has(text.stdout_text, "not measured (the drive reports no load position)")) << text.stdout_text;
  EXPECT_TRUE(has(text.stdout_text, "every setpoint applied once, in order")) << text.stdout_text;
  const CliResult own = run_cli("stream" + move + " --json --eds " + SETTLE_DRIVE_EDS);
  ASSERT_EQ(own.status, 0) << own.out;
  EXPECT_TRUE(json_of(own)["residual_can"].is_number()) << own.out;
}

// SDO moves bytes, not types: a 4-character string fits an UNSIGNED32 object and would be written
// and "read back". Where the standard (or the EDS) types the object, a --type of another type is
// refused before the bus is opened (this interface does not exist: a request that got that far would
// exit 1), and leaving --type out takes the standard's.
TEST(CliDrive, ATypeOtherThanTheObjectsIsRefusedBeforeAnythingIsSent) {
  struct Case {
    const char* index;
    const char* sub;
    const char* type;
    const char* value;
    const char* expect;
  };
  const Case cases[] = {{"0x607F", "0", "string", "ABCD", "CiA 402 makes it UNSIGNED32 (max profile velocity); give --type u32"},
                        {"0x1008", "0", "u32", "1", "CiA 301 makes it VISIBLE_STRING"},
                        {"0x6060", "0", "u8", "8", "CiA 402 makes it INTEGER8 (modes of operation); give --type i8"},
                        {"0x1400", "2", "u16", "1", "CiA 301 makes it UNSIGNED8 (RPDO transmission type)"},
                        {"0x1A05", "0", "u32", "1", "CiA 301 makes it UNSIGNED8 (TPDO mapping: number of mapped objects)"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string{c.index} + ":" + c.sub + " " + c.type);
    for (const char* sub : {"read", "write"}) {
      std::vector<std::string> argv{"drive", sub, "--bus", "settle-no-such-can", "--index", c.index, "--sub", c.sub,
                                    "--type", c.type, "--json"};
      if (std::string{sub} == "write") argv.insert(argv.end(), {"--value", c.value});
      const CliResult r = run_cli_argv(argv);
      EXPECT_EQ(r.status, 2) << r.out;
      const nlohmann::json j = json_of(r);
      EXPECT_EQ(j.at("error"), "type_mismatch") << j.dump();
      EXPECT_EQ(j.at("parameter"), "--type");
      EXPECT_TRUE(has(j.at("message").get<std::string>(), c.expect)) << j.dump();
    }
  }
  // The EDS's type wins over the standard's, and is checked the same way.
  const CliResult e = run_cli(std::string{"drive read --bus settle-no-such-can --index 0x6041 --type u32 --eds "} +
                              SETTLE_DRIVE_EDS);
  EXPECT_EQ(e.status, 2) << e.out;
  EXPECT_TRUE(has(e.stderr_text, "the EDS gives it the data type 0x0006; give --type u16")) << e.out;
  // Without --type the standard's type is used: the write of a string-sized value goes through as an integer.
  const CliResult ok = run_cli("drive write --bus loopback --index 0x607F --value 1234");
  ASSERT_EQ(ok.status, 0) << ok.out;
  EXPECT_EQ(ok.stdout_text, "0x607F:0 = 1234 (0x000004D2) (written and read back)\n");
}

// On a bus, --eds gives read and write their --type: with it the request gets as far as the bus
// (this one does not exist: exit 1); an object the EDS does not describe still needs --type.
TEST(CliDrive, TheEdsGivesTheType) {
  const std::string eds = std::string{" --eds "} + SETTLE_DRIVE_EDS;
  const CliResult typed = run_cli("drive read --bus settle-no-such-can --index 0x6041" + eds);
  EXPECT_EQ(typed.status, 1) << typed.out;
  EXPECT_TRUE(has(typed.stderr_text, "cannot open settle-no-such-can")) << typed.out;
  const CliResult w = run_cli("drive write --bus settle-no-such-can --index 0x6041 --value 70000" + eds);
  EXPECT_EQ(w.status, 2) << w.out;  // 0x6041 is UNSIGNED16 in the EDS: 70000 is out of its range
  EXPECT_TRUE(has(w.stderr_text, "--value: 70000 is out of range")) << w.out;
  EXPECT_TRUE(has(w.stderr_text, "--type u16")) << w.out;
  const CliResult unknown = run_cli("drive read --bus settle-no-such-can --index 0x2999" + eds);
  EXPECT_EQ(unknown.status, 2) << unknown.out;
  EXPECT_TRUE(has(unknown.stderr_text, "--type: required (the EDS gives no type settle drive reads for 0x2999:0)"))
      << unknown.out;
  const CliResult bad = run_cli("drive info --bus settle-no-such-can --eds /nonexistent/settle.eds");
  EXPECT_EQ(bad.status, 2) << bad.out;
  EXPECT_TRUE(has(bad.stderr_text, "settle: error: --eds: /nonexistent/settle.eds")) << bad.out;
}

}  // namespace
