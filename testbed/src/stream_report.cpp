// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/stream_report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>

#include "settle/plant/csv_columns.hpp"

namespace settle::testbed {

namespace {

using Json = nlohmann::ordered_json;

// A measurement that is absent (not aligned, not finite) is null, never a NaN.
Json number_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// Why the CAN residual was not measured (null when it was).
Json note_or_null(const AxisReport& a) { return a.load_measured ? Json(nullptr) : Json(a.load_note); }

long long count(std::uint64_t v) { return static_cast<long long>(v); }

// ... and in text, "n/a".
std::string shown(double v, const char* format) {
  if (!std::isfinite(v)) return "n/a";
  std::array<char, 32> b{};
  std::snprintf(b.data(), b.size(), format, v);
  return b.data();
}

// Axis 1's report: the one the single-axis fields describe (an empty one for a report without axes).
const AxisReport& first_axis(const StreamReport& r) {
  static const AxisReport none{};
  return r.axes.empty() ? none : r.axes.front();
}

Json optional_tick(const std::optional<std::uint64_t>& t) { return t ? Json(count(*t)) : Json(nullptr); }

// The drive's first error EMCY: code (hex), the phrase emcy_text makes, the manufacturer bytes.
Json emcy_json(const std::optional<hal::canopen::EmcyMessage>& e) {
  if (!e) return nullptr;
  char code[8];
  std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(e->error_code));
  return Json{{"code", code}, {"text", emcy_text(*e)}, {"cause", static_cast<long long>(e->data[0])}};
}

// One axis of --axes N in the "axes" array: what identifies it and what was measured on it.
Json axis_json(std::size_t i, const AxisReport& a) {
  return Json{
      {"axis", static_cast<long long>(i + 1)},
      {"node", static_cast<long long>(a.node)},
      {"distance", a.distance},
      {"duration", a.duration},
      {"drive_state", a.drive_state},
      {"drive_failure", a.drive_failure},
      {"drive_emcy", emcy_json(a.drive_emcy)},
      {"evaluation", core::to_string(a.evaluation)},
      {"setpoints", static_cast<long long>(a.setpoints.size())},
      {"move_start_tick", optional_tick(a.move_start_tick)},
      {"move_end_tick", optional_tick(a.move_end_tick)},
      {"feedback_samples", static_cast<long long>(a.feedback.size())},
      {"aligned", a.aligned()},
      {"feedback_overflows", count(a.axis.feedback_overflows)},
      {"feedback_late_ticks", count(a.feedback_late_ticks)},
      {"rpdo_sent", count(a.axis.rpdo_sent)},
      {"step_guard_trips", count(a.axis.step_guard_trips)},
      {"moves_aborted", count(a.axis.moves_aborted)},
      {"max_following_error", count(a.axis.max_following_error)},
      {"load_measured", a.load_measured},
      {"residual_can", number_or_null(a.residual_can.amplitude)},
      {"prv_can_percent", number_or_null(a.residual_can.prv_percent)},
      {"residual_can_note", note_or_null(a)},
      {"residual_offline", number_or_null(a.residual_offline.amplitude)},
      {"agreement", number_or_null(a.agreement)},
      {"fit_rms_can", number_or_null(a.residual_can.fit_rms)},
      {"residual_continuous", number_or_null(a.residual_continuous)},
      {"window_samples", static_cast<long long>(a.window_samples)},
  };
}

}  // namespace

void write_stream_text(const StreamReport& r, std::FILE* out) {
  const AxisReport& a1 = first_axis(r);
  const bool fault = r.session.fault != runtime::AxisFault::none;
  const bool refused = r.session.rejection != runtime::LoopStatus::ok;
  std::fprintf(out, "outcome            %s on %s%s%s%s%s\n", runtime::to_string(r.session.outcome), r.bus.c_str(),
               fault ? ", fault: " : "", fault ? runtime::to_string(r.session.fault) : "",
               refused ? ", refused: " : "", refused ? runtime::to_string(r.session.rejection) : "");
  if (a1.drive_emcy) std::fprintf(out, "drive EMCY         %s\n", emcy_text(*a1.drive_emcy).c_str());
  if (r.start_up_us) {
    std::fprintf(out, "start-up           operation enabled after %.1f ms (tick %llu)\n",
                 static_cast<double>(*r.start_up_us) / 1000.0, static_cast<unsigned long long>(r.session.ready_tick));
  } else {
    std::fprintf(out, "start-up           the drive never reached operation enabled\n");
  }
  std::fprintf(out, "frames             sent %llu, received %llu, tx busy %llu, late feedback ticks %llu, %s\n",
               static_cast<unsigned long long>(r.counters.sent), static_cast<unsigned long long>(r.counters.received),
               static_cast<unsigned long long>(r.counters.tx_busy),
               static_cast<unsigned long long>(a1.feedback_late_ticks),
               a1.aligned() ? "every setpoint applied once, in order" : "FEEDBACK DOES NOT MATCH THE SETPOINTS");
  if (a1.load_measured) {
    std::fprintf(out, "residual (CAN)     %s (PRV %s %%)\n", shown(a1.residual_can.amplitude, "%.9g").c_str(),
                 shown(a1.residual_can.prv_percent, "%.4f").c_str());
  } else {
    std::fprintf(out, "residual (CAN)     %s: the rest is not verified\n", a1.load_note.c_str());
  }
  std::fprintf(out, "residual (offline) %s (PRV %s %%), agreement %s\n",
               shown(a1.residual_offline.amplitude, "%.9g").c_str(),
               shown(a1.residual_offline.prv_percent, "%.4f").c_str(), shown(a1.agreement, "%.3g").c_str());
  if (a1.evaluation != core::Status::ok) {
    std::fprintf(out, "evaluation         %s refused the move: %s\n", to_string(r.scalar), core::to_string(a1.evaluation));
  }
  const std::string within =
      a1.setpoints_vs_double_max_counts ? std::to_string(*a1.setpoints_vs_double_max_counts) : std::string{"n/a"};
  std::fprintf(out,
               "scalar             %s: setpoints within %s counts of double's (%lld differ), residual %s %% "
               "from double's %s\n",
               to_string(r.scalar), within.c_str(), static_cast<long long>(a1.setpoints_differing_from_double),
               shown(a1.residual_vs_double_percent, "%.3g").c_str(), shown(a1.residual_double, "%.9g").c_str());
  if (a1.continuous_simulated) {
    std::fprintf(out, "continuous profile %s (PRV %s %%)\n", shown(a1.residual_continuous, "%.9g").c_str(),
                 shown(a1.prv_continuous_percent, "%.4f").c_str());
  }
  if (r.axes.size() > 1) {
    const std::vector<AxisReport>& axes = r.axes;
    if (r.session.outcome != runtime::SessionOutcome::completed) {
      std::fprintf(out, "axes               the outcome is axis %zu's (node %u)\n", r.session.axis + 1,
                   static_cast<unsigned>(axes[std::min(r.session.axis, axes.size() - 1)].node));
    }
    for (std::size_t i = 0; i < axes.size(); ++i) {
      const AxisReport& a = axes[i];
      const std::string end = a.move_end_tick ? std::to_string(*a.move_end_tick) : std::string{"n/a"};
      std::fprintf(out, "axis %zu (node %3u)  distance %.9g, residual (CAN) %s, (offline) %s, move ends tick %s%s\n",
                   i + 1, static_cast<unsigned>(a.node), a.distance,
                   a.load_measured ? shown(a.residual_can.amplitude, "%.9g").c_str() : a.load_note.c_str(),
                   shown(a.residual_offline.amplitude, "%.9g").c_str(), end.c_str(),
                   a.aligned() ? "" : ", FEEDBACK DOES NOT MATCH THE SETPOINTS");
    }
    const std::string spread = r.end_tick_spread ? std::to_string(*r.end_tick_spread) : std::string{"n/a"};
    const std::string start = r.start_tick_spread ? std::to_string(*r.start_tick_spread) : std::string{"n/a"};
    std::fprintf(out, "axes together      start spread %s ticks, end spread %s ticks; off the line %s counts "
                      "(setpoints), %s counts (feedback)\n",
                 start.c_str(), spread.c_str(), shown(r.line_deviation_setpoints_counts, "%.3g").c_str(),
                 shown(r.line_deviation_feedback_counts, "%.3g").c_str());
  }
  if (r.realtime) {
    const runtime::linux_rt::LatencyHistogram& l = r.timing.latency;
    const runtime::linux_rt::RealtimeSetup& rt = r.timing.realtime;
    const std::string pm_qos = rt.pm_qos ? "held at 0 us" : "not held (" + rt.pm_qos_error + ")";
    std::fprintf(out, "wake-up latency    min %lld p50 %lld p99 %lld max %lld ns, overruns %llu%s; PM QoS %s\n",
                 static_cast<long long>(l.min_ns()), static_cast<long long>(l.quantile_ns(0.5)),
                 static_cast<long long>(l.quantile_ns(0.99)), static_cast<long long>(l.max_ns()),
                 static_cast<unsigned long long>(r.timing.overruns),
                 rt.fifo ? "" : " (SCHED_FIFO not used: pass --rt-priority N as root)", pm_qos.c_str());
  }
}

std::string stream_json(const StreamReport& r) {
  const AxisReport& a1 = first_axis(r);
  const bool have_diff = a1.setpoints_vs_double_max_counts.has_value();
  const runtime::linux_rt::LatencyHistogram& l = r.timing.latency;
  Json j{
      {"status", r.measured() ? "ok" : "error"},
      {"outcome", runtime::to_string(r.session.outcome)},
      {"fault", runtime::to_string(r.session.fault)},
      // Why the loop refused a move (outcome rejected; "ok" otherwise).
      {"rejection", runtime::to_string(r.session.rejection)},
      {"drive_state", a1.drive_state},
      {"drive_failure", a1.drive_failure},
      {"drive_emcy", emcy_json(a1.drive_emcy)},
      // The loop's timeouts this run used (settle stream --timing and the options it presets).
      {"heartbeat_ms", static_cast<long long>(r.heartbeat_ms)},
      {"sdo_timeout_ms", static_cast<long long>(r.sdo_timeout_us / 1000)},
      {"feedback_timeout_periods", static_cast<long long>(r.feedback_timeout_periods)},
      // The session ended with the drive taken out of operation enabled (runtime::release_drives).
      {"drive_released", r.session.released},
      {"bus", r.bus},
      {"profile", core::to_string(a1.profile)},
      {"scalar", to_string(r.scalar)},
      // Why the selected evaluation refused the move ("ok" when it took it), e.g. a profile the
      // fixed-point formats cannot hold.
      {"evaluation", core::to_string(a1.evaluation)},
      {"setpoints", static_cast<long long>(a1.setpoints.size())},
      // Against the double evaluator's setpoints (null when either evaluation refused the move).
      {"setpoints_vs_double_max_counts",
       have_diff ? Json(static_cast<long long>(*a1.setpoints_vs_double_max_counts)) : Json(nullptr)},
      {"setpoints_differing_from_double",
       have_diff ? Json(static_cast<long long>(a1.setpoints_differing_from_double)) : Json(nullptr)},
      {"distance", a1.distance},
      {"duration", a1.duration},
      {"period_us", static_cast<long long>(r.scale.period_us)},
      {"ticks", count(r.session.ticks)},
      // Time to operation enabled (null: never), and its tick.
      {"start_up_ms", r.start_up_us ? Json(static_cast<double>(*r.start_up_us) / 1000.0) : Json(nullptr)},
      {"ready_tick", count(r.session.ready_tick)},
      {"frames_sent", count(r.counters.sent)},
      {"frames_received", count(r.counters.received)},
      {"tx_busy", count(r.counters.tx_busy)},
      {"rx_overflow_drops", count(r.counters.rx_overflow_drops)},
      {"feedback_samples", static_cast<long long>(a1.feedback.size())},
      {"feedback_late_ticks", count(a1.feedback_late_ticks)},
      {"aligned", a1.aligned()},
      {"frames_lost", count(r.frames_lost)},
      {"overruns", count(r.timing.overruns)},
      {"skipped_periods", count(r.session.missed_periods)},
      {"rpdo_sent", count(a1.axis.rpdo_sent)},
      {"step_guard_trips", count(a1.axis.step_guard_trips)},
      {"heartbeat_losses", count(a1.axis.heartbeat_losses)},
      {"emcy_received", count(a1.axis.emcy_received)},
      {"drive_restarts", count(a1.axis.restarts)},
      {"moves_aborted", count(a1.axis.moves_aborted)},
      {"max_following_error", count(a1.axis.max_following_error)},
      {"feedback_overflows", count(a1.axis.feedback_overflows)},
      {"feedback_timeouts", count(a1.axis.feedback_timeouts)},
      {"units_held", count(r.units_held)},
      // Absent (null) when there is nothing to measure: the move did not complete, or the
      // feedback did not match the setpoints.
      // The drive reports a load-side position (false: residual_can, prv_can_percent, agreement and
      // fit_rms_can are null, residual_can_note says why, and rest_measured is false).
      {"load_measured", a1.load_measured},
      {"rest_measured", r.rest_measured()},
      {"residual_can", number_or_null(a1.residual_can.amplitude)},
      {"prv_can_percent", number_or_null(a1.residual_can.prv_percent)},
      {"residual_can_note", note_or_null(a1)},
      {"residual_offline", number_or_null(a1.residual_offline.amplitude)},
      {"prv_offline_percent", number_or_null(a1.residual_offline.prv_percent)},
      {"agreement", number_or_null(a1.agreement)},
      {"residual_double", number_or_null(a1.residual_double)},
      {"residual_vs_double_percent", number_or_null(a1.residual_vs_double_percent)},
      // The same difference in load counts: what it is next to the measurement's resolution.
      {"residual_vs_double_load_counts", number_or_null(a1.residual_vs_double_load_counts)},
      {"fit_rms_can", number_or_null(a1.residual_can.fit_rms)},
      {"residual_continuous", number_or_null(a1.residual_continuous)},
      {"prv_continuous_percent", number_or_null(a1.prv_continuous_percent)},
      {"window_samples", static_cast<long long>(a1.window_samples)},
      {"latency_ns", Json{{"count", count(l.count())},
                          {"min", static_cast<long long>(l.min_ns())},
                          {"p50", static_cast<long long>(l.quantile_ns(0.5))},
                          {"p99", static_cast<long long>(l.quantile_ns(0.99))},
                          {"max", static_cast<long long>(l.max_ns())}}},
      {"realtime", Json{{"sched_fifo", r.timing.realtime.fifo},
                        {"sched_fifo_error", r.timing.realtime.fifo_error},
                        {"mlockall", r.timing.realtime.locked},
                        {"mlockall_error", r.timing.realtime.lock_error},
                        {"pm_qos", r.timing.realtime.pm_qos},
                        {"pm_qos_error", r.timing.realtime.pm_qos_error}}},
  };
  // --axes N: the fields above are axis 1's (and the run's); every axis, axis 1 included, is in
  // "axes", with how they moved together.
  if (r.axes.size() > 1) {
    Json list = Json::array();
    for (std::size_t i = 0; i < r.axes.size(); ++i) list.push_back(axis_json(i, r.axes[i]));
    j["outcome_axis"] = static_cast<long long>(r.session.axis + 1);
    j["axes"] = list;
    j["start_tick_spread"] = optional_tick(r.start_tick_spread);
    j["end_tick_spread"] = optional_tick(r.end_tick_spread);
    j["line_deviation_setpoints_counts"] = number_or_null(r.line_deviation_setpoints_counts);
    j["line_deviation_feedback_counts"] = number_or_null(r.line_deviation_feedback_counts);
  }
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

bool write_tick_csv(const StreamReport& r, std::FILE* out) {
  const AxisReport& a1 = first_axis(r);
  using plant::column;
  const std::string header = column("tick", "index") + "," + column("t", "s") + "," + column("target", "counts") + "," +
                             column("sent", "flag") + "," + column("moving", "flag") + "," + column("move_end", "flag") +
                             "," + column("position_actual", "counts") + "," + column("load_position", "counts") + "," +
                             column("velocity_actual", "drive_velocity_units") + "," +
                             column("tpdo1_received", "count") + "\n";
  bool ok = std::fputs(header.c_str(), out) >= 0;
  for (const runtime::TickRecord& t : a1.log) {
    ok = ok && std::fprintf(out, "%llu,%.6f,%d,%d,%d,%d,%d,%d,%d,%llu\n", static_cast<unsigned long long>(t.tick),
                            static_cast<double>(t.tick) * r.scale.period_s(), t.target, t.sent ? 1 : 0,
                            t.moving ? 1 : 0, t.move_end ? 1 : 0, t.position_actual, t.load_position,
                            t.velocity_actual, static_cast<unsigned long long>(t.feedback_count)) > 0;
  }
  return ok;
}

bool write_feedback_csv(const StreamReport& r, std::FILE* out) {
  const AxisReport& a1 = first_axis(r);
  if (!a1.aligned() || a1.setpoints.empty()) return false;
  const std::vector<std::int32_t>& sp = a1.setpoints;
  const std::size_t o = *a1.alignment;
  const std::size_t pre = std::min<std::size_t>(o, 50);
  using plant::column;
  const std::string header = column("period", "index") + "," + column("t", "s") + "," + column("commanded", "counts") +
                             "," + column("position_can", "counts") + "," + column("load_can", "counts") + "," +
                             column("load_offline", "counts") + "\n";
  bool ok = std::fputs(header.c_str(), out) >= 0;
  for (std::size_t i = o - pre; i < o + a1.replay.feedback.size(); ++i) {
    const long k = static_cast<long>(i) - static_cast<long>(o);
    const auto ku = static_cast<std::size_t>(k);
    const std::int32_t commanded = k < 0 ? sp.front() : (ku < sp.size() ? sp[ku] : sp.back());
    const std::int32_t load_offline = k < 0 ? a1.feedback[i].load_position : a1.replay.feedback[ku].load_position;
    ok = ok && std::fprintf(out, "%ld,%.6f,%d,%d,%d,%d\n", k, static_cast<double>(k + 1) * r.scale.period_s(),
                            commanded, a1.feedback[i].position_actual, a1.feedback[i].load_position, load_offline) > 0;
  }
  return ok;
}

}  // namespace settle::testbed
