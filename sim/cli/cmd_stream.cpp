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
#include <vector>

#include "commands.hpp"
#include "json.hpp"
#include "move_options.hpp"
#include "plant_options.hpp"
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

using Loop = firmware::ServoLoop<double, 1, 4>;

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
  void record(Loop& loop) {
    log.push_back(loop.record(0));
    drain(loop);
  }
  void drain(Loop& loop) {
    for (firmware::FeedbackSample fs{}; loop.feedback_log(0).pop(fs);) feedback.push_back(fs);
  }
  // After the session: the counters, and where the drive's start-up stands (why, when it failed).
  void finish(const Loop& loop, const hal::CanBus& on) {
    bus = on.counters();
    axis = loop.axis_stats(0);
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
  std::set<std::string> values = kMoveValueOptions;
  values.insert(kPlantValueOptions.begin(), kPlantValueOptions.end());
  values.insert(kDriveValueOptions.begin(), kDriveValueOptions.end());
  values.insert({"--bus", "--node", "--axis-vmax", "--settle-time", "--log", "--rt-priority", "--heartbeat-ms",
                 "--candump", "--sdo-timeout-ms", "--feedback-log"});
  const Args args{argc, argv, values, kMoveFlagOptions};
  const bool json = args.flag("--json");
  if (!args.ok()) return report_bad_request({"bad_option", args.error_param(), args.error()}, json);
  RequestError err;
  core::MoveRequest req{};
  if (!parse_move_request(args, req, err)) return report_bad_request(err, json);
  sim::ModalPlant plant{};
  if (!parse_plant(args, plant, err)) return report_bad_request(err, json);
  sim::DriveAxisConfig axis_cfg{};
  std::uint32_t period_us = 1000;
  if (!parse_drive(args, plant, axis_cfg, period_us, err)) return report_bad_request(err, json);
  core::Move<double> move{};
  if (!plan_move(req, move, err)) return report_bad_request(err, json);
  double node = 1, axis_vmax = std::fmax(move.peaks().v, 1e-12) * 1.5, settle_time = 1.0, priority = 0,
         heartbeat = 500, sdo_timeout = 1000;
  for (auto [name, v] : {std::pair{"--node", &node}, std::pair{"--axis-vmax", &axis_vmax},
                         std::pair{"--settle-time", &settle_time}, std::pair{"--rt-priority", &priority},
                         std::pair{"--heartbeat-ms", &heartbeat}, std::pair{"--sdo-timeout-ms", &sdo_timeout}}) {
    if (!read_number(args, name, *v, err)) return report_bad_request(err, json);
  }
  if (!(settle_time > 0.0 && settle_time < 600.0)) {
    return report_bad_request({"bad_number", "--settle-time", "--settle-time: seconds in (0, 600)"}, json);
  }
  const std::string bus_name = args.get("--bus").value_or("vcan0");
  const bool loopback = bus_name == "loopback";

  firmware::AxisConfig ac{};
  ac.drive.node = static_cast<hal::canopen::NodeId>(node);
  ac.drive.heartbeat_timeout_ms = static_cast<std::uint16_t>(heartbeat);
  ac.drive.sdo_timeout_us = static_cast<std::uint32_t>(sdo_timeout * 1000.0);
  ac.counts_per_unit = axis_cfg.counts_per_unit;
  ac.vmax = axis_vmax;
  firmware::SessionConfig sc{};
  sc.settle_ticks = static_cast<std::uint64_t>(settle_time * 1e6 / period_us);
  sc.enable_timeout_ticks = 5'000'000 / period_us;
  // The drive's own enabling deadline is the session's 5 s window, not RemoteDrive's 1 s default:
  // a host that stalls the process for a second must not fail a drive that enables in time.
  ac.drive.enable_timeout_us = static_cast<std::uint32_t>(sc.enable_timeout_ticks * period_us);
  const std::uint64_t move_ticks = static_cast<std::uint64_t>(move.duration() * 1e6 / period_us) + 2;
  sc.max_ticks = sc.enable_timeout_ticks + move_ticks + sc.settle_ticks + 10;

  Outcome out{};
  // Allocated before the loop starts: no heap use while streaming.
  out.log.reserve(sc.max_ticks + 1);
  out.feedback.reserve(sc.max_ticks + 64);
  firmware::linux_rt::RealtimeSetup rt{};
  firmware::linux_rt::LatencyHistogram latency{};
  std::uint64_t overruns = 0;
  if (loopback) {
    hal::LoopbackHub hub;
    hal::LoopbackBus<256> master{hub};
    hal::LoopbackBus<256> drive_port{hub};
    // A listening port sees every frame on the in-process bus: the loopback run's candump log.
    hal::LoopbackBus<256> sniffer{hub};
    std::FILE* dump = nullptr;
    if (const auto path = args.get("--candump")) {
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
    auto recorder = std::make_unique<hal::RecordingBus<1024>>(bus, hal::realtime_us);
    hal::CandumpFile dump;
    if (const auto path = args.get("--candump"); path && !dump.open(path->c_str(), bus_name.c_str())) {
      std::fprintf(stderr, "settle stream: cannot write %s\n", path->c_str());
      return kExitFailure;
    }
    hal::CanBus& link = dump.is_open() ? static_cast<hal::CanBus&>(*recorder) : bus;
    if (priority > 0) rt = firmware::linux_rt::request_realtime(static_cast<int>(priority));
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
  if (const auto path = args.get("--log"); path && !write_stream_log(path->c_str(), out.log, period_us)) {
    std::fprintf(stderr, "settle stream: cannot write %s\n", path->c_str());
    return kExitFailure;
  }

  // Offline: the same integer setpoints through the same drive model and plant, no bus.
  std::vector<std::int32_t> sp;
  sim::Replay replay{};
  const bool have_replay =
      sim::stream_setpoints(move, period_us, axis_cfg.counts_per_unit, 0, sp) == sim::SimStatus::ok &&
      sim::replay_stream(axis_cfg, plant, 0, sp, sc.settle_ticks, replay) == sim::SimStatus::ok;
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
  if (const auto path = args.get("--feedback-log"); path && aligned) {
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
  sim::SimResult cont{};
  sim::SimOptions so{};
  so.record = false;
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
  if (json) {
    JsonWriter w{stdout};
    w.begin_object()
        .field("status", completed ? "ok" : "error")
        .field("outcome", firmware::to_string(out.session.outcome))
        .field("drive_state", out.drive_state.c_str())
        .field("drive_failure", out.drive_failure.c_str())
        .field("bus", loopback ? "loopback (in-process, virtual time)" : bus_name.c_str())
        .field("profile", core::to_string(move.profile().kind()))
        .field("distance", move.distance())
        .field("move_time", move.duration())
        .field("period_us", static_cast<long long>(period_us))
        .field("ticks", static_cast<long long>(out.session.ticks))
        .field("frames_sent", static_cast<long long>(out.bus.sent))
        .field("frames_received", static_cast<long long>(out.bus.received))
        .field("tx_busy", static_cast<long long>(out.bus.tx_busy))
        .field("rx_overflow_drops", static_cast<long long>(out.bus.rx_overflow_drops))
        .field("feedback_samples", static_cast<long long>(out.feedback.size()))
        .field("feedback_late_ticks", static_cast<long long>(late))
        .field("aligned", aligned)
        .field("frames_lost", lost)
        .field("overruns", static_cast<long long>(overruns))
        .field("skipped_periods", static_cast<long long>(out.session.missed_periods))
        .field("rpdo_sent", static_cast<long long>(out.axis.rpdo_sent))
        .field("step_guard_trips", static_cast<long long>(out.axis.step_guard_trips))
        .field("heartbeat_losses", static_cast<long long>(out.axis.heartbeat_losses))
        .field("emcy_received", static_cast<long long>(out.axis.emcy_received))
        .field("drive_restarts", static_cast<long long>(out.axis.restarts))
        .field("moves_aborted", static_cast<long long>(out.axis.moves_aborted))
        .field("max_following_error", static_cast<long long>(out.axis.max_following_error))
        .field("feedback_overflows", static_cast<long long>(out.axis.feedback_overflows))
        .field("residual_can", can.amplitude)
        .field("prv_can_percent", can.prv_percent)
        .field("residual_offline", off.amplitude)
        .field("prv_offline_percent", off.prv_percent)
        .field("agreement", agreement)
        .field("fit_rms_can", can.fit_rms)
        .field("residual_continuous", have_cont ? cont.metrics.residual_amplitude : double{NAN})
        .field("prv_continuous_percent", have_cont ? cont.metrics.prv_percent : double{NAN})
        .field("window_samples", static_cast<long long>(measured.size()));
    w.key("latency_ns")
        .begin_object()
        .field("count", static_cast<long long>(latency.count()))
        .field("min", static_cast<long long>(latency.min_ns()))
        .field("p50", static_cast<long long>(latency.quantile_ns(0.5)))
        .field("p99", static_cast<long long>(latency.quantile_ns(0.99)))
        .field("max", static_cast<long long>(latency.max_ns()))
        .end_object();
    w.key("realtime")
        .begin_object()
        .field("sched_fifo", rt.fifo)
        .field("sched_fifo_error", rt.fifo_error)
        .field("mlockall", rt.locked)
        .field("mlockall_error", rt.lock_error)
        .end_object();
    w.end_object().finish();
  } else {
    std::printf("outcome            %s on %s\n", firmware::to_string(out.session.outcome),
                loopback ? "loopback (in-process, virtual time)" : bus_name.c_str());
    std::printf("frames             sent %llu, received %llu, tx busy %llu, late feedback ticks %llu, %s\n",
                static_cast<unsigned long long>(out.bus.sent), static_cast<unsigned long long>(out.bus.received),
                static_cast<unsigned long long>(out.bus.tx_busy), static_cast<unsigned long long>(late),
                aligned ? "every setpoint applied once, in order" : "FEEDBACK DOES NOT MATCH THE SETPOINTS");
    std::printf("residual (CAN)     %.9g (PRV %.4f %%)\n", can.amplitude, can.prv_percent);
    std::printf("residual (offline) %.9g (PRV %.4f %%), agreement %.3g\n", off.amplitude, off.prv_percent, agreement);
    if (have_cont) {
      std::printf("continuous profile %.9g (PRV %.4f %%)\n", cont.metrics.residual_amplitude, cont.metrics.prv_percent);
    }
    if (!loopback) {
      std::printf("wake-up latency    min %lld p50 %lld p99 %lld max %lld ns, overruns %llu%s\n",
                  static_cast<long long>(latency.min_ns()), static_cast<long long>(latency.quantile_ns(0.5)),
                  static_cast<long long>(latency.quantile_ns(0.99)), static_cast<long long>(latency.max_ns()),
                  static_cast<unsigned long long>(overruns),
                  rt.fifo ? "" : " (SCHED_FIFO not used: pass --rt-priority N as root)");
    }
  }
  return completed ? kExitOk : kExitFailure;
}

}  // namespace settle::cli
