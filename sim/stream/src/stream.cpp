#include "settle/sim/stream.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>

#include "settle/firmware/evaluation.hpp"
#include "settle/sim/command.hpp"
#include "settle/sim/limits.hpp"
#include "settle/sim/online_command.hpp"
#include "settle/sim/simulate.hpp"

namespace settle::sim {

const char* to_string(StreamScalar s) noexcept {
  switch (s) {
    case StreamScalar::double_precision: return "double";
    case StreamScalar::single_precision: return "float";
    case StreamScalar::fixed_point: return "fixed";
  }
  return "?";
}

bool StreamReport::measured() const noexcept {
  return completed() && std::isfinite(residual_can.amplitude) && std::isfinite(residual_offline.amplitude) &&
         std::isfinite(agreement) && std::isfinite(residual_continuous);
}

namespace {

// The loop for each evaluation (--scalar): its scalar, one axis, four queued moves, online changes.
template <typename Scalar, typename Evaluation>
using LoopOf = firmware::ServoLoop<Scalar, 1, 4, Evaluation, hal::CanBus, true>;

// The integer targets an evaluation produces for a move, tick by tick from 0 to the move's end,
// and with a change the move's up to the switch, then the blend's to its end: the prepare/start/
// next the loop runs in its ticks and service(), offline. The replay's setpoints for every scalar
// come from here, and so do the double evaluator's they are compared with. Not ok when the
// evaluation refuses the move or the blend (the loop refuses them too) or it has more than kMaxSamples.
template <typename Evaluation>
core::Status evaluated_setpoints(const StreamSpec& spec, std::vector<std::int32_t>& out) {
  const core::AxisScale& scale = spec.drive.scale;
  out.clear();
  auto slot = std::make_unique<typename Evaluation::Stored>();  // not movable: the stream refers into it
  if (const core::Status st = Evaluation::prepare(spec.move, scale, *slot); st != core::Status::ok) return st;
  typename Evaluation::Stream s = Evaluation::start(*slot, 0);
  bool last = false;
  while (!last && out.size() < kMaxSamples) out.push_back(s.next(last));
  if (!last) return core::Status::duration_does_not_fit;
  if (!spec.change) return core::Status::ok;
  const auto k = static_cast<std::size_t>(std::llround(spec.change->at / scale.period_s()));
  if (out.size() > k) out.resize(k);
  while (out.size() < k) out.push_back(out.empty() ? 0 : out.back());
  auto blend = std::make_unique<typename Evaluation::BlendStored>();
  if (const core::Status st = Evaluation::prepare(spec.change->blend, scale, *blend); st != core::Status::ok) return st;
  typename Evaluation::BlendStream b = Evaluation::start(*blend, 0);
  last = false;
  while (!last && out.size() < kMaxSamples) out.push_back(b.next(last));
  return last ? core::Status::ok : core::Status::duration_does_not_fit;
}

core::Status changed_setpoints(StreamScalar scalar, const StreamSpec& spec, std::vector<std::int32_t>& out) {
  switch (scalar) {
    case StreamScalar::single_precision: return evaluated_setpoints<firmware::FloatEvaluation<float>>(spec, out);
    case StreamScalar::fixed_point: return evaluated_setpoints<firmware::PolyFixedEvaluation>(spec, out);
    case StreamScalar::double_precision: break;
  }
  return evaluated_setpoints<firmware::FloatEvaluation<double>>(spec, out);
}

// How long the command lasts: the move, or the move to the switch and then the blend.
double command_duration(const StreamSpec& spec) {
  return spec.change ? spec.change->at + spec.change->blend.duration() : spec.move.duration();
}

}  // namespace

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

// The session's clock is the bus's.
struct BusClock {
  StreamBus& bus;
  std::uint64_t wait() { return bus.wait(); }
  [[nodiscard]] std::uint64_t now_us() const { return bus.now_us(); }
};

// The session on `bus` with the loop of one evaluation; fills the report's run fields. "" or
// why it could not run.
template <typename Scalar, typename Evaluation>
std::string stream_session(const StreamSpec& spec, const firmware::AxisConfig& ac, const firmware::SessionConfig& sc,
                           StreamBus& bus, StreamReport& r) {
  using Loop = LoopOf<Scalar, Evaluation>;
  auto loop = std::make_unique<Loop>(bus.link(), ac.scale.period_us);
  if (const firmware::LoopStatus st = loop->add_axis(ac); st != firmware::LoopStatus::ok) {
    return std::string{"the loop refused the axis: "} + firmware::to_string(st);
  }
  const auto drain = [&] {
    for (firmware::FeedbackSample fs{}; loop->feedback_log(0).pop(fs);) r.feedback.push_back(fs);
  };
  // A change: halt()/retarget() posted and service() run between two ticks, the configuration's
  // lead_ticks setpoints before the switch, as an application would.
  std::int64_t ask_at = -1;
  if (spec.change) {
    firmware::OnlineConfig oc{};
    oc.mode_count = std::min(spec.change->modes.size(), oc.modes.size());
    for (std::size_t i = 0; i < oc.mode_count; ++i) oc.modes[i] = spec.change->modes[i];
    oc.limits = spec.change->limits;
    if (const firmware::LoopStatus st = loop->configure_online(0, oc); st != firmware::LoopStatus::ok) {
      return std::string{"the loop refused the online configuration: "} + firmware::to_string(st);
    }
    ask_at = std::llround(spec.change->at / ac.scale.period_s()) - static_cast<std::int64_t>(oc.lead_ticks);
  }
  std::int64_t moving_ticks = 0;
  bool asked_ok = true;
  BusClock clock{bus};
  bus.begin();
  const std::uint64_t started_us = clock.now_us();
  // Everything the observer appends to was reserved by the caller: no heap use while streaming.
  r.session = firmware::run_session(*loop, clock, &spec.move, 1, sc, [&](std::uint64_t, bool) {
    if (!r.start_up_us && loop->all_ready()) r.start_up_us = clock.now_us() - started_us;
    r.log.push_back(loop->record(0));
    if (loop->record(0).moving && loop->record(0).sent) {
      if (++moving_ticks == ask_at) {
        asked_ok = (spec.change->target ? loop->retarget(0, *spec.change->target) : loop->halt(0)) &&
                   loop->service() == firmware::LoopStatus::ok;
      }
    }
    drain();
    bus.between_ticks();
  });
  if (spec.change && (!asked_ok || loop->online_switches(0) != 1)) {
    return "the loop did not switch to the blend at " + std::to_string(spec.change->at) + " s";
  }
  // The last TPDOs may still be on their way: take them, the way the loop does, before counting.
  if (std::string why = bus.finish([&](const hal::CanFrame& f, std::uint64_t now_us) {
        loop->receive(f, now_us);
        drain();
      });
      !why.empty()) {
    return why;
  }
  r.counters = bus.counters();
  r.axis = loop->axis_stats(0);
  r.units_held = loop->stats().units_held;
  const auto& d = loop->drive(0);
  r.drive_state = hal::canopen::to_string(d.state());
  if (d.state() == hal::canopen::RemoteDriveState::failed) r.drive_failure = start_up_failure_text(d.failure());
  r.timing = bus.timing();
  return {};
}

// The measurements: the replay, the alignment of the CAN feedback with it, the residual fits and
// the continuous reference.
void measure(const StreamSpec& spec, std::uint64_t settle_ticks, StreamReport& r) {
  const core::AxisScale& scale = spec.drive.scale;
  const double load_cpu = spec.drive.load_counts_per_unit;
  // Offline: the same integer setpoints through the same drive model and plant, no bus.
  const bool have_sp = r.evaluation == core::Status::ok;
  const bool have_replay =
      have_sp && replay_stream(spec.drive, spec.plant, 0, r.setpoints, settle_ticks, r.replay) == SimStatus::ok;
  // The double evaluator's setpoints and their replay: what double streams (its run aligns with
  // exactly this replay), the reference float and fixed are held to.
  std::vector<std::int32_t> sp_double;
  Replay replay_double{};
  const bool have_double =
      changed_setpoints(StreamScalar::double_precision, spec, sp_double) == core::Status::ok &&
      replay_stream(spec.drive, spec.plant, 0, sp_double, settle_ticks, replay_double) == SimStatus::ok;
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
  if (r.aligned()) {
    for (std::size_t i = r.replay.move_periods - 1; i < r.replay.feedback.size(); ++i) {
      measured.push_back(r.feedback[*r.alignment + i].load_position);
    }
  }
  r.window_samples = measured.size();
  const double dt = scale.period_s();
  SampledResidual& can = r.residual_can;
  SampledResidual& off = r.residual_offline;
  if (fitted_residual(measured, load_cpu, r.replay.final_load, dt, spec.plant, r.replay.step_residual, can) !=
          SimStatus::ok ||
      fitted_residual(r.replay.load_after, load_cpu, r.replay.final_load, dt, spec.plant, r.replay.step_residual,
                      off) != SimStatus::ok) {
    can.amplitude = off.amplitude = can.prv_percent = off.prv_percent = NAN;
  }
  SampledResidual off_double{};
  if (!have_double || fitted_residual(replay_double.load_after, load_cpu, replay_double.final_load, dt, spec.plant,
                                      replay_double.step_residual, off_double) != SimStatus::ok) {
    off_double.amplitude = NAN;
  }
  r.residual_double = off_double.amplitude;
  // The residual measured over CAN against the double run's (its aligned replay), in percent, and
  // the same difference in load counts: what it is next to the measurement's resolution.
  r.residual_vs_double_percent =
      r.aligned() ? std::fabs(can.amplitude - off_double.amplitude) / off_double.amplitude * 100.0 : double{NAN};
  r.residual_vs_double_load_counts = std::fabs(can.amplitude - off_double.amplitude) * load_cpu;
  r.agreement = r.aligned() ? std::fabs(can.amplitude - off.amplitude) : double{NAN};
  SimResult cont{};
  SimOptions so{};
  so.record = false;
  // The residual is exact at the move's end whatever the grid; the grid only samples the peak
  // deflection and the settling time, so a long move takes a coarser one (at most 2e6 steps x modes).
  so.dt = std::max(so.dt, command_duration(spec) * static_cast<double>(spec.plant.modes().size()) / kMaxSimWork);
  if (spec.change) {
    const OnlineChangeCommand changed{spec.move, spec.change->at, spec.change->blend};
    r.continuous_simulated = simulate(spec.plant, changed, so, cont) == SimStatus::ok;
  } else {
    r.continuous_simulated = simulate(spec.plant, MoveCommand{spec.move}, so, cont) == SimStatus::ok;
  }
  r.residual_continuous = r.continuous_simulated ? cont.metrics.residual_amplitude : double{NAN};
  r.prv_continuous_percent = r.continuous_simulated ? cont.metrics.prv_percent : double{NAN};
  for (std::size_t i = 1; i < r.log.size(); ++i) {
    if (r.log[i].feedback_count != r.log[i - 1].feedback_count + 1 && r.log[i].feedback_count > 0) {
      ++r.feedback_late_ticks;
    }
  }
  // Frames the bus dropped on our side (a full receive queue); the drive's side reports its own.
  // A setpoint or feedback lost within the move would also have broken the alignment above.
  r.frames_lost = r.counters.rx_overflow_drops + r.counters.tx_errors;
}

}  // namespace

hal::eds::FeedbackRequest streaming_feedback(const hal::eds::Description& eds) {
  hal::eds::FeedbackRequest f{};
  f.velocity_actual = eds.find(hal::canopen::obj::velocity_actual, 0) != nullptr;
  if (eds.find(hal::canopen::obj::load_position_actual, 0) != nullptr) {
    f.load_position_index = hal::canopen::obj::load_position_actual;
    f.load_position_sub = 0;
  }
  return f;
}

StreamReport run_stream(const StreamSpec& spec, StreamBus& bus) {
  StreamReport r{};
  const std::uint32_t period_us = spec.drive.scale.period_us;
  r.bus = bus.name();
  r.realtime = bus.realtime();
  r.profile = spec.move.profile().kind();
  r.scalar = spec.scalar;
  r.distance = spec.move.distance();
  r.move_time = spec.move.duration();
  r.scale = spec.drive.scale;
  if (!spec.drive.scale.valid()) {
    r.failure = "the axis scale needs a positive period and a positive, finite counts per unit";
    return r;
  }

  firmware::AxisConfig ac{};
  ac.drive.node = spec.node;
  ac.drive.sync_period_us = period_us;
  ac.drive.heartbeat_timeout_ms = spec.heartbeat_ms;
  ac.drive.sdo_timeout_us = spec.sdo_timeout_us;
  ac.scale = spec.drive.scale;
  ac.vmax = spec.axis_vmax.value_or(std::fmax(spec.move.peaks().v, 1e-12) * 1.5);
  ac.feedback_timeout_periods = spec.feedback_timeout_periods;
  firmware::SessionConfig sc{};
  sc.settle_ticks = static_cast<std::uint64_t>(spec.settle_time_s * 1e6 / period_us);
  sc.enable_timeout_ticks = 5'000'000 / period_us;
  // The drive's own enabling deadline is the session's 5 s window, not RemoteDrive's 1 s default:
  // a host that stalls the process for a second must not fail a drive that enables in time.
  ac.drive.enable_timeout_us = static_cast<std::uint32_t>(sc.enable_timeout_ticks * period_us);
  if (spec.eds) {
    const hal::eds::DriveConfigResult d = hal::eds::drive_config_from_eds(*spec.eds, ac.drive, streaming_feedback(*spec.eds));
    if (!d.ok()) {
      r.failure = "--eds: " + d.error;
      return r;
    }
    ac.drive = d.config;
  }
  const std::uint64_t move_ticks = static_cast<std::uint64_t>(command_duration(spec) * 1e6 / period_us) + 2;
  // Completion waits for the feedback to show the target (at most in_position_timeout_periods).
  sc.max_ticks = sc.enable_timeout_ticks + move_ticks + sc.settle_ticks + ac.in_position_timeout_periods + 10;
  if (sc.max_ticks > kMaxSamples) {
    r.failure = "the session would last more than 1e7 periods";
    return r;
  }

  // The setpoints the selected evaluation produces (the replay's).
  r.evaluation = changed_setpoints(spec.scalar, spec, r.setpoints);
  // Allocated before the loop starts: no heap use while streaming.
  r.log.reserve(sc.max_ticks + sc.release_ticks + 1);
  r.feedback.reserve(sc.max_ticks + sc.release_ticks + 64);
  if (std::string why = bus.open(spec); !why.empty()) {
    r.failure = why;
    return r;
  }
  std::string why;
  switch (spec.scalar) {
    case StreamScalar::single_precision:
      why = stream_session<float, firmware::FloatEvaluation<float>>(spec, ac, sc, bus, r);
      break;
    case StreamScalar::fixed_point:
      why = stream_session<double, firmware::PolyFixedEvaluation>(spec, ac, sc, bus, r);
      break;
    case StreamScalar::double_precision:
      why = stream_session<double, firmware::FloatEvaluation<double>>(spec, ac, sc, bus, r);
      break;
  }
  if (!why.empty()) {
    r.failure = why;
    return r;
  }
  measure(spec, sc.settle_ticks, r);
  return r;
}

}  // namespace settle::sim
