// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/stream.hpp"
#include "settle/testbed/clocked_bus.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "settle/core/limits.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/runtime/evaluation.hpp"
#include "settle/runtime/setpoint_sequence.hpp"
#include "settle/testbed/simulated_drive.hpp"
#include "settle/plant/command.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/online_command.hpp"
#include "settle/plant/simulate.hpp"

namespace settle::testbed {

const char* to_string(StreamScalar s) noexcept {
  switch (s) {
    case StreamScalar::double_precision: return "double";
    case StreamScalar::single_precision: return "float";
    case StreamScalar::fixed_point: return "fixed";
  }
  return "?";
}

bool AxisReport::measured() const noexcept {
  const bool load_ok = !load_measured || (std::isfinite(residual_can.amplitude) && std::isfinite(agreement));
  return aligned() && load_ok && std::isfinite(residual_offline.amplitude) && std::isfinite(residual_continuous);
}

bool StreamReport::measured() const noexcept {
  const bool together =
      axes.size() < 2 || (start_tick_spread && end_tick_spread && std::isfinite(line_deviation_setpoints_counts) &&
                          std::isfinite(line_deviation_feedback_counts));
  return !axes.empty() && session.outcome == runtime::SessionOutcome::completed && together &&
         std::all_of(axes.begin(), axes.end(), [](const AxisReport& a) { return a.measured(); });
}

bool StreamReport::rest_measured() const noexcept {
  return measured() && std::all_of(axes.begin(), axes.end(), [](const AxisReport& a) { return a.load_measured; });
}

namespace {

// A double NaN: the NAN macro is a float, and assigning it promotes it.
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The loop for each evaluation (--scalar): its scalar, up to core::kMaxAxes axes (--axes), four
// queued moves, online changes, and a second of feedback per axis at 1 kHz (a host process held
// off the CPU for longer than a microcontroller's 16 periods still loses no sample).
template <typename Scalar, typename Evaluation>
using LoopOf = runtime::ServoLoop<Scalar, core::kMaxAxes, 4, Evaluation, hal::CanBus, true, 1024>;
// Drained every tick, the log cannot overflow then: a tick takes at most kMaxFramesPerTick frames,
// two of them a sample. (A dropped sample would break the period-by-period correspondence the
// measurement relies on, unseen where the positions are at rest.)
static_assert(1024 >= LoopOf<double, runtime::FloatEvaluation<double>>::kMaxFramesPerTick);

// The integer targets an evaluation produces for a move, tick by tick from 0 to the move's end,
// and with a change the move's up to the switch, then the blend's to its end: what the loop
// streams (runtime::stream_setpoints, its switch rule), offline. The replay's setpoints for every
// scalar come from here, and so do the double evaluator's they are compared with. Not ok when the
// evaluation refuses the move or the blend (the loop refuses them too) or it has more than kMaxSamples.
template <typename Evaluation>
core::Status evaluated_setpoints(const StreamSpec& spec, const StreamAxis& axis, std::vector<std::int32_t>& out) {
  const core::AxisScale& scale = spec.drive.scale;
  out.clear();
  auto slot = std::make_unique<typename Evaluation::Stored>();  // not movable: the stream refers into it
  if (const core::Status st = Evaluation::prepare(axis.move, scale, *slot); st != core::Status::ok) return st;
  auto blend = std::make_unique<typename Evaluation::BlendStored>();
  runtime::SetpointSwitch<Evaluation> change{blend.get(), 0};
  const bool blends = axis.change && !axis.change->finish;
  if (blends) {
    if (const core::Status st = Evaluation::prepare(axis.change->blend, scale, *blend); st != core::Status::ok) return st;
    change.at = static_cast<std::int32_t>(std::llround(axis.change->at / scale.period_s()));
  }
  const runtime::SetpointSequence seq = runtime::stream_setpoints<Evaluation>(
      *slot, 0, &change, blends ? 1 : 0, plant::kMaxSamples, [&](std::int32_t sp) { out.push_back(sp); });
  return seq.ended ? core::Status::ok : core::Status::duration_does_not_fit;
}

core::Status changed_setpoints(StreamScalar scalar, const StreamSpec& spec, const StreamAxis& axis,
                               std::vector<std::int32_t>& out) {
  switch (scalar) {
    case StreamScalar::single_precision: return evaluated_setpoints<runtime::FloatEvaluation<float>>(spec, axis, out);
    case StreamScalar::fixed_point: return evaluated_setpoints<runtime::PolyFixedEvaluation>(spec, axis, out);
    case StreamScalar::double_precision: break;
  }
  return evaluated_setpoints<runtime::FloatEvaluation<double>>(spec, axis, out);
}

// Whether the evaluation takes the spec's move and, with a change that blends, the blend (what the
// loop's submit() and service() prepare), without streaming them.
template <typename Evaluation>
StreamRefusal evaluation_takes(const StreamSpec& spec, const StreamAxis& axis) {
  StreamRefusal r{};
  auto slot = std::make_unique<typename Evaluation::Stored>();
  r.why = Evaluation::prepare(axis.move, spec.drive.scale, *slot);
  if (r.why == core::Status::ok && axis.change && !axis.change->finish) {
    auto blend = std::make_unique<typename Evaluation::BlendStored>();
    r.why = Evaluation::prepare(axis.change->blend, spec.drive.scale, *blend);
    r.in_change = r.why != core::Status::ok;
  }
  if (r.why != core::Status::ok) r.status = runtime::LoopStatus::evaluation_refused;
  return r;
}

// How long the command lasts: the move, or the move to the switch and then the blend.
double command_duration(const StreamAxis& axis) {
  return axis.change && !axis.change->finish ? axis.change->at + axis.change->blend.duration()
                                             : axis.move.duration();
}

}  // namespace

std::string emcy_text(const hal::canopen::EmcyMessage& m) {
  namespace code = hal::canopen::emcy_code;
  namespace cause = hal::canopen::emcy_cause;
  const char* meaning = "an error the drive defines";
  switch (m.error_code) {
    case code::generic: meaning = "generic error"; break;
    case code::communication: meaning = "communication"; break;
    case code::can_overrun: meaning = "CAN overrun"; break;
    case code::life_guard: meaning = "life guard: the master's heartbeat lost"; break;
    case code::pdo_length: meaning = "a PDO shorter than its mapping"; break;
    case code::pdo_length_exceeded: meaning = "a PDO longer than its mapping"; break;
    case code::sync_data_length: meaning = "a SYNC of the wrong length"; break;
    case code::rpdo_timeout: meaning = "RPDO timeout"; break;
    case code::velocity: meaning = "a setpoint step beyond the velocity limit 0x607F"; break;
    case code::following_error: meaning = "following error"; break;
    case code::reference_limit: meaning = "software position limit"; break;
    default: break;
  }
  const char* rule = nullptr;
  switch (m.data[0]) {
    case cause::step_limit: rule = "a setpoint step refused"; break;
    case cause::following_error: rule = "the following error window exceeded"; break;
    case cause::sync_counter: rule = "the SYNC counter repeated or skipped"; break;
    case cause::sync_length: rule = "a SYNC without the counter 0x1019 asks for"; break;
    case cause::sync_rate: rule = "SYNCs faster than the period 0x1006"; break;
    case cause::nmt_command: rule = "a third party's NMT command while enabled"; break;
    case cause::heartbeat: rule = "the master's heartbeat (0x1016) not heard"; break;
    case cause::sync_loss: rule = "SYNC lost: no SYNC for more periods than 0x2001 allows"; break;
    case cause::rpdo_loss: rule = "RPDO lost: no setpoint for more periods than 0x2001 allows"; break;
    default: break;
  }
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%04X", static_cast<unsigned>(m.error_code));
  return std::string{"EMCY "} + hex + " (" + meaning + (rule != nullptr ? std::string{": "} + rule : std::string{}) + ")";
}

std::string start_up_failure_text(const hal::canopen::RemoteDriveFailure& f) {
  static constexpr std::array<const char*, 5> sdo{"idle", "busy", "done", "aborted", "timed out"};
  std::array<char, 96> text{};
  if (f.enable_timeout) {
    std::snprintf(text.data(), text.size(), "the drive did not reach operation enabled in time");
  } else if (f.wrong_value) {
    // wrong_value (a write read back as another value), not_cia402, wrong_identity, mode_not_applied
    std::snprintf(text.data(), text.size(), "0x%04X:%u %s: expected 0x%X, read 0x%X", f.index,
                  static_cast<unsigned>(f.sub), hal::canopen::to_string(f.error), static_cast<unsigned>(f.expected),
                  static_cast<unsigned>(f.actual));
  } else if (f.error == hal::canopen::StartupError::plan_too_long) {
    std::snprintf(text.data(), text.size(), "the configuration needs more start-up steps than the master holds");
  } else {
    std::snprintf(text.data(), text.size(), "SDO 0x%04X:%u %s (abort 0x%08X)", f.index, static_cast<unsigned>(f.sub),
                  sdo[static_cast<std::size_t>(f.status) % sdo.size()], static_cast<unsigned>(f.abort));
  }
  return text.data();
}

namespace {

// Why a drive that was configured never reached operation enabled, from its last TPDO1.
std::string enable_failure_text(const hal::canopen::RemoteFeedback& f) {
  if (f.tpdo1_received == 0) return "the drive sent no statusword (no TPDO1 received)";
  std::array<char, 128> text{};
  std::snprintf(text.data(), text.size(), "the drive's statusword stayed 0x%04X (%s), not operation enabled",
                static_cast<unsigned>(f.statusword),
                hal::canopen::to_string(hal::canopen::state_from_statusword(f.statusword)));
  return text.data();
}

// The session's clock is the bus's.
struct BusClock {
  ClockedBus& bus;
  std::uint64_t wait() { return bus.wait(); }
  [[nodiscard]] std::uint64_t now_us() const { return bus.now_us(); }
};

// A change on the axes that have one: the loop's online configuration of each, and when to ask
// (halt()/retarget() on every such axis and service() between two ticks, the configuration's
// lead_ticks setpoints before the switch, as an application would). The ticks are counted on the
// first axis with a change (every change has the same `at`): `lead` (axes.size(): none).
struct ChangeAsk {
  std::size_t lead{0};
  std::int64_t at_moving_tick{-1};
};

template <typename Loop>
std::string configure_changes(Loop& loop, const StreamSpec& spec, ChangeAsk& ask) {
  const std::size_t n = spec.axes.size();
  ask = ChangeAsk{n, -1};
  for (std::size_t i = 0; i < n; ++i) {
    const std::optional<StreamChange>& ch = spec.axes[i].change;
    if (!ch) continue;
    runtime::OnlineConfig oc{};
    oc.mode_count = std::min(ch->modes.size(), oc.modes.size());
    for (std::size_t k = 0; k < oc.mode_count; ++k) oc.modes[k] = ch->modes[k];
    oc.limits = ch->limits;
    oc.path = ch->path;
    if (const runtime::LoopStatus st = loop.configure_online(i, oc); st != runtime::LoopStatus::ok) {
      return "the loop refused axis " + std::to_string(i + 1) + "'s online configuration: " + runtime::to_string(st);
    }
    if (ask.lead == n) {
      ask.lead = i;
      ask.at_moving_tick =
          std::llround(ch->at / spec.drive.scale.period_s()) - static_cast<std::int64_t>(oc.lead_ticks);
    }
  }
  return {};
}

// After the session: what the loop and the bus say about each axis and about the run.
template <typename Loop>
void report_run(Loop& loop, const StreamSpec& spec, const ClockedBus& bus, StreamReport& r) {
  r.counters = bus.counters();
  r.units_held = loop.stats().units_held;
  r.timing = bus.timing();
  r.heartbeat_ms = spec.heartbeat_ms;
  r.sdo_timeout_us = spec.sdo_timeout_us;
  r.feedback_timeout_periods = spec.feedback_timeout_periods;
  // Frames the bus dropped on our side (a full receive queue); the drive's side reports its own.
  // A setpoint or feedback lost within the move would also break every axis's alignment.
  r.frames_lost = r.counters.rx_overflow_drops + r.counters.tx_errors;
  for (std::size_t i = 0; i < r.axes.size(); ++i) {
    AxisReport& a = r.axes[i];
    a.axis = loop.axis_stats(i);
    const auto& d = loop.drive(i);
    a.drive_state = hal::canopen::to_string(d.state());
    if (d.state() == hal::canopen::RemoteDriveState::failed) a.drive_failure = start_up_failure_text(d.failure());
    if (!r.start_up_us && !hal::canopen::is_operation_enabled(d.feedback().statusword) &&
        (a.drive_failure.empty() || d.failure().enable_timeout)) {
      // Never enabled: what the drive's statusword showed instead (or that none came).
      a.drive_failure += (a.drive_failure.empty() ? "" : ": ") + enable_failure_text(d.feedback());
    }
  }
}

// The session on `bus` with the loop of one evaluation, one loop axis per spec axis (acs[i] its
// loop configuration, r.axes[i] its report); fills the report's run fields. "" or why it could not
// run.
template <typename Scalar, typename Evaluation>
std::string stream_session(const StreamSpec& spec, const std::vector<runtime::AxisConfig>& acs,
                           const runtime::SessionConfig& sc, ClockedBus& bus, StreamReport& r) {
  using Loop = LoopOf<Scalar, Evaluation>;
  const std::size_t n = spec.axes.size();
  auto loop = std::make_unique<Loop>(bus.link(), acs.front().scale.period_us);
  std::vector<core::Move<double>> moves;
  for (std::size_t i = 0; i < n; ++i) {
    if (const runtime::LoopStatus st = loop->add_axis(acs[i]); st != runtime::LoopStatus::ok) {
      return "the loop refused axis " + std::to_string(i + 1) + ": " + runtime::to_string(st);
    }
    moves.push_back(spec.axes[i].move);
  }
  // Each drive's first error EMCY, seen when its consumer's count moves (every tick and while the
  // late frames are taken).
  std::vector<std::uint32_t> emcys_seen(n, 0);
  const auto drain = [&] {
    for (std::size_t i = 0; i < n; ++i) {
      for (runtime::FeedbackSample fs{}; loop->feedback_log(i).pop(fs);) r.axes[i].feedback.push_back(fs);
      const hal::canopen::EmcyConsumer& e = loop->drive(i).emcy();
      if (e.count() == emcys_seen[i]) continue;
      emcys_seen[i] = e.count();
      if (!r.axes[i].drive_emcy && e.in_error()) r.axes[i].drive_emcy = e.last();
    }
  };
  ChangeAsk change{};
  if (std::string why = configure_changes(*loop, spec, change); !why.empty()) return why;
  const auto ask = [&] {
    bool ok = true;
    for (std::size_t i = 0; i < n; ++i) {
      const std::optional<StreamChange>& ch = spec.axes[i].change;
      if (ch) ok = (ch->target ? loop->retarget(i, *ch->target) : loop->halt(i)) && ok;
    }
    return loop->service() == runtime::LoopStatus::ok && ok;
  };
  std::int64_t moving_ticks = 0;
  bool asked_ok = true;
  BusClock clock{bus};
  bus.begin();
  const std::uint64_t started_us = clock.now_us();
  // Everything the observer appends to was reserved by the caller: no heap use while streaming.
  // Move i goes to axis i (runtime::run_session), all in the same tick.
  r.session = runtime::run_session(*loop, clock, moves.data(), n, sc, [&](std::uint64_t, bool) {
    if (!r.start_up_us && loop->all_ready()) r.start_up_us = clock.now_us() - started_us;
    for (std::size_t i = 0; i < n; ++i) r.axes[i].log.push_back(loop->record(i));
    if (change.lead < n && loop->record(change.lead).moving && loop->record(change.lead).sent &&
        ++moving_ticks == change.at_moving_tick) {
      asked_ok = ask();
    }
    drain();
    bus.between_ticks();
  });
  // A session that ended before the change (a refused move, a drive lost) reports its own
  // outcome, which says why; only a session that ran to its end must have switched.
  const bool ran_out = r.session.outcome == runtime::SessionOutcome::completed;
  for (std::size_t i = 0; i < n; ++i) {
    if (spec.axes[i].change &&
        (!asked_ok || (ran_out && loop->online_switches(i) + loop->online_finishes(i) != 1))) {
      return "the loop did not switch axis " + std::to_string(i + 1) + " to its blend at " +
             std::to_string(spec.axes[i].change->at) + " s";
    }
  }
  // The last TPDOs may still be on their way: take them, the way the loop does, before counting.
  if (std::string why = bus.finish([&](const hal::CanFrame& f, std::uint64_t now_us) {
        loop->receive(f, now_us);
        drain();
      });
      !why.empty()) {
    return why;
  }
  report_run(*loop, spec, bus, r);
  return {};
}

// The measurements: the replay, the alignment of the CAN feedback with it, the residual fits and
// the continuous reference.
void measure(const StreamSpec& spec, const StreamAxis& axis, std::uint64_t settle_ticks, AxisReport& r) {
  const core::AxisScale& scale = spec.drive.scale;
  const double load_cpu = spec.drive.load_counts_per_unit;
  // Offline: the same integer setpoints through the same drive model and plant, no bus.
  const bool have_sp = r.evaluation == core::Status::ok;
  const bool have_replay =
      have_sp && replay_stream(spec.drive, spec.plant, 0, r.setpoints, settle_ticks, r.replay) == plant::SimStatus::ok;
  // The double evaluator's setpoints and their replay: what double streams (its run aligns with
  // exactly this replay), the reference float and fixed are held to.
  std::vector<std::int32_t> sp_double;
  Replay replay_double{};
  const bool have_double =
      changed_setpoints(StreamScalar::double_precision, spec, axis, sp_double) == core::Status::ok &&
      replay_stream(spec.drive, spec.plant, 0, sp_double, settle_ticks, replay_double) == plant::SimStatus::ok;
  // Setpoint by setpoint (the shorter sequence held at its last), the largest difference in counts.
  if (have_sp && have_double) {
    const std::vector<std::int32_t>& sp = r.setpoints;
    std::int64_t max_diff = 0;
    for (std::size_t i = 0; i < std::max(sp.size(), sp_double.size()); ++i) {
      const std::int64_t a = i < sp.size() ? sp[i] : sp.back();
      const std::int64_t b = i < sp_double.size() ? sp_double[i] : sp_double.back();
      max_diff = std::max(max_diff, a > b ? a - b : b - a);
      r.setpoints_differing_from_double += a != b ? 1 : 0;
    }
    r.setpoints_vs_double_max_counts = max_diff;
  }
  // From the CAN feedback: find the replay's period-by-period positions in the received sequence.
  // An exact match proves every setpoint was applied once, in order, with no feedback lost in
  // between; the load samples from the final setpoint on then give the measured residual.
  std::vector<std::int32_t> positions;
  positions.reserve(r.feedback.size());
  for (const auto& fs : r.feedback) positions.push_back(fs.position_actual);
  if (have_replay) r.alignment = align_feedback(positions, r.replay);
  std::vector<std::int32_t> measured;
  if (r.aligned() && r.load_measured) {
    for (std::size_t i = r.replay.move_periods - 1; i < r.replay.feedback.size(); ++i) {
      measured.push_back(r.feedback[*r.alignment + i].load_position);
    }
  }
  r.window_samples = measured.size();
  const double dt = scale.period_s();
  SampledResidual& can = r.residual_can;
  SampledResidual& off = r.residual_offline;
  if (fitted_residual(measured, load_cpu, r.replay.final_load, dt, spec.plant, r.replay.step_residual, can) !=
          plant::SimStatus::ok ||
      fitted_residual(r.replay.load_after, load_cpu, r.replay.final_load, dt, spec.plant, r.replay.step_residual,
                      off) != plant::SimStatus::ok) {
    can.amplitude = off.amplitude = can.prv_percent = off.prv_percent = kNaN;
  }
  if (!r.load_measured) {
    // No load position on the bus: nothing to fit (a column of zeros is no measurement).
    can = SampledResidual{};
    can.amplitude = can.prv_percent = can.fit_rms = kNaN;
  }
  SampledResidual off_double{};
  if (!have_double || fitted_residual(replay_double.load_after, load_cpu, replay_double.final_load, dt, spec.plant,
                                      replay_double.step_residual, off_double) != plant::SimStatus::ok) {
    off_double.amplitude = kNaN;
  }
  r.residual_double = off_double.amplitude;
  // The residual measured over CAN against the double run's (its aligned replay), in percent, and
  // the same difference in load counts: what it is next to the measurement's resolution.
  r.residual_vs_double_percent =
      r.aligned() ? std::fabs(can.amplitude - off_double.amplitude) / off_double.amplitude * 100.0 : kNaN;
  r.residual_vs_double_load_counts = std::fabs(can.amplitude - off_double.amplitude) * load_cpu;
  r.agreement = r.aligned() ? std::fabs(can.amplitude - off.amplitude) : kNaN;
  plant::SimResult cont{};
  plant::SimOptions so{};
  so.record = false;
  // The residual is exact at the move's end whatever the grid; the grid only samples the peak
  // deflection and the settling time, so a long move takes a coarser one (at most 2e6 steps x modes).
  so.dt = std::max(so.dt, command_duration(axis) * static_cast<double>(spec.plant.modes().size()) / plant::kMaxSimWork);
  if (axis.change && !axis.change->finish) {
    const plant::OnlineChangeCommand changed{axis.move, axis.change->at, axis.change->blend};
    r.continuous_simulated = plant::simulate(spec.plant, changed, so, cont) == plant::SimStatus::ok;
  } else {
    r.continuous_simulated = plant::simulate(spec.plant, plant::MoveCommand{axis.move}, so, cont) == plant::SimStatus::ok;
  }
  r.residual_continuous = r.continuous_simulated ? cont.metrics.residual_amplitude : kNaN;
  r.prv_continuous_percent = r.continuous_simulated ? cont.metrics.prv_percent : kNaN;
  for (std::size_t i = 1; i < r.log.size(); ++i) {
    if (r.log[i].feedback_count != r.log[i - 1].feedback_count + 1 && r.log[i].feedback_count > 0) {
      ++r.feedback_late_ticks;
    }
  }
  for (std::size_t i = 0; i < r.log.size(); ++i) {
    if (!r.move_start_tick && r.log[i].moving && r.log[i].sent) r.move_start_tick = i;
    if (r.log[i].move_end) r.move_end_tick = i;
  }
}

// How the axes moved together (StreamReport's multi-axis fields), from every axis's tick log and
// its feedback aligned with its replay.
void measure_axes(const StreamSpec& spec, StreamReport& r) {
  const std::size_t n = spec.axes.size();
  // The line from the start to every axis's target, in counts.
  std::vector<double> dir(n);
  for (std::size_t i = 0; i < n; ++i) dir[i] = spec.axes[i].move.distance() * spec.drive.scale.counts_per_unit;
  std::vector<double> p(n);
  const auto off_line = [&] { return core::offset_from_line(p.data(), dir.data(), n); };
  // Start and end ticks of every moving axis.
  std::uint64_t s_lo = ~std::uint64_t{0}, s_hi = 0, e_lo = ~std::uint64_t{0}, e_hi = 0;
  bool all = true, any = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (spec.axes[i].move.distance() == 0.0) continue;
    const AxisReport& a = r.axes[i];
    if (!a.move_start_tick || !a.move_end_tick || *a.move_start_tick == 0) {
      all = false;
      continue;
    }
    any = true;
    s_lo = std::min(s_lo, *a.move_start_tick);
    s_hi = std::max(s_hi, *a.move_start_tick);
    e_lo = std::min(e_lo, *a.move_end_tick);
    e_hi = std::max(e_hi, *a.move_end_tick);
  }
  r.line_deviation_setpoints_counts = r.line_deviation_feedback_counts = kNaN;
  if (!all || !any) return;
  r.start_tick_spread = s_hi - s_lo;
  r.end_tick_spread = e_hi - e_lo;
  // The setpoints sent, tick by tick from the first start to the last end, each axis from where
  // it held before its move.
  double worst = 0.0;
  for (std::uint64_t t = s_lo; t <= e_hi; ++t) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::vector<runtime::TickRecord>& log = r.axes[i].log;
      const std::uint64_t held = r.axes[i].move_start_tick.value_or(s_lo) - 1;
      p[i] = t < log.size() && held < log.size() ? static_cast<double>(log[t].target) - log[held].target : 0.0;
    }
    worst = std::max(worst, off_line());
  }
  r.line_deviation_setpoints_counts = worst;
  // The positions the drives reported, SYNC by SYNC from the first setpoint (each axis's replay
  // starts at 0 and its alignment says where that SYNC's feedback is).
  std::size_t periods = ~std::size_t{0};
  for (std::size_t i = 0; i < n; ++i) {
    if (!r.axes[i].aligned()) return;
    periods = std::min(periods, r.axes[i].replay.feedback.size());
  }
  worst = 0.0;
  for (std::size_t k = 0; k < periods; ++k) {
    for (std::size_t i = 0; i < n; ++i) p[i] = r.axes[i].feedback[*r.axes[i].alignment + k].position_actual;
    worst = std::max(worst, off_line());
  }
  r.line_deviation_feedback_counts = worst;
}

}  // namespace

double stream_axis_vmax(const StreamSpec& spec, const StreamAxis& axis) {
  if (spec.axis_vmax) return *spec.axis_vmax;
  double v = std::fmax(axis.move.peaks().v, 1e-12) * 1.5;
  if (axis.change) v = std::fmax(v, axis.change->limits.vmax);  // what the loop's own halt may plan
  return v;
}

StreamRefusal check_streamable(const StreamSpec& spec, bool simulated_drive) {
  for (std::size_t i = 0; i < spec.axes.size(); ++i) {
    const StreamAxis& one = spec.axes[i];
    // The fastest the command goes: the move's peak, or the vmax the loop plans its change within.
    const double move_v = one.move.peaks().v;
    const double change_v = one.change ? one.change->limits.vmax : 0.0;
    double drive_vmax = 0.0;  // counts/s, 0: not known
    if (simulated_drive) {
      SimulatedDriveSpec ds{};
      ds.node = one.node;
      ds.eds = spec.eds.get();
      const DriveFromEds d = simulated_drive_config(ds);
      // Without a config the bus's open() refuses the description, naming it.
      drive_vmax = static_cast<double>(d.config ? d.config->max_profile_velocity
                                                : hal::canopen::DriveNodeConfig{}.max_profile_velocity);
    }
    const double cpu = spec.drive.scale.counts_per_unit;
    StreamRefusal r{};
    const auto over = [&](runtime::LoopStatus status, double limit) {
      const double tolerated = limit * (1.0 + core::kLimitSlack);  // the loop's tolerance
      if (move_v <= tolerated && change_v <= tolerated) return false;
      r.status = status;
      r.in_change = move_v <= tolerated;
      r.limit = limit;
      r.peak = r.in_change ? change_v : move_v;
      return true;
    };
    if (over(runtime::LoopStatus::exceeds_axis_velocity, stream_axis_vmax(spec, one))) {
    } else if (drive_vmax > 0.0 && over(runtime::LoopStatus::exceeds_drive_velocity, drive_vmax / cpu)) {
      r.limit *= cpu;
      r.peak *= cpu;
    } else {
      switch (spec.scalar) {
        case StreamScalar::single_precision: r = evaluation_takes<runtime::FloatEvaluation<float>>(spec, one); break;
        case StreamScalar::fixed_point: r = evaluation_takes<runtime::PolyFixedEvaluation>(spec, one); break;
        case StreamScalar::double_precision: r = evaluation_takes<runtime::FloatEvaluation<double>>(spec, one); break;
      }
    }
    if (r.status != runtime::LoopStatus::ok) {
      r.axis = i;
      return r;
    }
  }
  return {};
}

hal::eds::FeedbackRequest streaming_feedback(const hal::eds::Description& eds, const LoadFeedback& load) {
  hal::eds::FeedbackRequest f{};
  f.velocity_actual = eds.find(hal::canopen::obj::velocity_actual, 0) != nullptr;
  if (load.index != 0) {
    f.load_position_index = load.index;
    f.load_position_sub = load.sub;
  } else if (const auto& marked = eds.load_position()) {
    // The description's own mark (Settle's drive: 0x2000); another vendor's 0x2000 is theirs.
    f.load_position_index = marked->index;
    f.load_position_sub = marked->sub;
  }
  return f;
}

std::optional<NodeClash> shared_node(const std::vector<hal::canopen::NodeId>& nodes) {
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    for (std::size_t k = 0; k < i; ++k) {
      if (nodes[i] == nodes[k]) return NodeClash{k, i, nodes[i]};
    }
  }
  return std::nullopt;
}

namespace {

// What run_stream refuses before anything is sent: "" or why.
std::string spec_problem(const StreamSpec& spec) {
  const std::size_t n = spec.axes.size();
  if (!spec.drive.scale.valid()) return "the axis scale needs a positive period and a positive, finite counts per unit";
  if (n == 0) return "no axis to stream";
  if (n > core::kMaxAxes) return "at most 8 axes";
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < i; ++k) {
      const StreamAxis& a = spec.axes[i];
      const StreamAxis& b = spec.axes[k];
      if (a.change && b.change && a.change->at != b.change->at) {
        return "axes " + std::to_string(k + 1) + " and " + std::to_string(i + 1) +
               " change at different times: every axis's halt or retarget is asked for in the same period";
      }
    }
  }
  std::vector<hal::canopen::NodeId> nodes;
  for (const StreamAxis& a : spec.axes) nodes.push_back(a.node);
  if (const std::optional<NodeClash> c = shared_node(nodes)) {
    return "axes " + std::to_string(c->earlier + 1) + " and " + std::to_string(c->later + 1) + " are both on node " +
           std::to_string(c->node) + ": one drive per node";
  }
  return {};
}

// The run's first stage: the loop's configuration of every axis and of the session, every axis's
// selected setpoints, and the records reserved (no heap use while streaming). "" or why not.
std::string prepare(const StreamSpec& spec, std::vector<runtime::AxisConfig>& acs, runtime::SessionConfig& sc,
                    StreamReport& r) {
  const std::uint32_t period_us = spec.drive.scale.period_us;
  const std::size_t n = spec.axes.size();
  acs.assign(n, runtime::AxisConfig{});
  sc = runtime::SessionConfig{};
  sc.settle_ticks = static_cast<std::uint64_t>(spec.settle_time_s * 1e6 / period_us);
  sc.enable_timeout_ticks = 5'000'000 / period_us;
  double longest = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    runtime::AxisConfig& ac = acs[i];
    ac.drive.node = spec.axes[i].node;
    ac.drive.sync_period_us = period_us;
    ac.drive.heartbeat_timeout_ms = spec.heartbeat_ms;
    ac.drive.sdo_timeout_us = spec.sdo_timeout_us;
    ac.scale = spec.drive.scale;
    ac.vmax = stream_axis_vmax(spec, spec.axes[i]);
    ac.feedback_timeout_periods = spec.feedback_timeout_periods;
    // The drive's own enabling deadline is the session's 5 s window, not RemoteDrive's 1 s default:
    // a host that stalls the process for a second must not fail a drive that enables in time.
    ac.drive.enable_timeout_us = static_cast<std::uint32_t>(sc.enable_timeout_ticks * period_us);
    if (spec.eds) {
      const hal::eds::DriveConfigResult d =
          hal::eds::drive_config_from_eds(*spec.eds, ac.drive, streaming_feedback(*spec.eds, spec.load_feedback));
      if (!d.ok()) return "--eds: " + d.error;
      ac.drive = d.config;
    }
    AxisReport& a = r.axes[i];
    a.load_measured = ac.drive.layout.load_position.mapped();
    if (!a.load_measured) a.load_note = "not measured (the drive reports no load position)";
    longest = std::fmax(longest, command_duration(spec.axes[i]));
  }
  const std::uint64_t move_ticks = static_cast<std::uint64_t>(longest * 1e6 / period_us) + 2;
  // Completion waits for the feedback to show the target (at most in_position_timeout_periods).
  sc.max_ticks = sc.enable_timeout_ticks + move_ticks + sc.settle_ticks + acs.front().in_position_timeout_periods + 10;
  if (sc.max_ticks > plant::kMaxSamples) return "the session would last more than 1e7 periods";
  for (std::size_t i = 0; i < n; ++i) {
    AxisReport& a = r.axes[i];
    // The setpoints the selected evaluation produces (the replay's).
    a.evaluation = changed_setpoints(spec.scalar, spec, spec.axes[i], a.setpoints);
    // Allocated before the loop starts: no heap use while streaming.
    a.log.reserve(sc.max_ticks + sc.release_ticks + 1);
    a.feedback.reserve(sc.max_ticks + sc.release_ticks + 64);
  }
  return {};
}

// The run's second stage: the session with the loop of the spec's scalar.
std::string session(const StreamSpec& spec, const std::vector<runtime::AxisConfig>& acs,
                    const runtime::SessionConfig& sc, ClockedBus& bus, StreamReport& r) {
  switch (spec.scalar) {
    case StreamScalar::single_precision:
      return stream_session<float, runtime::FloatEvaluation<float>>(spec, acs, sc, bus, r);
    case StreamScalar::fixed_point: return stream_session<double, runtime::PolyFixedEvaluation>(spec, acs, sc, bus, r);
    case StreamScalar::double_precision: break;
  }
  return stream_session<double, runtime::FloatEvaluation<double>>(spec, acs, sc, bus, r);
}

}  // namespace

StreamReport run_stream(const StreamSpec& spec, ClockedBus& bus) {
  StreamReport r{};
  r.bus = bus.name();
  r.realtime = bus.realtime();
  r.scalar = spec.scalar;
  r.scale = spec.drive.scale;
  for (const StreamAxis& axis : spec.axes) {
    AxisReport a{};
    a.node = axis.node;
    a.profile = axis.move.profile().kind();
    a.distance = axis.move.distance();
    a.duration = axis.move.duration();
    r.axes.push_back(std::move(a));
  }
  std::vector<runtime::AxisConfig> acs;
  runtime::SessionConfig sc{};
  r.failure = spec_problem(spec);
  if (r.failure.empty()) r.failure = prepare(spec, acs, sc, r);
  if (r.failure.empty()) r.failure = bus.open(spec);
  if (r.failure.empty()) r.failure = session(spec, acs, sc, bus, r);
  if (!r.failure.empty()) return r;
  // The run's last stage: the measurements, axis by axis and together.
  for (std::size_t i = 0; i < spec.axes.size(); ++i) measure(spec, spec.axes[i], sc.settle_ticks, r.axes[i]);
  if (spec.axes.size() > 1) measure_axes(spec, r);
  return r;
}

}  // namespace settle::testbed
