// SPDX-License-Identifier: Apache-2.0
// The stream reporters on hand-made reports: the text summary line by line, the JSON document's
// field names (an interface: settle demo, tests/e2e and the examples parse them) and its
// nulls, and both CSV files row by row.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "settle/testbed/stream_report.hpp"

namespace settle::testbed {
namespace {

// What a writer wrote, through a temporary file, and what it returned (true for a void writer).
struct Written {
  bool ok{true};
  std::string text;
};
template <typename Writer>
Written captured(Writer&& write) {
  Written w{};
  std::FILE* f = std::tmpfile();
  EXPECT_NE(f, nullptr);
  if (f == nullptr) return w;
  if constexpr (std::is_void_v<decltype(write(f))>) {
    write(f);
  } else {
    w.ok = write(f);
  }
  std::rewind(f);
  for (int c = std::fgetc(f); c != EOF; c = std::fgetc(f)) w.text.push_back(static_cast<char>(c));
  std::fclose(f);
  return w;
}

// A real-time run that completed and aligned, every measurement present.
StreamReport completed_run() {
  StreamReport r{};
  r.axes.resize(1);
  r.bus = "vcan9";
  r.realtime = true;
  r.axes[0].profile = core::ProfileKind::scurve;
  r.scalar = StreamScalar::single_precision;
  r.axes[0].distance = 0.05;
  r.axes[0].duration = 0.3;
  r.scale = {1e6, 500};
  r.session.outcome = runtime::SessionOutcome::completed;
  r.session.ticks = 42;
  r.counters.sent = 10;
  r.counters.received = 12;
  r.counters.tx_busy = 1;
  r.axes[0].feedback_late_ticks = 2;
  r.axes[0].alignment = 0;
  r.axes[0].setpoints = {0, 1, 2};
  r.axes[0].setpoints_vs_double_max_counts = 1;
  r.axes[0].setpoints_differing_from_double = 3;
  r.axes[0].residual_can = {0.000123456789, 1.5, 10, 0.25};
  r.axes[0].residual_offline = {0.000123456788, 1.49999, 10, 0.25};
  r.axes[0].agreement = 1e-12;
  r.axes[0].residual_double = 0.0001234;
  r.axes[0].residual_vs_double_percent = 0.25;
  r.axes[0].residual_vs_double_load_counts = 0.5;
  r.axes[0].continuous_simulated = true;
  r.axes[0].residual_continuous = 0.00012;
  r.axes[0].prv_continuous_percent = 1.45;
  r.axes[0].window_samples = 10;
  r.timing.latency.add(1500);
  r.timing.overruns = 4;
  r.start_up_us = 123'400;
  r.session.ready_tick = 123;
  r.timing.realtime.pm_qos = true;
  return r;
}

// In-process, halted by the feedback watchdog, with an evaluation that refused the move.
StreamReport refused_run() {
  StreamReport r{};
  r.axes.resize(1);
  r.bus = "loopback (in-process, virtual time)";
  r.scalar = StreamScalar::fixed_point;
  r.session.outcome = runtime::SessionOutcome::feedback_timeout;
  r.session.fault = runtime::AxisFault::feedback_timeout;
  r.axes[0].evaluation = core::Status::transition_shorter_than_tick;
  r.axes[0].residual_can.amplitude = r.axes[0].residual_can.prv_percent = NAN;
  r.axes[0].residual_offline.amplitude = r.axes[0].residual_offline.prv_percent = NAN;
  r.axes[0].agreement = r.axes[0].residual_double = r.axes[0].residual_vs_double_percent = r.axes[0].residual_vs_double_load_counts = NAN;
  r.axes[0].residual_continuous = r.axes[0].prv_continuous_percent = NAN;
  return r;
}

TEST(StreamReportText, ACompletedRealTimeRun) {
  EXPECT_EQ(captured([](std::FILE* f) { write_stream_text(completed_run(), f); }).text,
            "outcome            completed on vcan9\n"
            "start-up           operation enabled after 123.4 ms (tick 123)\n"
            "frames             sent 10, received 12, tx busy 1, late feedback ticks 2, every setpoint applied once, "
            "in order\n"
            "residual (CAN)     0.000123456789 (PRV 1.5000 %)\n"
            "residual (offline) 0.000123456788 (PRV 1.5000 %), agreement 1e-12\n"
            "scalar             float: setpoints within 1 counts of double's (3 differ), residual 0.25 % from double's "
            "0.0001234\n"
            "continuous profile 0.00012 (PRV 1.4500 %)\n"
            "wake-up latency    min 1500 p50 2000 p99 2000 max 1500 ns, overruns 4 (SCHED_FIFO not used: pass "
            "--rt-priority N as root); PM QoS held at 0 us\n");
}

TEST(StreamReportText, APmQosRequestNotHeldSaysWhy) {
  StreamReport r = completed_run();
  r.timing.realtime.pm_qos = false;
  r.timing.realtime.pm_qos_error = "Permission denied";
  const std::string text = captured([&](std::FILE* f) { write_stream_text(r, f); }).text;
  EXPECT_NE(text.find("; PM QoS not held (Permission denied)\n"), std::string::npos) << text;
}

TEST(StreamReportText, AbsentMeasurementsAreNotAvailableNeverNan) {
  EXPECT_EQ(captured([](std::FILE* f) { write_stream_text(refused_run(), f); }).text,
            "outcome            feedback_timeout on loopback (in-process, virtual time), fault: feedback_timeout\n"
            "start-up           the drive never reached operation enabled\n"
            "frames             sent 0, received 0, tx busy 0, late feedback ticks 0, FEEDBACK DOES NOT MATCH THE "
            "SETPOINTS\n"
            "residual (CAN)     n/a (PRV n/a %)\n"
            "residual (offline) n/a (PRV n/a %), agreement n/a\n"
            "evaluation         fixed refused the move: transition_shorter_than_tick\n"
            "scalar             fixed: setpoints within n/a counts of double's (0 differ), residual n/a % from "
            "double's n/a\n");
}

TEST(StreamReportJson, FieldNamesInOrder) {
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(stream_json(completed_run()));
  std::vector<std::string> names;
  for (const auto& item : j.items()) names.push_back(item.key());
  const std::vector<std::string> want{
      "status", "outcome", "fault", "rejection", "drive_state", "drive_failure", "drive_emcy", "heartbeat_ms", "sdo_timeout_ms",
      "feedback_timeout_periods", "drive_released", "bus", "profile", "scalar", "evaluation",
      "setpoints", "setpoints_vs_double_max_counts", "setpoints_differing_from_double", "distance", "duration",
      "period_us", "ticks", "start_up_ms", "ready_tick", "frames_sent", "frames_received", "tx_busy", "rx_overflow_drops", "feedback_samples",
      "feedback_late_ticks", "aligned", "frames_lost", "overruns", "skipped_periods", "rpdo_sent",
      "step_guard_trips", "heartbeat_losses", "emcy_received", "drive_restarts", "moves_aborted",
      "max_following_error", "feedback_overflows", "feedback_timeouts", "units_held", "load_measured",
      "rest_measured", "residual_can", "prv_can_percent", "residual_can_note", "residual_offline", "prv_offline_percent", "agreement", "residual_double",
      "residual_vs_double_percent", "residual_vs_double_load_counts", "fit_rms_can", "residual_continuous",
      "prv_continuous_percent", "window_samples", "latency_ns", "realtime"};
  EXPECT_EQ(names, want);
}

TEST(StreamReportJson, ACompletedRunIsOkWithItsNumbers) {
  const nlohmann::json j = nlohmann::json::parse(stream_json(completed_run()));
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["outcome"], "completed");
  EXPECT_EQ(j["bus"], "vcan9");
  EXPECT_EQ(j["profile"], "scurve");
  EXPECT_EQ(j["scalar"], "float");
  EXPECT_EQ(j["setpoints"], 3);
  EXPECT_EQ(j["setpoints_vs_double_max_counts"], 1);
  EXPECT_EQ(j["setpoints_differing_from_double"], 3);
  EXPECT_EQ(j["period_us"], 500);
  EXPECT_EQ(j["ticks"], 42);
  EXPECT_EQ(j["aligned"], true);
  EXPECT_EQ(j["residual_can"], 0.000123456789);
  EXPECT_EQ(j["fit_rms_can"], 0.25);
  EXPECT_EQ(j["residual_vs_double_load_counts"], 0.5);
  EXPECT_EQ(j["residual_continuous"], 0.00012);
  EXPECT_EQ(j["window_samples"], 10);
  EXPECT_EQ(j["latency_ns"]["count"], 1);
  EXPECT_EQ(j["latency_ns"]["min"], 1500);
  EXPECT_EQ(j["overruns"], 4);
  EXPECT_EQ(j["realtime"]["pm_qos"], true);
  EXPECT_EQ(j["start_up_ms"], 123.4);
  EXPECT_EQ(j["ready_tick"], 123);
  EXPECT_EQ(j["realtime"]["pm_qos_error"], "");
}

TEST(StreamReportJson, AbsentMeasurementsAreNullAndTheStatusAnError) {
  const nlohmann::json j = nlohmann::json::parse(stream_json(refused_run()));
  EXPECT_EQ(j["status"], "error");
  EXPECT_EQ(j["evaluation"], "transition_shorter_than_tick");
  for (const char* k : {"setpoints_vs_double_max_counts", "setpoints_differing_from_double", "residual_can",
                        "prv_can_percent", "residual_offline", "agreement", "residual_double",
                        "residual_vs_double_percent", "residual_continuous", "prv_continuous_percent"}) {
    EXPECT_TRUE(j[k].is_null()) << k;
  }
  // Completed and aligned, but one measurement missing: still not a success.
  StreamReport r = completed_run();
  r.axes[0].residual_continuous = NAN;
  EXPECT_EQ(nlohmann::json::parse(stream_json(r))["status"], "error");
}

TEST(StreamReportJson, AnInterfaceNameThatIsNotUtf8IsReplaced) {
  StreamReport r = completed_run();
  r.bus = "can\xff";
  const nlohmann::json j = nlohmann::json::parse(stream_json(r));
  EXPECT_EQ(j["bus"], "can\xef\xbf\xbd");  // U+FFFD
}

TEST(StreamReportCsv, OneRowPerTick) {
  StreamReport r = completed_run();  // 500 us period
  runtime::TickRecord a{};
  a.tick = 0;
  runtime::TickRecord b{};
  b.tick = 3;
  b.target = -7;
  b.sent = true;
  b.moving = true;
  b.move_end = true;
  b.position_actual = 5;
  b.load_position = 6;
  b.velocity_actual = -8;
  b.feedback_count = 2;
  r.axes[0].log = {a, b};
  const Written w = captured([&](std::FILE* f) { return write_tick_csv(r, f); });
  EXPECT_TRUE(w.ok);
  EXPECT_EQ(w.text,
            "tick_index,t_s,target_counts,sent_flag,moving_flag,move_end_flag,position_actual_counts,"
            "load_position_counts,velocity_actual_drive_velocity_units,tpdo1_received_count\n"
            "0,0.000000,0,0,0,0,0,0,0,0\n"
            "3,0.001500,-7,1,1,1,5,6,-8,2\n");
}

TEST(StreamReportCsv, FeedbackAlignedWithTheReplay) {
  StreamReport r{};
  r.axes.resize(1);
  r.scale = {1e6, 1000};
  r.axes[0].setpoints = {0, 5, 10};
  r.axes[0].alignment = 2;  // the replay's first period is the third feedback sample
  for (std::int32_t i = 0; i < 6; ++i) r.axes[0].feedback.push_back({100 + i, 200 + i, 0});  // position, load, velocity
  for (std::int32_t i = 0; i < 4; ++i) r.axes[0].replay.feedback.push_back({0, 0, 300 + i});  // position, velocity, load
  const Written w = captured([&](std::FILE* f) { return write_feedback_csv(r, f); });
  EXPECT_TRUE(w.ok);
  EXPECT_EQ(w.text,
            "period_index,t_s,commanded_counts,position_can_counts,load_can_counts,load_offline_counts\n"
            "-2,-0.001000,0,100,200,200\n"
            "-1,0.000000,0,101,201,201\n"
            "0,0.001000,0,102,202,300\n"
            "1,0.002000,5,103,203,301\n"
            "2,0.003000,10,104,204,302\n"
            "3,0.004000,10,105,205,303\n");
  r.axes[0].alignment.reset();
  EXPECT_FALSE(write_feedback_csv(r, stdout));  // nothing to align: nothing written
}

}  // namespace
}  // namespace settle::testbed
