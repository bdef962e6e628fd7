// settle stream: the servo loop streaming a planned move to a drive over CAN, and the proof that
// the machine ended at rest: residual vibration measured from the drive's CAN feedback, next to
// the offline replay of the same setpoints (no bus) and the continuous profile (no sampling).
// --bus vcan0 (any SocketCAN interface) runs in real time against a `settle plant` process;
// --bus loopback runs the plant node in this process on the in-process bus, in virtual time.
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "commands.hpp"
#include "json.hpp"
#include "move_options.hpp"
#include "options.hpp"
#include "plant_options.hpp"
#include "settle/firmware/evaluation.hpp"
#include "settle/firmware/linux/periodic.hpp"
#include "settle/firmware/session.hpp"
#include "settle/hal/candump_file.hpp"
#include "settle/hal/candump_log.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "socketcan_open.hpp"
#include "settle/sim/command.hpp"
#include "settle/sim/plant_node.hpp"
#include "settle/sim/simulate.hpp"
#include "settle/sim/stream_check.hpp"

namespace settle::cli {

namespace {

// The loop's evaluation is chosen by --scalar: ServoLoop<Scalar, 1, 4, Evaluation> for
// (double, FloatEvaluation<double>), (float, FloatEvaluation<float>) or (double, PolyFixedEvaluation:
// the firmware's fixed-point evaluation with room for the pseudo-polynomial's pieces).
template <typename Scalar, typename Evaluation>
using LoopOf = firmware::ServoLoop<Scalar, 1, 4, Evaluation>;

// The integer targets an evaluation produces for a move, tick by tick from 0 to the move's end:
// the prepare/start/next the loop runs in its ticks, offline: the replay's setpoints for every
// scalar come from here, and so do the double evaluator's they are compared with. Not ok when the
// evaluation refuses the move (the loop refuses it at submit too). The caller has bounded the periods.
template <typename Evaluation>
core::Status evaluated_setpoints(const core::Move<double>& move, const core::AxisScale& scale,
                         std::vector<std::int32_t>& out) {
  out.clear();
  auto slot = std::make_unique<typename Evaluation::Stored>();  // not movable: the stream refers into it
  if (const core::Status st = Evaluation::prepare(move, scale, *slot); st != core::Status::ok) {
    return st;
  }
  typename Evaluation::Stream s = Evaluation::start(*slot, 0);
  bool last = false;
  while (!last && out.size() <= static_cast<std::size_t>(kMaxStreamPeriods)) out.push_back(s.next(last));
  return last ? core::Status::ok : core::Status::duration_does_not_fit;
}

// The Linux periodic timer as a session clock.
class RealtimeClock {
 public:
  explicit RealtimeClock(std::uint32_t period_us) : timer_{period_us} { timer_.start(); }
  std::uint64_t wait() { return timer_.wait(); }
  [[nodiscard]] std::uint64_t now_us() const { return timer_.now_us(); }
  [[nodiscard]] const firmware::linux_rt::PeriodicTimer& timer() const { return timer_; }

 private:
  firmware::linux_rt::PeriodicTimer timer_;
};

struct Outcome {
  firmware::SessionResult session{};
  std::vector<firmware::TickRecord> log;
  std::vector<firmware::FeedbackSample> feedback;  // every TPDO pair, in arrival order

  // After each tick: its record, and the feedback the loop received (draining its log).
  template <typename Loop>
  void record(Loop& loop) {
    log.push_back(loop.record(0));
    drain(loop);
  }
  template <typename Loop>
  void drain(Loop& loop) {
    for (firmware::FeedbackSample fs{}; loop.feedback_log(0).pop(fs);) feedback.push_back(fs);
  }
  // After the session: the counters, and where the drive's start-up stands (why, when it failed).
  template <typename Loop>
  void finish(const Loop& loop, const hal::CanBus& on) {
    bus = on.counters();
    axis = loop.axis_stats(0);
    units_held = loop.stats().units_held;
    const auto& d = loop.drive(0);
    drive_state = hal::canopen::to_string(d.state());
    if (d.state() != hal::canopen::RemoteDriveState::failed) return;
    const hal::canopen::RemoteDriveFailure& f = d.failure();
    static constexpr std::array<const char*, 5> sdo{"idle", "busy", "done", "aborted", "timed out"};
    std::array<char, 96> text{};
    if (f.enable_timeout) {
      std::snprintf(text.data(), text.size(), "the drive did not reach operation enabled in time");
    } else if (f.wrong_value) {
      std::snprintf(text.data(), text.size(), "0x%04X:%u read back a value other than the one written", f.index,
                    static_cast<unsigned>(f.sub));
    } else {
      std::snprintf(text.data(), text.size(), "SDO 0x%04X:%u %s (abort 0x%08X)", f.index, static_cast<unsigned>(f.sub),
                    sdo[static_cast<std::size_t>(f.status) % sdo.size()], static_cast<unsigned>(f.abort));
    }
    drive_failure = text.data();
  }
  hal::BusCounters bus{};
  firmware::AxisStats axis{};
  std::uint64_t units_held{0};
  std::string drive_state;
  std::string drive_failure;  // empty unless start-up failed
};

bool write_stream_log(const char* path, const std::vector<firmware::TickRecord>& log, std::uint32_t period_us) {
  std::FILE* f = std::fopen(path, "w");
  if (f == nullptr) return false;
  std::fprintf(f, "tick,t,target,sent,moving,move_end,position_actual,load_position,velocity_actual,feedback_count\n");
  for (const auto& r : log) {
    std::fprintf(f, "%llu,%.6f,%d,%d,%d,%d,%d,%d,%d,%llu\n", static_cast<unsigned long long>(r.tick),
                 static_cast<double>(r.tick) * period_us * 1e-6, r.target, r.sent ? 1 : 0, r.moving ? 1 : 0,
                 r.move_end ? 1 : 0, r.position_actual, r.load_position, r.velocity_actual,
                 static_cast<unsigned long long>(r.feedback_count));
  }
  return std::fclose(f) == 0;
}

}  // namespace

int cmd_stream(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("stream", argc, argv, args); rc >= 0) return rc;
  const bool json = args.json();
  RequestError err;
  core::MoveRequest req{};
  if (!parse_move_request(args, req, err)) return report_bad_request(err, json);
  sim::ModalPlant plant{};
  if (!parse_plant(args, plant, err)) return report_bad_request(err, json);
  sim::DriveAxisConfig axis_cfg{};
  if (!parse_drive(args, plant, axis_cfg, err)) return report_bad_request(err, json);
  const std::uint32_t period_us = axis_cfg.scale.period_us;
  core::Move<double> move{};
  if (!plan_move(req, move, err)) return report_bad_request(err, json);
  // Each in its table range: node 1..127, rt priority 0..99, heartbeat 10..10000 ms, SDO timeout
  // 1..60000 ms, settle time (0, 600) s, axis vmax (0, 1e9].
  const long long node = args.integer("--node", 1);
  const long long priority = args.integer("--rt-priority", 0);
  const long long heartbeat = args.integer("--heartbeat-ms", 500);
  const long long sdo_timeout = args.integer("--sdo-timeout-ms", 1000);
  static_assert(firmware::kDefaultFeedbackTimeoutPeriods == 10, "the option table documents the loop's default");
  const long long feedback_timeout = args.integer("--feedback-timeout-periods", firmware::kDefaultFeedbackTimeoutPeriods);
  const double settle_time = args.real("--settle-time", 1.0);
  const double axis_vmax = args.real("--axis-vmax", std::fmax(move.peaks().v, 1e-12) * 1.5);
  const std::string bus_name = args.text("--bus", "vcan0");
  const bool loopback = bus_name == "loopback";

  // Sizes, before anything is allocated: the session's records, the offline replay and the
  // continuous simulation (1e-4 s grid) all grow with the move and the settle time.
  if (move.duration() + settle_time > kMaxSeconds) {
    return report_bad_request({"too_long", "--time",
                               "--time: the move lasts " + format_number(move.duration()) +
                                   " s; at most 3600 s of move + settle time"},
                              json);
  }
  const double periods = (5.0 + move.duration() + settle_time) * 1e6 / period_us;
  if (periods > kMaxStreamPeriods) {
    const char* who = move.duration() >= settle_time ? "--time" : "--settle-time";
    return report_bad_request({"too_many_samples", who,
                               std::string{who} + ": " + format_number(periods) +
                                   " periods of start-up (5 s) + move + settle time; at most 1e6 (or a longer "
                                   "--period-us)"},
                              json);
  }
  // Every setpoint and every load position must fit the drive's 32-bit counts.
  const double reach = std::fabs(move.distance()) * 2.0 + 1.0;
  if (reach * axis_cfg.scale.counts_per_unit > 2e9) {
    return report_bad_request({"out_of_range", "--counts-per-unit",
                               "--counts-per-unit: --distance x --counts-per-unit exceeds 32-bit counts (1e9)"},
                              json);
  }
  if (reach * axis_cfg.load_counts_per_unit > 2e9) {
    return report_bad_request({"out_of_range", "--load-counts-per-unit",
                               "--load-counts-per-unit: --distance x --load-counts-per-unit exceeds 32-bit counts (1e9)"},
                              json);
  }

  firmware::AxisConfig ac{};
  ac.drive.node = static_cast<hal::canopen::NodeId>(node);
  ac.drive.heartbeat_timeout_ms = static_cast<std::uint16_t>(heartbeat);
  ac.drive.sdo_timeout_us = static_cast<std::uint32_t>(sdo_timeout * 1000);
  ac.scale = axis_cfg.scale;
  ac.vmax = axis_vmax;
  ac.feedback_timeout_periods = static_cast<std::uint16_t>(feedback_timeout);  // 0..65535
  firmware::SessionConfig sc{};
  sc.settle_ticks = static_cast<std::uint64_t>(settle_time * 1e6 / period_us);
  sc.enable_timeout_ticks = 5'000'000 / period_us;
  // The drive's own enabling deadline is the session's 5 s window, not RemoteDrive's 1 s default:
  // a host that stalls the process for a second must not fail a drive that enables in time.
  ac.drive.enable_timeout_us = static_cast<std::uint32_t>(sc.enable_timeout_ticks * period_us);
  const std::uint64_t move_ticks = static_cast<std::uint64_t>(move.duration() * 1e6 / period_us) + 2;
  // Completion waits for the feedback to show the target (at most in_position_timeout_periods).
  sc.max_ticks = sc.enable_timeout_ticks + move_ticks + sc.settle_ticks + ac.in_position_timeout_periods + 10;

  Outcome out{};
  // Allocated before the loop starts: no heap use while streaming.
  out.log.reserve(sc.max_ticks + 1);
  out.feedback.reserve(sc.max_ticks + 64);
  firmware::linux_rt::RealtimeSetup rt{};
  firmware::linux_rt::LatencyHistogram latency{};
  std::uint64_t overruns = 0;
  // The setpoints the selected evaluation produces (the replay's), and the double evaluator's.
  std::vector<std::int32_t> sp;
  core::Status evaluation = core::Status::ok;
  // The session, once for each evaluation: -1 when it ran (whatever its outcome), else the exit code.
  const auto session = [&]<typename Scalar, typename Evaluation>(std::type_identity<Scalar>,
                                                                 std::type_identity<Evaluation>) -> int {
    using Loop = LoopOf<Scalar, Evaluation>;
    evaluation = evaluated_setpoints<Evaluation>(move, axis_cfg.scale, sp);
    if (loopback) {
      hal::LoopbackHub hub;
      hal::LoopbackBus<256> master{hub};
      hal::LoopbackBus<256> drive_port{hub};
      // A listening port sees every frame on the in-process bus: the loopback run's candump log.
      hal::LoopbackBus<256> sniffer{hub};
      std::FILE* dump = nullptr;
      if (const auto path = args.text("--candump")) {
        dump = std::fopen(path->c_str(), "w");
        if (dump == nullptr) {
          std::fprintf(stderr, "settle stream: cannot write %s\n", path->c_str());
          return kExitFailure;
        }
      }
      hal::canopen::DriveNodeConfig dc{};
      dc.node = ac.drive.node;
      dc.sync_period_us = period_us;
      sim::DriveAxis axis{};
      if (sim::DriveAxis::make(axis_cfg, plant, 0, axis) != sim::SimStatus::ok) return kExitFailure;
      sim::PlantNode pn{dc, std::move(axis)};
      pn.start(0, drive_port);
      auto loop = std::make_unique<Loop>(master, period_us);
      if (loop->add_axis(ac) != firmware::LoopStatus::ok) return kExitFailure;
      firmware::VirtualClock clock{period_us};
      hub.set_time_us(period_us);  // the first tick
      out.session = firmware::run_session(*loop, clock, &move, 1, 0, sc, [&](std::uint64_t, bool) {
        out.record(*loop);
        hub.set_time_us(clock.now_us());  // the drive answers within this period
        hal::CanFrame f{};
        while (drive_port.receive(f, 0) == hal::ReceiveStatus::received) (void)pn.on_frame(f, clock.now_us(), drive_port);
        pn.poll(clock.now_us(), drive_port);
        std::array<char, 256> line{};
        while (sniffer.receive(f, 0) == hal::ReceiveStatus::received) {
          const std::size_t n = hal::format_candump_line(f, "loopback", line);
          if (dump != nullptr && n > 0) std::fprintf(dump, "%.*s\n", static_cast<int>(n), line.data());
        }
        hub.set_time_us(clock.now_us() + period_us);  // the loop's next tick sends at that time
      });
      if (dump != nullptr) std::fclose(dump);
      out.finish(*loop, master);
    } else {
      hal::SocketCanBus bus;
      const hal::OpenStatus os = open_socketcan(bus, bus_name);
      if (os != hal::OpenStatus::ok) {
        std::fprintf(stderr, "settle stream: cannot open %s: %s (try --bus loopback)\n", bus_name.c_str(),
                     hal::to_string(os));
        return kExitFailure;
      }
      // --candump: this process's own log of every frame it sends and receives (complete, unlike a
      // sniffer's), written between ticks; its line count equals frames_sent + frames_received.
      auto recorder = std::make_unique<hal::RecordingBus<4096>>(bus, hal::realtime_us);
      hal::CandumpFile dump;
      if (const auto path = args.text("--candump"); path && !dump.open(path->c_str(), bus_name.c_str())) {
        std::fprintf(stderr, "settle stream: cannot write %s\n", path->c_str());
        return kExitFailure;
      }
      hal::CanBus& link = dump.is_open() ? static_cast<hal::CanBus&>(*recorder) : bus;
      if (priority > 0) rt = firmware::linux_rt::request_realtime(static_cast<int>(priority));  // 1..99
      auto loop = std::make_unique<Loop>(link, period_us);
      if (loop->add_axis(ac) != firmware::LoopStatus::ok) return kExitFailure;
      RealtimeClock clock{period_us};
      out.session = firmware::run_session(*loop, clock, &move, 1, 0, sc, [&](std::uint64_t, bool) {
        out.record(*loop);
        if (dump.is_open()) (void)dump.write_records(*recorder);
      });
      // The last TPDOs may still be on their way: take them, the way the loop does, before counting.
      hal::CanFrame f{};
      while (link.receive(f, 50000) == hal::ReceiveStatus::received) {
        loop->receive(f, clock.now_us());
        out.drain(*loop);
        if (dump.is_open()) (void)dump.write_records(*recorder);  // the recorder's ring is bounded
      }
      if (dump.is_open() && !(dump.write_records(*recorder) && dump.close())) {
        std::fprintf(stderr, "settle stream: the --candump log is incomplete (%llu records lost or unwritten)\n",
                     static_cast<unsigned long long>(dump.records_lost()));
        return kExitFailure;
      }
      out.finish(*loop, bus);
      latency = clock.timer().latency();
      overruns = clock.timer().overruns();
    }
    return -1;
  };
  const std::string scalar = args.text("--scalar", "double");
  using std::type_identity;
  const int rc =
      scalar == "float"   ? session(type_identity<float>{}, type_identity<firmware::FloatEvaluation<float>>{})
      : scalar == "fixed" ? session(type_identity<double>{}, type_identity<firmware::PolyFixedEvaluation>{})
                          : session(type_identity<double>{}, type_identity<firmware::FloatEvaluation<double>>{});
  if (rc >= 0) return rc;
  if (const auto path = args.text("--log"); path && !write_stream_log(path->c_str(), out.log, period_us)) {
    std::fprintf(stderr, "settle stream: cannot write %s\n", path->c_str());
    return kExitFailure;
  }

  // Offline: the same integer setpoints through the same drive model and plant, no bus.
  sim::Replay replay{};
  const bool have_sp = evaluation == core::Status::ok;
  const bool have_replay =
      have_sp && sim::replay_stream(axis_cfg, plant, 0, sp, sc.settle_ticks, replay) == sim::SimStatus::ok;
  // The double evaluator's setpoints and their replay: what --scalar double streams (its run
  // aligns with exactly this replay), the reference float and fixed are held to.
  std::vector<std::int32_t> sp_double;
  sim::Replay replay_double{};
  const bool have_double =
      evaluated_setpoints<firmware::FloatEvaluation<double>>(move, axis_cfg.scale, sp_double) ==
          core::Status::ok &&
      sim::replay_stream(axis_cfg, plant, 0, sp_double, sc.settle_ticks, replay_double) == sim::SimStatus::ok;
  // Setpoint by setpoint (the shorter sequence held at its last), the largest difference in counts.
  long long sp_max_diff = -1;
  long long sp_differing = 0;
  if (have_sp && have_double) {
    sp_max_diff = 0;
    for (std::size_t i = 0; i < std::max(sp.size(), sp_double.size()); ++i) {
      const std::int64_t a = i < sp.size() ? sp[i] : sp.back();
      const std::int64_t b = i < sp_double.size() ? sp_double[i] : sp_double.back();
      sp_max_diff = std::max<long long>(sp_max_diff, a > b ? a - b : b - a);
      sp_differing += a != b ? 1 : 0;
    }
  }
  // From the CAN feedback: find the replay's period-by-period positions in the received sequence.
  // An exact match proves every setpoint was applied once, in order, with no feedback lost in
  // between; the load samples from the final setpoint on then give the measured residual.
  std::vector<std::int32_t> positions;
  for (const auto& fs : out.feedback) positions.push_back(fs.position_actual);
  const std::optional<std::size_t> found = have_replay ? sim::align_feedback(positions, replay) : std::nullopt;
  const bool aligned = found.has_value();
  const std::size_t offset = found.value_or(0);
  std::vector<std::int32_t> measured;
  if (aligned) {
    for (std::size_t i = replay.move_periods - 1; i < replay.feedback.size(); ++i) {
      measured.push_back(out.feedback[offset + i].load_position);
    }
  }
  const double dt = period_us * 1e-6;
  // Commanded and measured motion per drive period, aligned: what the plots show.
  if (const auto path = args.text("--feedback-log"); path && aligned) {
    std::FILE* f = std::fopen(path->c_str(), "w");
    if (f == nullptr) {
      std::fprintf(stderr, "settle stream: cannot write %s\n", path->c_str());
      return kExitFailure;
    }
    std::fprintf(f, "period,t,commanded,position_can,load_can,load_offline\n");
    const std::size_t o = offset;
    const std::size_t pre = std::min<std::size_t>(o, 50);
    for (std::size_t i = o - pre; i < o + replay.feedback.size(); ++i) {
      const long k = static_cast<long>(i) - static_cast<long>(o);
      const std::int32_t cmd = k < 0 ? sp.front() : (static_cast<std::size_t>(k) < sp.size() ? sp[static_cast<std::size_t>(k)] : sp.back());
      const std::int32_t off_load = k < 0 ? out.feedback[i].load_position : replay.feedback[static_cast<std::size_t>(k)].load_position;
      std::fprintf(f, "%ld,%.6f,%d,%d,%d,%d\n", k, static_cast<double>(k + 1) * dt, cmd, out.feedback[i].position_actual,
                   out.feedback[i].load_position, off_load);
    }
    std::fclose(f);
  }
  sim::SampledResidual can{}, off{};
  if (sim::fitted_residual(measured, axis_cfg.load_counts_per_unit, replay.final_load, dt, plant,
                           replay.step_residual, can) != sim::SimStatus::ok ||
      sim::fitted_residual(replay.load_after, axis_cfg.load_counts_per_unit, replay.final_load, dt, plant,
                           replay.step_residual, off) != sim::SimStatus::ok) {
    can.amplitude = off.amplitude = can.prv_percent = off.prv_percent = NAN;
  }
  sim::SampledResidual off_double{};
  if (!have_double || sim::fitted_residual(replay_double.load_after, axis_cfg.load_counts_per_unit,
                                           replay_double.final_load, dt, plant, replay_double.step_residual,
                                           off_double) != sim::SimStatus::ok) {
    off_double.amplitude = NAN;
  }
  // The residual measured over CAN against the double run's (its aligned replay), in percent.
  const double vs_double =
      aligned ? std::fabs(can.amplitude - off_double.amplitude) / off_double.amplitude * 100.0 : double{NAN};
  sim::SimResult cont{};
  sim::SimOptions so{};
  so.record = false;
  // The residual is exact at the move's end whatever the grid; the grid only samples the peak
  // deflection and the settling time, so a long move takes a coarser one (at most 2e6 steps x modes).
  so.dt = std::max(so.dt, move.duration() * static_cast<double>(plant.modes().size()) / kMaxSimWork);
  const bool have_cont = sim::simulate(plant, sim::MoveCommand{move}, so, cont) == sim::SimStatus::ok;
  const double agreement = aligned ? std::fabs(can.amplitude - off.amplitude) : double{NAN};
  std::uint64_t late = 0;
  for (std::size_t i = 1; i < out.log.size(); ++i) {
    if (out.log[i].feedback_count != out.log[i - 1].feedback_count + 1 && out.log[i].feedback_count > 0) ++late;
  }
  // Frames the bus dropped on our side (a full receive queue); the drive's side reports its own.
  // A setpoint or feedback lost within the move would also have broken the alignment above.
  const auto lost = static_cast<long long>(out.bus.rx_overflow_drops + out.bus.tx_errors);

  const bool completed = out.session.outcome == firmware::SessionOutcome::completed && aligned;
  const Json j{
      {"status", completed ? "ok" : "error"},
      {"outcome", firmware::to_string(out.session.outcome)},
      {"fault", firmware::to_string(out.session.fault)},
      {"drive_state", out.drive_state},
      {"drive_failure", out.drive_failure},
      {"bus", loopback ? "loopback (in-process, virtual time)" : bus_name},
      {"profile", core::to_string(move.profile().kind())},
      {"scalar", scalar},
      // Why the selected evaluation refused the move ("ok" when it took it), e.g. a profile the
      // fixed-point formats cannot hold.
      {"evaluation", core::to_string(evaluation)},
      {"setpoints", static_cast<long long>(sp.size())},
      // Against the double evaluator's setpoints (null when either evaluation refused the move).
      {"setpoints_vs_double_max_counts", sp_max_diff < 0 ? Json(nullptr) : Json(sp_max_diff)},
      {"setpoints_differing_from_double", sp_max_diff < 0 ? Json(nullptr) : Json(sp_differing)},
      {"distance", move.distance()},
      {"move_time", move.duration()},
      {"period_us", static_cast<long long>(period_us)},
      {"ticks", static_cast<long long>(out.session.ticks)},
      {"frames_sent", static_cast<long long>(out.bus.sent)},
      {"frames_received", static_cast<long long>(out.bus.received)},
      {"tx_busy", static_cast<long long>(out.bus.tx_busy)},
      {"rx_overflow_drops", static_cast<long long>(out.bus.rx_overflow_drops)},
      {"feedback_samples", static_cast<long long>(out.feedback.size())},
      {"feedback_late_ticks", static_cast<long long>(late)},
      {"aligned", aligned},
      {"frames_lost", lost},
      {"overruns", static_cast<long long>(overruns)},
      {"skipped_periods", static_cast<long long>(out.session.missed_periods)},
      {"rpdo_sent", static_cast<long long>(out.axis.rpdo_sent)},
      {"step_guard_trips", static_cast<long long>(out.axis.step_guard_trips)},
      {"heartbeat_losses", static_cast<long long>(out.axis.heartbeat_losses)},
      {"emcy_received", static_cast<long long>(out.axis.emcy_received)},
      {"drive_restarts", static_cast<long long>(out.axis.restarts)},
      {"moves_aborted", static_cast<long long>(out.axis.moves_aborted)},
      {"max_following_error", static_cast<long long>(out.axis.max_following_error)},
      {"feedback_overflows", static_cast<long long>(out.axis.feedback_overflows)},
      {"feedback_timeouts", static_cast<long long>(out.axis.feedback_timeouts)},
      {"units_held", static_cast<long long>(out.units_held)},
      // Absent (null) when there is nothing to measure: the move did not complete, or the
      // feedback did not match the setpoints.
      {"residual_can", finite_or_null(can.amplitude)},
      {"prv_can_percent", finite_or_null(can.prv_percent)},
      {"residual_offline", finite_or_null(off.amplitude)},
      {"prv_offline_percent", finite_or_null(off.prv_percent)},
      {"agreement", finite_or_null(agreement)},
      {"residual_double", finite_or_null(off_double.amplitude)},
      {"residual_vs_double_percent", finite_or_null(vs_double)},
      // The same difference in load counts: what it is next to the measurement's resolution.
      {"residual_vs_double_load_counts",
       finite_or_null(std::fabs(can.amplitude - off_double.amplitude) * axis_cfg.load_counts_per_unit)},
      {"fit_rms_can", finite_or_null(can.fit_rms)},
      {"residual_continuous", have_cont ? finite_or_null(cont.metrics.residual_amplitude) : Json(nullptr)},
      {"prv_continuous_percent", have_cont ? finite_or_null(cont.metrics.prv_percent) : Json(nullptr)},
      {"window_samples", static_cast<long long>(measured.size())},
      {"latency_ns", Json{{"count", static_cast<long long>(latency.count())},
                          {"min", static_cast<long long>(latency.min_ns())},
                          {"p50", static_cast<long long>(latency.quantile_ns(0.5))},
                          {"p99", static_cast<long long>(latency.quantile_ns(0.99))},
                          {"max", static_cast<long long>(latency.max_ns())}}},
      {"realtime", Json{{"sched_fifo", rt.fifo},
                        {"sched_fifo_error", rt.fifo_error},
                        {"mlockall", rt.locked},
                        {"mlockall_error", rt.lock_error}}},
  };
  // Success is reported only with every measurement present and finite.
  const bool measured_ok = completed && !j["residual_can"].is_null() && !j["residual_offline"].is_null() &&
                           !j["agreement"].is_null() && !j["residual_continuous"].is_null();
  if (json) {
    Json doc = j;
    if (!measured_ok) doc["status"] = "error";
    print_json(doc);
  } else {
    std::printf("outcome            %s on %s%s%s\n", firmware::to_string(out.session.outcome),
                loopback ? "loopback (in-process, virtual time)" : bus_name.c_str(),
                out.session.fault == firmware::AxisFault::none ? "" : ", fault: ",
                out.session.fault == firmware::AxisFault::none ? "" : firmware::to_string(out.session.fault));
    std::printf("frames             sent %llu, received %llu, tx busy %llu, late feedback ticks %llu, %s\n",
                static_cast<unsigned long long>(out.bus.sent), static_cast<unsigned long long>(out.bus.received),
                static_cast<unsigned long long>(out.bus.tx_busy), static_cast<unsigned long long>(late),
                aligned ? "every setpoint applied once, in order" : "FEEDBACK DOES NOT MATCH THE SETPOINTS");
    // A measurement that is absent (no aligned feedback) is "n/a", never a printed nan.
    auto g = [](double v, const char* f) {
      if (!std::isfinite(v)) return std::string{"n/a"};
      std::array<char, 32> b{};
      std::snprintf(b.data(), b.size(), f, v);
      return std::string{b.data()};
    };
    std::printf("residual (CAN)     %s (PRV %s %%)\n", g(can.amplitude, "%.9g").c_str(), g(can.prv_percent, "%.4f").c_str());
    std::printf("residual (offline) %s (PRV %s %%), agreement %s\n", g(off.amplitude, "%.9g").c_str(),
                g(off.prv_percent, "%.4f").c_str(), g(agreement, "%.3g").c_str());
    if (!have_sp) std::printf("evaluation         %s refused the move: %s\n", scalar.c_str(), core::to_string(evaluation));
    std::printf("scalar             %s: setpoints within %s counts of double's (%lld differ), residual %s %% "
                "from double's %s\n",
                scalar.c_str(), sp_max_diff < 0 ? "n/a" : std::to_string(sp_max_diff).c_str(), sp_differing,
                g(vs_double, "%.3g").c_str(), g(off_double.amplitude, "%.9g").c_str());
    if (have_cont) {
      std::printf("continuous profile %s (PRV %s %%)\n", g(cont.metrics.residual_amplitude, "%.9g").c_str(),
                  g(cont.metrics.prv_percent, "%.4f").c_str());
    }
    if (!loopback) {
      std::printf("wake-up latency    min %lld p50 %lld p99 %lld max %lld ns, overruns %llu%s\n",
                  static_cast<long long>(latency.min_ns()), static_cast<long long>(latency.quantile_ns(0.5)),
                  static_cast<long long>(latency.quantile_ns(0.99)), static_cast<long long>(latency.max_ns()),
                  static_cast<unsigned long long>(overruns),
                  rt.fifo ? "" : " (SCHED_FIFO not used: pass --rt-priority N as root)");
    }
  }
  return measured_ok ? kExitOk : kExitFailure;
}

}  // namespace settle::cli
