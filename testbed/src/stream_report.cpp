// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/stream_report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>

namespace settle::testbed {

namespace {

using Json = nlohmann::ordered_json;

// A measurement that is absent (not aligned, not finite) is null, never a NaN.
Json number_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// Why the CAN residual was not measured (null when it was).
Json note_or_null(const StreamReport& r) { return r.load_measured ? Json(nullptr) : Json(r.load_note); }

long long count(std::uint64_t v) { return static_cast<long long>(v); }

// ... and in text, "n/a".
std::string shown(double v, const char* format) {
  if (!std::isfinite(v)) return "n/a";
  std::array<char, 32> b{};
  std::snprintf(b.data(), b.size(), format, v);
  return b.data();
}

// Every axis of the run, axis 1 first.
std::vector<const StreamReport*> axes_of(const StreamReport& r) {
  std::vector<const StreamReport*> v{&r};
  for (const StreamReport& a : r.more_axes) v.push_back(&a);
  return v;
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
Json axis_json(std::size_t i, const StreamReport& a) {
  return Json{
      {"axis", static_cast<long long>(i + 1)},
      {"node", static_cast<long long>(a.node)},
      {"distance", a.distance},
      {"move_time", a.move_time},
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
  const bool fault = r.session.fault != runtime::AxisFault::none;
  const bool refused = r.session.rejection != runtime::LoopStatus::ok;
  std::fprintf(out, "outcome            %s on %s%s%s%s%s\n", runtime::to_string(r.session.outcome), r.bus.c_str(),
               fault ? ", fault: " : "", fault ? runtime::to_string(r.session.fault) : "",
               refused ? ", refused: " : "", refused ? runtime::to_string(r.session.rejection) : "");
  if (r.drive_emcy) std::fprintf(out, "drive EMCY         %s\n", emcy_text(*r.drive_emcy).c_str());
  if (r.start_up_us) {
    std::fprintf(out, "start-up           operation enabled after %.1f ms (tick %llu)\n",
                 static_cast<double>(*r.start_up_us) / 1000.0, static_cast<unsigned long long>(r.session.ready_tick));
  } else {
    std::fprintf(out, "start-up           the drive never reached operation enabled\n");
  }
  std::fprintf(out, "frames             sent %llu, received %llu, tx busy %llu, late feedback ticks %llu, %s\n",
               static_cast<unsigned long long>(r.counters.sent), static_cast<unsigned long long>(r.counters.received),
               static_cast<unsigned long long>(r.counters.tx_busy),
               static_cast<unsigned long long>(r.feedback_late_ticks),
               r.aligned() ? "every setpoint applied once, in order" : "FEEDBACK DOES NOT MATCH THE SETPOINTS");
  if (r.load_measured) {
    std::fprintf(out, "residual (CAN)     %s (PRV %s %%)\n", shown(r.residual_can.amplitude, "%.9g").c_str(),
                 shown(r.residual_can.prv_percent, "%.4f").c_str());
  } else {
    std::fprintf(out, "residual (CAN)     %s: the rest is not verified\n", r.load_note.c_str());
  }
  std::fprintf(out, "residual (offline) %s (PRV %s %%), agreement %s\n",
               shown(r.residual_offline.amplitude, "%.9g").c_str(),
               shown(r.residual_offline.prv_percent, "%.4f").c_str(), shown(r.agreement, "%.3g").c_str());
  if (r.evaluation != core::Status::ok) {
    std::fprintf(out, "evaluation         %s refused the move: %s\n", to_string(r.scalar), core::to_string(r.evaluation));
  }
  const std::string within =
      r.setpoints_vs_double_max_counts ? std::to_string(*r.setpoints_vs_double_max_counts) : std::string{"n/a"};
  std::fprintf(out,
               "scalar             %s: setpoints within %s counts of double's (%lld differ), residual %s %% "
               "from double's %s\n",
               to_string(r.scalar), within.c_str(), static_cast<long long>(r.setpoints_differing_from_double),
               shown(r.residual_vs_double_percent, "%.3g").c_str(), shown(r.residual_double, "%.9g").c_str());
  if (r.continuous_simulated) {
    std::fprintf(out, "continuous profile %s (PRV %s %%)\n", shown(r.residual_continuous, "%.9g").c_str(),
                 shown(r.prv_continuous_percent, "%.4f").c_str());
  }
  if (!r.more_axes.empty()) {
    const std::vector<const StreamReport*> axes = axes_of(r);
    if (r.session.outcome != runtime::SessionOutcome::completed) {
      std::fprintf(out, "axes               the outcome is axis %zu's (node %u)\n", r.session.axis + 1,
                   static_cast<unsigned>(axes[std::min(r.session.axis, axes.size() - 1)]->node));
    }
    for (std::size_t i = 0; i < axes.size(); ++i) {
      const StreamReport& a = *axes[i];
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
  const bool have_diff = r.setpoints_vs_double_max_counts.has_value();
  const runtime::linux_rt::LatencyHistogram& l = r.timing.latency;
  Json j{
      {"status", r.measured() ? "ok" : "error"},
      {"outcome", runtime::to_string(r.session.outcome)},
      {"fault", runtime::to_string(r.session.fault)},
      // Why the loop refused a move (outcome rejected; "ok" otherwise).
      {"rejection", runtime::to_string(r.session.rejection)},
      {"drive_state", r.drive_state},
      {"drive_failure", r.drive_failure},
      {"drive_emcy", emcy_json(r.drive_emcy)},
      // The loop's timeouts this run used (settle stream --timing and the options it presets).
      {"heartbeat_ms", static_cast<long long>(r.heartbeat_ms)},
      {"sdo_timeout_ms", static_cast<long long>(r.sdo_timeout_us / 1000)},
      {"feedback_timeout_periods", static_cast<long long>(r.feedback_timeout_periods)},
      // The session ended with the drive taken out of operation enabled (runtime::release_drives).
      {"drive_released", r.session.released},
      {"bus", r.bus},
      {"profile", core::to_string(r.profile)},
      {"scalar", to_string(r.scalar)},
      // Why the selected evaluation refused the move ("ok" when it took it), e.g. a profile the
      // fixed-point formats cannot hold.
      {"evaluation", core::to_string(r.evaluation)},
      {"setpoints", static_cast<long long>(r.setpoints.size())},
      // Against the double evaluator's setpoints (null when either evaluation refused the move).
      {"setpoints_vs_double_max_counts",
       have_diff ? Json(static_cast<long long>(*r.setpoints_vs_double_max_counts)) : Json(nullptr)},
      {"setpoints_differing_from_double",
       have_diff ? Json(static_cast<long long>(r.setpoints_differing_from_double)) : Json(nullptr)},
      {"distance", r.distance},
      {"move_time", r.move_time},
      {"period_us", static_cast<long long>(r.scale.period_us)},
      {"ticks", count(r.session.ticks)},
      // Time to operation enabled (null: never), and its tick.
      {"start_up_ms", r.start_up_us ? Json(static_cast<double>(*r.start_up_us) / 1000.0) : Json(nullptr)},
      {"ready_tick", count(r.session.ready_tick)},
      {"frames_sent", count(r.counters.sent)},
      {"frames_received", count(r.counters.received)},
      {"tx_busy", count(r.counters.tx_busy)},
      {"rx_overflow_drops", count(r.counters.rx_overflow_drops)},
      {"feedback_samples", static_cast<long long>(r.feedback.size())},
      {"feedback_late_ticks", count(r.feedback_late_ticks)},
      {"aligned", r.aligned()},
      {"frames_lost", count(r.frames_lost)},
      {"overruns", count(r.timing.overruns)},
      {"skipped_periods", count(r.session.missed_periods)},
      {"rpdo_sent", count(r.axis.rpdo_sent)},
      {"step_guard_trips", count(r.axis.step_guard_trips)},
      {"heartbeat_losses", count(r.axis.heartbeat_losses)},
      {"emcy_received", count(r.axis.emcy_received)},
      {"drive_restarts", count(r.axis.restarts)},
      {"moves_aborted", count(r.axis.moves_aborted)},
      {"max_following_error", count(r.axis.max_following_error)},
      {"feedback_overflows", count(r.axis.feedback_overflows)},
      {"feedback_timeouts", count(r.axis.feedback_timeouts)},
      {"units_held", count(r.units_held)},
      // Absent (null) when there is nothing to measure: the move did not complete, or the
      // feedback did not match the setpoints.
      // The drive reports a load-side position (false: residual_can, prv_can_percent, agreement and
      // fit_rms_can are null, residual_can_note says why, and rest_measured is false).
      {"load_measured", r.load_measured},
      {"rest_measured", r.rest_measured()},
      {"residual_can", number_or_null(r.residual_can.amplitude)},
      {"prv_can_percent", number_or_null(r.residual_can.prv_percent)},
      {"residual_can_note", note_or_null(r)},
      {"residual_offline", number_or_null(r.residual_offline.amplitude)},
      {"prv_offline_percent", number_or_null(r.residual_offline.prv_percent)},
      {"agreement", number_or_null(r.agreement)},
      {"residual_double", number_or_null(r.residual_double)},
      {"residual_vs_double_percent", number_or_null(r.residual_vs_double_percent)},
      // The same difference in load counts: what it is next to the measurement's resolution.
      {"residual_vs_double_load_counts", number_or_null(r.residual_vs_double_load_counts)},
      {"fit_rms_can", number_or_null(r.residual_can.fit_rms)},
      {"residual_continuous", number_or_null(r.residual_continuous)},
      {"prv_continuous_percent", number_or_null(r.prv_continuous_percent)},
      {"window_samples", static_cast<long long>(r.window_samples)},
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
  if (!r.more_axes.empty()) {
    const std::vector<const StreamReport*> axes = axes_of(r);
    Json list = Json::array();
    for (std::size_t i = 0; i < axes.size(); ++i) list.push_back(axis_json(i, *axes[i]));
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
  bool ok = std::fprintf(out, "tick,t,target,sent,moving,move_end,position_actual,load_position,velocity_actual,"
                              "feedback_count\n") > 0;
  for (const runtime::TickRecord& t : r.log) {
    ok = ok && std::fprintf(out, "%llu,%.6f,%d,%d,%d,%d,%d,%d,%d,%llu\n", static_cast<unsigned long long>(t.tick),
                            static_cast<double>(t.tick) * r.scale.period_s(), t.target, t.sent ? 1 : 0,
                            t.moving ? 1 : 0, t.move_end ? 1 : 0, t.position_actual, t.load_position,
                            t.velocity_actual, static_cast<unsigned long long>(t.feedback_count)) > 0;
  }
  return ok;
}

bool write_feedback_csv(const StreamReport& r, std::FILE* out) {
  if (!r.aligned() || r.setpoints.empty()) return false;
  const std::vector<std::int32_t>& sp = r.setpoints;
  const std::size_t o = *r.alignment;
  const std::size_t pre = std::min<std::size_t>(o, 50);
  bool ok = std::fprintf(out, "period,t,commanded,position_can,load_can,load_offline\n") > 0;
  for (std::size_t i = o - pre; i < o + r.replay.feedback.size(); ++i) {
    const long k = static_cast<long>(i) - static_cast<long>(o);
    const auto ku = static_cast<std::size_t>(k);
    const std::int32_t commanded = k < 0 ? sp.front() : (ku < sp.size() ? sp[ku] : sp.back());
    const std::int32_t load_offline = k < 0 ? r.feedback[i].load_position : r.replay.feedback[ku].load_position;
    ok = ok && std::fprintf(out, "%ld,%.6f,%d,%d,%d,%d\n", k, static_cast<double>(k + 1) * r.scale.period_s(),
                            commanded, r.feedback[i].position_actual, r.feedback[i].load_position, load_offline) > 0;
  }
  return ok;
}

}  // namespace settle::testbed
