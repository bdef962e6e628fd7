// SPDX-License-Identifier: Apache-2.0
#include "demo.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "settle/papers/figures.hpp"
#include "settle/testbed/spawn.hpp"
#include "socketcan_open.hpp"

namespace settle::app {

namespace {

namespace fs = std::filesystem;
namespace co = hal::canopen;

constexpr co::NodeId kNode = 1;
// A bound on a hang (a drive that never boots, never answers), not a readiness delay.
constexpr std::chrono::seconds kGuard{60};
// The object the barrier reads: the identity's serial number, which no master here reads.
constexpr std::uint16_t kBarrierIndex = 0x1018;
constexpr std::uint8_t kBarrierSub = 4;

std::string num(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string path_in(const std::string& dir, const std::string& name) { return (fs::path{dir} / name).string(); }

// The harness's own CAN node for one drive process: opened before the process starts, so that
// its boot-up cannot be missed; it hears only the drive's heartbeats and SDO answers.
class DriveWatch {
 public:
  [[nodiscard]] hal::OpenStatus open(const std::string& iface) {
    const hal::OpenStatus st = open_socketcan(bus_, iface);
    if (st != hal::OpenStatus::ok) return st;
    const hal::CanFilter filters[] = {
        {co::cob_id(co::cob::heartbeat, kNode), 0x7FF, hal::FrameFormat::standard},
        {co::cob_id(co::cob::sdo_tx, kNode), 0x7FF, hal::FrameFormat::standard},
    };
    if (bus_.set_filters(filters) != hal::BusStatus::ok) return hal::OpenStatus::error;
    return st;
  }

  // The drive's boot-up or heartbeat: its socket is open and it takes frames from now on.
  [[nodiscard]] bool wait_heartbeat(testbed::ChildProcess& drive, std::string& why) {
    return wait_for(
        [](const hal::CanFrame& f) {
          return f.id == co::cob_id(co::cob::heartbeat, kNode) && co::decode_heartbeat(f).has_value();
        },
        drive, "the drive's boot-up or heartbeat", why);
  }

  // Sends an SDO upload and waits for the answer (the value or an abort). The drive takes the
  // frames of its queue in order, so it has then taken every frame sent on the bus before.
  [[nodiscard]] bool barrier(testbed::ChildProcess& drive, std::string& why) {
    hal::CanFrame f{};
    while (bus_.receive(f, 0) == hal::ReceiveStatus::received) {  // answers queued before are not this one's
    }
    const hal::CanFrame request = co::encode_sdo_upload_request(kNode, kBarrierIndex, kBarrierSub);
    const auto end = std::chrono::steady_clock::now() + kGuard;
    hal::SendStatus sent = bus_.send(request);
    while (sent == hal::SendStatus::busy && std::chrono::steady_clock::now() < end) {
      hal::CanFrame ignored{};
      (void)bus_.receive(ignored, 1000);  // a full transmit queue drains within a frame time
      sent = bus_.send(request);
    }
    if (sent != hal::SendStatus::sent) {
      why = "the barrier SDO could not be sent";
      return false;
    }
    return wait_for(
        [](const hal::CanFrame& fr) {
          const auto m = co::decode_sdo_response(fr, kNode);
          return m && m->index == kBarrierIndex && m->sub == kBarrierSub &&
                 (m->kind == co::SdoKind::upload_response || m->kind == co::SdoKind::abort);
        },
        drive, "the drive's answer to the barrier SDO", why);
  }

 private:
  template <typename Match>
  bool wait_for(Match match, testbed::ChildProcess& drive, const char* what, std::string& why) {
    const auto end = std::chrono::steady_clock::now() + kGuard;
    hal::CanFrame f{};
    while (std::chrono::steady_clock::now() < end) {
      const hal::ReceiveStatus rs = bus_.receive(f, 100'000);
      if (rs == hal::ReceiveStatus::received && match(f)) return true;
      if (rs == hal::ReceiveStatus::error) {
        why = std::string{what} + ": receive failed (errno " + std::to_string(bus_.last_errno()) + ")";
        return false;
      }
      if (!drive.running()) {
        why = std::string{what} + ": the drive process has exited";
        return false;
      }
    }
    why = std::string{what} + ": not seen within " + std::to_string(kGuard.count()) + " s";
    return false;
  }

  hal::SocketCanBus bus_;
};

std::optional<Json> read_json(const std::string& path, std::string& why) {
  std::ifstream in{path};
  if (!in) {
    why = "no " + fs::path{path}.filename().string();
    return std::nullopt;
  }
  Json j = Json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    why = fs::path{path}.filename().string() + " is not one JSON object";
    return std::nullopt;
  }
  return j;
}

long long count_lines(const std::string& path) {
  std::ifstream in{path};
  if (!in) return 0;
  return static_cast<long long>(std::count(std::istreambuf_iterator<char>{in}, std::istreambuf_iterator<char>{}, '\n'));
}

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// `settle stream` on the scenario: the common part of every run's command line.
std::vector<std::string> stream_argv(const DemoSpec& spec, const PaperScenario& s, const std::string& bus) {
  std::vector<std::string> v{spec.settle, "stream", "--bus", bus};
  v = concat(concat(v, s.plant), s.move);
  return concat(v, {"--axis-vmax", num("%g", s.axis_vmax), "--settle-time", "1"});
}

testbed::SpawnOptions to_files(const std::string& out, const std::string& err) {
  testbed::SpawnOptions o;
  o.output = testbed::SpawnOutput::to_file;
  o.output_file = out;
  o.error_file = err;
  return o;
}

std::string spawn_failure(const char* what, const testbed::SpawnResult& r) {
  return std::string{what} + " could not be started: " + to_string(r.status) + " (errno " +
         std::to_string(r.error) + ")";
}

// Every file a run of the demo writes for one scenario: removed first, so that a file left by an
// earlier run (a plant summary after a loopback run) is never read as this run's.
void remove_outputs(const std::string& dir, const std::string& id) {
  std::vector<std::string> names{"plant-" + id + ".json",    "plant-" + id + ".csv",  "plant-" + id + ".err",
                                 "stream-" + id + ".json",   "stream-" + id + ".csv", "stream-" + id + ".err",
                                 "stream-" + id + ".log",    "feedback-" + id + ".csv", "bus-" + id + ".log",
                                 id + ".png",                id + ".gp"};
  for (const char* sc : kDemoScalars) {
    names.push_back("scalar-" + std::string{sc} + "-" + id + ".json");
    names.push_back("scalar-" + std::string{sc} + "-" + id + ".err");
  }
  std::error_code ec;
  for (const std::string& n : names) fs::remove(path_in(dir, n), ec);
}

// Every file the commissioning scenario writes, removed first (as remove_outputs does).
void remove_commissioning_outputs(const std::string& dir, const std::string& id) {
  std::error_code ec;
  for (const std::string step : {"identify-", "tune-", "stream-"}) {
    for (const char* ext : {".json", ".err", ".log", ".csv"}) fs::remove(path_in(dir, step + id + ext), ec);
  }
  for (const std::string& n : {"feedback-" + id + ".csv", "plant-" + id + "-identify.json",
                               "plant-" + id + "-identify.csv", "plant-" + id + "-identify.err",
                               "plant-" + id + "-stream.json", "plant-" + id + "-stream.csv",
                               "plant-" + id + "-stream.err"}) {
    fs::remove(path_in(dir, n), ec);
  }
}

// The drive and the loop run with their default timeouts: `--timing sim` (options.cpp), which
// tolerates a stalled user-mode-linux guest on a loaded host. The plant is SYNC-driven, so a stall
// delays the physics but never changes it. No SCHED_FIFO for the loop: in the guest both processes
// share one CPU, and a loop kept late by a loaded host would starve the drive's process (see
// tests/e2e/e2e.py).

struct DriveSession {
  bool ran{false};    // the master's process ran to its end (its JSON says how it went)
  std::string error;  // why not, or why the session's end could not be confirmed
};

// One session against a drive process on spec.bus: `settle plant` with the plant's options (its
// summary in plant-<tag>.json, its log plant-<tag>.csv), ready once its boot-up or heartbeat is on
// the bus; the master's process `master` run to its end (stdout to <master_out>.json, stderr to
// .err); the barrier, SIGTERM.
DriveSession drive_session(const DemoSpec& spec, const std::vector<std::string>& plant, const std::string& tag,
                           const std::vector<std::string>& master, const std::string& master_out) {
  DriveSession d;
  DriveWatch watch;
  if (const hal::OpenStatus st = watch.open(spec.bus); st != hal::OpenStatus::ok) {
    d.error = "cannot open " + spec.bus + ": " + hal::to_string(st);
    return d;
  }
  const std::vector<std::string> plant_argv =
      concat(concat({spec.settle, "plant", "--bus", spec.bus}, plant),
             {"--log", path_in(spec.out, "plant-" + tag + ".csv"), "--json"});
  testbed::ChildProcess drive;
  testbed::SpawnResult r = testbed::start_program(
      plant_argv, to_files(path_in(spec.out, "plant-" + tag + ".json"), path_in(spec.out, "plant-" + tag + ".err")),
      drive);
  if (r.status != testbed::SpawnStatus::ok) {
    d.error = spawn_failure("settle plant", r);
    return d;
  }
  if (!watch.wait_heartbeat(drive, d.error)) return d;  // the drive is killed with `drive`
  r = testbed::run_program(master, to_files(master_out + ".json", master_out + ".err"));
  if (r.status != testbed::SpawnStatus::ok && r.status != testbed::SpawnStatus::exit_nonzero) {
    d.error = spawn_failure(("settle " + master.at(1)).c_str(), r);
    return d;
  }
  d.ran = true;
  (void)watch.barrier(drive, d.error);
  drive.signal(SIGTERM);
  (void)drive.wait();
  return d;
}

// One scenario over SocketCAN: the drive process and the loop process (drive_session), and both
// JSON summaries.
void run_socketcan(const DemoSpec& spec, DemoRun& run) {
  const PaperScenario& s = run.scenario;
  const std::string& id = s.id;
  const std::vector<std::string> loop_argv = concat(
      stream_argv(spec, s, spec.bus),
      {"--log", path_in(spec.out, "stream-" + id + ".csv"), "--feedback-log", path_in(spec.out, "feedback-" + id + ".csv"),
       "--candump", path_in(spec.out, "stream-" + id + ".log"), "--json"});
  const DriveSession d = drive_session(spec, s.plant, id, loop_argv, path_in(spec.out, "stream-" + id));
  if (!d.ran) {
    run.error = d.error;
    return;
  }
  std::string why;
  run.stream = read_json(path_in(spec.out, "stream-" + id + ".json"), why);
  if (!run.stream) run.error = why;
  run.plant = read_json(path_in(spec.out, "plant-" + id + ".json"), why);
  run.logged = count_lines(path_in(spec.out, "stream-" + id + ".log"));
  if (!d.error.empty() && run.error.empty()) run.error = d.error;
}

void run_loopback(const DemoSpec& spec, DemoRun& run) {
  const std::string& id = run.scenario.id;
  const std::vector<std::string> argv =
      concat(stream_argv(spec, run.scenario, "loopback"),
             {"--log", path_in(spec.out, "stream-" + id + ".csv"), "--feedback-log",
              path_in(spec.out, "feedback-" + id + ".csv"), "--candump", path_in(spec.out, "bus-" + id + ".log"), "--json"});
  const testbed::SpawnResult r = testbed::run_program(
      argv, to_files(path_in(spec.out, "stream-" + id + ".json"), path_in(spec.out, "stream-" + id + ".err")));
  if (r.status != testbed::SpawnStatus::ok && r.status != testbed::SpawnStatus::exit_nonzero) {
    run.error = spawn_failure("settle stream", r);
    return;
  }
  run.stream = read_json(path_in(spec.out, "stream-" + id + ".json"), run.error);
}

// The loop's three evaluations on the loopback bus, in virtual time: quick, where three real-time
// runs per scenario on a SocketCAN bus would triple the demo. Each run is proven against the
// replay of its own evaluation's setpoints.
void run_scalars(const DemoSpec& spec, DemoScalarRuns& runs) {
  const std::string& id = runs.scenario.id;
  for (std::size_t k = 0; k < kDemoScalars.size(); ++k) {
    const std::string sc = kDemoScalars[k];
    const std::string base = path_in(spec.out, "scalar-" + sc + "-" + id);
    const std::vector<std::string> argv =
        concat(stream_argv(spec, runs.scenario, "loopback"), {"--scalar", sc, "--json"});
    const testbed::SpawnResult r = testbed::run_program(argv, to_files(base + ".json", base + ".err"));
    std::string why;
    if (r.status == testbed::SpawnStatus::ok || r.status == testbed::SpawnStatus::exit_nonzero) {
      runs.runs[k] = read_json(base + ".json", why);
    }
  }
}

// A process run to its end, its stdout (one JSON object) in <base>.json and its stderr in <base>.err.
std::optional<Json> run_to_json(const std::vector<std::string>& argv, const std::string& base, std::string& why) {
  const testbed::SpawnResult r = testbed::run_program(argv, to_files(base + ".json", base + ".err"));
  if (r.status != testbed::SpawnStatus::ok && r.status != testbed::SpawnStatus::exit_nonzero) {
    why = spawn_failure(("settle " + argv.at(1)).c_str(), r);
    return std::nullopt;
  }
  return read_json(base + ".json", why);
}

// The commissioning scenario: settle identify measures the modes from the drive's frames (on
// SocketCAN against a `settle plant` process that alone has the plant's options; on loopback its
// in-process drive), settle tune plans the move for what was measured, and settle stream streams
// that plan (--plan-from) to the same kind of drive. The stream is given the true plant only to
// measure the residual from the feedback (as every scenario's is); the plan comes from the tune.
void run_commissioning(const DemoSpec& spec, const CommissioningScenario& c, bool socketcan, CommissioningResult& res) {
  const std::string id = c.id;
  const std::string identify_base = path_in(spec.out, "identify-" + id);
  const std::string tune_base = path_in(spec.out, "tune-" + id);
  const std::string stream_base = path_in(spec.out, "stream-" + id);
  std::string why;
  // 1. identify
  std::vector<std::string> identify{spec.settle, "identify", "--bus", socketcan ? spec.bus : "loopback"};
  identify = concat(identify, c.identify);
  if (socketcan) {
    identify = concat(identify, {"--candump", identify_base + ".log", "--json"});
    const DriveSession d = drive_session(spec, concat(c.plant, c.noise), id + "-identify", identify, identify_base);
    res.plant_identify = read_json(path_in(spec.out, "plant-" + id + "-identify.json"), why);
    if (!d.ran || !d.error.empty()) {
      res.error = "settle identify: " + d.error;
      return;
    }
    res.identify = read_json(identify_base + ".json", why);
  } else {
    identify = concat(concat(concat(identify, c.plant), c.noise), {"--candump", identify_base + ".log", "--json"});
    res.identify = run_to_json(identify, identify_base, why);
  }
  if (!res.identify || res.identify->value("status", "") != "ok") {
    if (!res.identify) res.error = "settle identify: " + why;
    return;  // judge() says why
  }
  // 2. tune, from the identified modes and their intervals only
  res.tune = run_to_json(concat(concat({spec.settle, "tune", "--modes-from", identify_base + ".json"}, c.tune), {"--json"}),
                         tune_base, why);
  if (!res.tune || res.tune->value("status", "") != "ok") {
    if (!res.tune) res.error = "settle tune: " + why;
    return;
  }
  // 3. stream the tuned plan
  std::vector<std::string> stream{spec.settle, "stream", "--bus", socketcan ? spec.bus : "loopback", "--plan-from",
                                  tune_base + ".json"};
  stream = concat(concat(stream, c.plant), {"--settle-time", "1", "--log", stream_base + ".csv", "--feedback-log",
                                            path_in(spec.out, "feedback-" + id + ".csv"), "--candump",
                                            stream_base + ".log", "--json"});
  if (socketcan) {
    const DriveSession d = drive_session(spec, concat(c.plant, c.noise), id + "-stream", stream, stream_base);
    res.plant_stream = read_json(path_in(spec.out, "plant-" + id + "-stream.json"), why);
    if (!d.ran || !d.error.empty()) {
      res.error = "settle stream: " + d.error;
      return;
    }
    res.stream = read_json(stream_base + ".json", why);
  } else {
    res.stream = run_to_json(stream, stream_base, why);
  }
  if (!res.stream) res.error = "settle stream: " + why;
}

// Appends `from` to `to`; false if either cannot be read or written.
bool append_file(const std::string& from, std::ofstream& to) {
  std::ifstream in{from, std::ios::binary};
  if (!in) return false;
  to << in.rdbuf();
  return static_cast<bool>(to);
}

}  // namespace

bool run_ok(const DemoRun& run, bool socketcan) {
  if (!run.stream || !run.error.empty()) return false;
  const Json& r = *run.stream;
  if (r.value("status", "") != "ok") return false;
  if (!socketcan) return true;
  return run.logged == r.value("frames_sent", -1LL) + r.value("frames_received", -1LL);
}

bool DemoReport::ok() const {
  for (const DemoRun& r : runs) {
    if (!run_ok(r, socketcan)) return false;
  }
  if (capture && !(capture->complete() && capture->steps_back == 0)) return false;
  return !runs.empty() && commissioning.ok();
}

bool run_demo(const DemoSpec& spec, const PaperScenarios& scenarios, const CommissioningScenario& commissioning,
              DemoReport& report, std::string& why) {
  std::error_code ec;
  fs::create_directories(spec.out, ec);
  if (ec || !fs::is_directory(spec.out)) {
    why = "cannot create the output directory " + spec.out;
    return false;
  }
  DemoReport rep;
  rep.out = fs::absolute(spec.out, ec).lexically_normal().string();
  rep.socketcan = spec.bus != "loopback";
  rep.bus = rep.socketcan ? spec.bus : "loopback (in-process bus, virtual time: no kernel CAN involved)";
  rep.gammas = scenarios.gammas_optimised;
  if (rep.socketcan) {  // the bus must be there before any process is started
    DriveWatch probe;
    if (const hal::OpenStatus st = probe.open(spec.bus); st != hal::OpenStatus::ok) {
      why = "cannot open " + spec.bus + ": " + hal::to_string(st) + " (tools/demo brings vcan0 up; or --bus loopback)";
      return false;
    }
  }
  for (const PaperScenario& s : scenarios.scenarios) remove_outputs(spec.out, s.id);
  remove_commissioning_outputs(spec.out, commissioning.id);
  fs::remove(path_in(spec.out, "bus.log"), ec);

  // bus.log. On SocketCAN: what the bus saw, captured by a socket of this process from before the
  // first drive process starts to after the last has ended (every process's frames, the barriers
  // too, in the kernel's order and time; hal/bus_capture.hpp). On loopback: each session's
  // in-process bus as a listening port saw it, one session after another, each in its own
  // virtual time from 0.
  hal::BusCapture capture;
  std::ofstream bus_log;
  if (rep.socketcan) {
    if (const std::string e = capture.start(spec.bus, path_in(spec.out, "bus.log")); !e.empty()) {
      why = "bus.log: " + e;
      return false;
    }
  } else {
    bus_log.open(path_in(spec.out, "bus.log"), std::ios::binary);
  }
  for (const PaperScenario& s : scenarios.scenarios) {
    std::fprintf(stderr, "settle demo: %s on %s\n", s.id.c_str(), rep.socketcan ? spec.bus.c_str() : "loopback");
    DemoRun run{s, std::nullopt, std::nullopt, -1, ""};
    if (rep.socketcan) {
      run_socketcan(spec, run);
    } else {
      run_loopback(spec, run);
    }
    if (!rep.socketcan) (void)append_file(path_in(spec.out, "bus-" + s.id + ".log"), bus_log);
    rep.runs.push_back(std::move(run));
  }
  bus_log.close();
  std::fprintf(stderr, "settle demo: %s on %s\n", commissioning.id.c_str(), rep.socketcan ? spec.bus.c_str() : "loopback");
  rep.commissioning_scenario = commissioning;
  run_commissioning(spec, commissioning, rep.socketcan, rep.commissioning);
  judge(commissioning, rep.commissioning);
  if (rep.socketcan) rep.capture = capture.stop();
  for (const PaperScenario& s : scenarios.scenarios) {
    DemoScalarRuns runs{s, {}};
    run_scalars(spec, runs);
    rep.scalars.push_back(std::move(runs));
  }
  // Per scenario: the commanded setpoints and the load position measured over CAN (aligned
  // period by period), with the offline replay on top.
  for (const DemoRun& run : rep.runs) {
    const std::string csv = "feedback-" + run.scenario.id + ".csv";
    if (!fs::exists(path_in(spec.out, csv))) continue;
    papers::FigureFiles files;
    const std::string title = run.scenario.label + ", " + run.scenario.id + ": commanded and measured over CAN";
    if (papers::write_stream_figure(spec.out, run.scenario.id, csv, title, files) == plant::SimStatus::ok) {
      rep.gnuplot = files.gnuplot;
      rep.plots.insert(rep.plots.end(), files.png.begin(), files.png.end());
    }
  }
  report = std::move(rep);
  return true;
}

// ---- the report ---------------------------------------------------------------------------------

namespace {

bool has_number(const Json& j, const char* key) { return j.contains(key) && j.at(key).is_number(); }

std::string cell(const Json& j, const char* key, const char* f = "%.3e") {
  return has_number(j, key) ? num(f, j.at(key).get<double>()) : "-";
}

long long integer(const Json& j, const char* key) { return has_number(j, key) ? j.at(key).get<long long>() : 0; }

std::string text(const Json& j, const char* key) {
  return j.contains(key) && j.at(key).is_string() ? j.at(key).get<std::string>() : "-";
}

// The scalar table: float or fixed against double, three cells and a note ("" when they agree).
struct Comparison {
  std::string sp{"-"}, residual{"-"}, dres{"-"};
  std::string note;
  bool agrees{false};
};

Comparison compare(const char* sc, const std::optional<Json>& r, const std::optional<Json>& d) {
  Comparison c;
  const std::string name = sc;
  if (!r || !d || text(*d, "status") != "ok") {
    c.note = name + ": no result";
    return c;
  }
  if (text(*r, "evaluation") != "ok") {
    c.residual = "refused";
    c.note = name + ": refused (" + text(*r, "evaluation") + ")";
    return c;
  }
  if (text(*r, "status") != "ok" || !has_number(*r, "residual_can") || !has_number(*d, "residual_can")) {
    c.note = name + ": " + text(*r, "outcome") + ", not aligned";
    return c;
  }
  const long long dsp = integer(*r, "setpoints_vs_double_max_counts");
  const double rr = r->at("residual_can").get<double>(), rd = d->at("residual_can").get<double>();
  const double dres = std::abs(rr - rd) / rd * 100.0;
  c.sp = std::to_string(dsp);
  c.residual = num("%.4e", rr);
  c.dres = num("%.3g", dres);
  std::string bad;
  if (dsp > 1) bad = std::to_string(dsp) + " counts";
  if (dres > 1.0) {
    bad += (bad.empty() ? "" : ", ") + num("%.3g", dres) + " % = " + cell(*r, "residual_vs_double_load_counts", "%.2g") +
           " load count";
  }
  if (bad.empty()) {
    c.agrees = true;
  } else {
    c.note = name + ": NO, " + bad;
  }
  return c;
}

// The commissioning table: each mode's truth against what was identified, the tuned plan, and
// the PRV of that plan measured from the drive's CAN feedback.
void print_commissioning(const DemoReport& rep, std::FILE* out) {
  const CommissioningScenario& c = rep.commissioning_scenario;
  const CommissioningResult& r = rep.commissioning;
  std::string truth;
  for (const std::string& a : c.plant) truth += (truth.empty() ? "" : " ") + a;
  std::fprintf(out,
               "\nCommissioning (issue 15): modes only the drive process knows (%s), its load encoder noisy (%.3g load "
               "counts = 1 %% of the excitation's peak deflection %.4g mm); settle identify -> settle tune -> settle "
               "stream --plan-from\n\n",
               truth.c_str(), c.noise_counts, c.peak_deflection * 1e3);
  const char* row = "%-5s %10s %34s %8s %8s %26s %8s %s\n";
  std::fprintf(out, row, "mode", "true w", "identified w [95 % interval]", "err %", "true z", "identified z [interval]",
               "err", "within (0.5 %, 0.01)");
  for (std::size_t j = 0; j < r.modes.size(); ++j) {
    const ModeCheck& m = r.modes[j];
    std::fprintf(out, row, std::to_string(j + 1).c_str(), num("%.4f", m.truth.omega).c_str(),
                 (num("%.4f", m.omega) + " [" + num("%.4f", m.omega_lo) + ", " + num("%.4f", m.omega_hi) + "]").c_str(),
                 num("%+.3f", m.omega_error * 100.0).c_str(), num("%.4f", m.truth.zeta).c_str(),
                 (num("%.4f", m.zeta) + " [" + num("%.4f", m.zeta_lo) + ", " + num("%.4f", m.zeta_hi) + "]").c_str(),
                 num("%+.4f", m.zeta_error).c_str(), m.within ? "yes" : "NO");
  }
  if (r.identify && r.identify->value("status", "") == "ok" && r.modes.size() != c.modes.size()) {
    std::fprintf(out, "  <- %zu modes identified, %zu true\n", r.identify->value("modes", Json::array()).size(),
                 c.modes.size());
  }
  if (r.tune && r.tune->value("status", "") == "ok") {
    const Json& t = *r.tune;
    const std::string name = t.contains("candidate") ? t["candidate"].value("name", std::string{"-"}) : "-";
    std::fprintf(out, "\ntuned plan   %s, %s s, worst residual over the identified band %s of a step's (bound %s)\n",
                 name.c_str(), cell(t, "duration", "%.4f").c_str(), cell(t, "worst_residual", "%.4g").c_str(),
                 cell(t, "residual_max", "%.4g").c_str());
  }
  if (r.stream) {
    const Json& s = *r.stream;
    std::fprintf(out, "streamed     %s, %s s; PRV measured from the drive's CAN feedback %s %% (offline replay %s %%, "
                 "bound %.3g %%): %s\n",
                 text(s, "profile").c_str(), cell(s, "move_time", "%.4f").c_str(), cell(s, "prv_can_percent", "%.4f").c_str(),
                 cell(s, "prv_offline_percent", "%.4f").c_str(), c.prv_max_percent, r.prv_ok ? "yes" : "NO");
  }
  std::fprintf(out, "commissioning: %s\n", r.ok() ? "ok" : ("FAILED" + (r.error.empty() ? std::string{} : ": " + r.error)).c_str());
  std::fputs("files: identify-commissioning.json/.log, tune-commissioning.json, stream-commissioning.json/.csv/.log, "
             "feedback-commissioning.csv\n",
             out);
}

}  // namespace

void print_demo(const DemoReport& rep, std::FILE* out) {
  std::fprintf(out, "\nSettle demo: bus %s\n", rep.bus.c_str());
  std::string g;
  for (const double x : rep.gammas) g += (g.empty() ? "" : ",") + num("%.9g", x);
  std::fprintf(out, "seed 004 exponents: %s (optimised from 3,4,5)\n\n", g.c_str());
  const char* row = "%-19s %-13s %7s %6s %6s %6s %4s %5s %8s %13s %9s %16s %9s %9s %16s";
  std::fprintf(out, row, "scenario", "profile", "T (s)", "sent", "recv", "logged", "lost", "late", "overruns",
               "residual CAN", "PRV CAN %", "residual offline", "PRV off %", "agreement", "continuous PRV %");
  std::fputc('\n', out);
  long long log_total = 0, frames_total = 0;
  for (const DemoRun& run : rep.runs) {
    const char* name = run.scenario.label.c_str();
    if (!run.stream) {
      std::fprintf(out, "%-19s %s: no result (%s)\n", name, run.scenario.id.c_str(), run.error.c_str());
      continue;
    }
    const Json& r = *run.stream;
    long long lost = integer(r, "frames_lost");
    if (run.plant) lost += integer(*run.plant, "rx_overflow_drops");
    const long long counted = integer(r, "frames_sent") + integer(r, "frames_received");
    std::string logged = "-";
    if (rep.socketcan) {
      logged = std::to_string(run.logged);
      log_total += run.logged;
      frames_total += counted;
    }
    const std::string continuous =
        has_number(r, "residual_continuous") ? cell(r, "prv_continuous_percent", "%.4f") : "-";
    std::fprintf(out, row, name, text(r, "profile").c_str(), cell(r, "move_time", "%.4f").c_str(),
                 std::to_string(integer(r, "frames_sent")).c_str(), std::to_string(integer(r, "frames_received")).c_str(),
                 logged.c_str(), std::to_string(lost).c_str(), std::to_string(integer(r, "feedback_late_ticks")).c_str(),
                 std::to_string(integer(r, "overruns")).c_str(), cell(r, "residual_can").c_str(),
                 cell(r, "prv_can_percent", "%.4f").c_str(), cell(r, "residual_offline").c_str(),
                 cell(r, "prv_offline_percent", "%.4f").c_str(), cell(r, "agreement", "%.1e").c_str(), continuous.c_str());
    if (!run_ok(run, rep.socketcan)) {
      const std::string why = !run.error.empty()           ? run.error
                              : text(r, "status") != "ok" ? text(r, "outcome")
                                                           : "bus log incomplete";
      std::fprintf(out, "  <- %s", why.c_str());
    }
    std::fputc('\n', out);
  }
  if (rep.socketcan && log_total != frames_total) {
    std::fprintf(out, "\nthe streams' logs: %lld lines, their frames sent + received: %lld -- INCOMPLETE\n", log_total,
                 frames_total);
  }
  if (rep.capture) {
    const hal::BusCaptureResult& c = *rep.capture;
    std::fprintf(out, "\nbus.log: %llu frames captured on %s, %.1f s, %llu dropped by the kernel, %llu out of time order%s%s\n",
                 static_cast<unsigned long long>(c.frames), rep.bus.c_str(),
                 c.frames > 0 ? static_cast<double>(c.last_us - c.first_us) / 1e6 : 0.0,
                 static_cast<unsigned long long>(c.kernel_drops), static_cast<unsigned long long>(c.steps_back),
                 c.complete() && c.steps_back == 0 ? " (complete)" : " -- INCOMPLETE", c.error.empty() ? "" : (": " + c.error).c_str());
  }

  print_commissioning(rep, out);

  // The three evaluations: setpoints against double's (largest difference, counts) and the
  // residual measured over CAN against the double run's (percent; and in load counts, next to
  // the resolution).
  std::fprintf(out, "\nThe loop's evaluation (settle stream --scalar, loopback bus): float and fixed against double\n\n");
  const char* srow = "%-19s %-13s %13s | %5s %13s %8s | %5s %13s %8s | %s\n";
  std::fprintf(out, srow, "scenario", "profile", "residual dbl", "d sp", "residual flt", "d res %", "d sp", "residual fix",
               "d res %", "agree (sp <= 1 count, residual <= 1 %)");
  int agree = 0, total = 0;
  for (const DemoScalarRuns& s : rep.scalars) {
    const std::optional<Json>& d = s.runs[0];
    const Comparison f = compare("float", s.runs[1], d), x = compare("fixed", s.runs[2], d);
    total += 2;
    agree += (f.agrees ? 1 : 0) + (x.agrees ? 1 : 0);
    std::string notes = f.note;
    if (!x.note.empty()) notes += (notes.empty() ? "" : "; ") + x.note;
    std::fprintf(out, srow, s.scenario.label.c_str(), d ? text(*d, "profile").c_str() : "-",
                 d ? cell(*d, "residual_can", "%.4e").c_str() : "-", f.sp.c_str(), f.residual.c_str(), f.dres.c_str(),
                 x.sp.c_str(), x.residual.c_str(), x.dres.c_str(), notes.empty() ? "yes" : notes.c_str());
  }
  std::fprintf(out, "\nfloat and fixed agree with double on %d of %d runs\n", agree, total);
  std::fputs("'d sp' = largest |setpoint - double's setpoint| in counts; 'd res %' = |residual - double's| / double's.\n"
             "A residual under one load count is at the measurement's floor: a one-count setpoint change moves it\n"
             "by more than 1 % there, so such rows also give the difference in load counts.\n"
             "\nresiduals in output units (m of tip or mass, rad of platform); PRV = % of an unshaped step's residual;\n"
             "'logged' = lines of the stream's own bus log (every frame it sent and received; = sent + recv);\n"
             "'late' = servo ticks whose feedback arrived after the next tick began (aligned by sequence, not lost);\n"
             "'continuous' = the same move without sampling or quantisation: the difference is what 1 kHz and 1 count "
             "add.\n",
             out);
  std::fprintf(out, "\nresults, logs and plots: %s\n", rep.out.c_str());
  std::fprintf(out,
               "  bus.log (candump format: %s), stream-*.json/csv/log (servo loop), "
               "feedback-*.csv (aligned), plant-*.csv (drive), *.png%s\n",
               rep.socketcan ? "what the bus saw, every process's frames in time order, kernel timestamps"
                             : "each session's in-process bus, one after another, each in virtual time from 0",
               rep.gnuplot ? "" : " (gnuplot not found: .gp scripts written, PNGs not rendered)");
}

Json demo_json(const DemoReport& rep) {
  Json runs = Json::array();
  for (const DemoRun& r : rep.runs) {
    runs.push_back(Json{{"id", r.scenario.id},
                        {"label", r.scenario.label},
                        {"ok", run_ok(r, rep.socketcan)},
                        {"error", r.error},
                        {"logged", r.logged < 0 ? Json(nullptr) : Json(r.logged)},
                        {"stream", r.stream ? *r.stream : Json(nullptr)},
                        {"plant", r.plant ? *r.plant : Json(nullptr)}});
  }
  Json scalars = Json::array();
  for (const DemoScalarRuns& s : rep.scalars) {
    Json j{{"id", s.scenario.id}};
    for (std::size_t k = 0; k < kDemoScalars.size(); ++k) j[kDemoScalars[k]] = s.runs[k] ? *s.runs[k] : Json(nullptr);
    scalars.push_back(j);
  }
  const CommissioningResult& c = rep.commissioning;
  Json modes = Json::array();
  for (const ModeCheck& m : c.modes) {
    modes.push_back(Json{{"true", Json{{"omega", m.truth.omega}, {"zeta", m.truth.zeta}, {"gain", m.truth.gain}}},
                         {"omega", m.omega},
                         {"zeta", m.zeta},
                         {"omega_ci", Json::array({m.omega_lo, m.omega_hi})},
                         {"zeta_ci", Json::array({m.zeta_lo, m.zeta_hi})},
                         {"omega_error", m.omega_error},
                         {"zeta_error", m.zeta_error},
                         {"within", m.within}});
  }
  const auto doc = [](const std::optional<Json>& j) { return j ? *j : Json(nullptr); };
  const Json commissioning{{"ok", c.ok()},
                           {"error", c.error},
                           {"scenario", to_json(rep.commissioning_scenario)},
                           {"modes", modes},
                           {"modes_ok", c.modes_ok},
                           {"prv_percent", finite_or_null(c.prv_percent)},
                           {"prv_ok", c.prv_ok},
                           {"identify", doc(c.identify)},
                           {"tune", doc(c.tune)},
                           {"stream", doc(c.stream)},
                           {"plant_identify", doc(c.plant_identify)},
                           {"plant_stream", doc(c.plant_stream)}};
  Json bus_log(nullptr);  // loopback: no capture
  if (rep.capture) {
    const hal::BusCaptureResult& cap = *rep.capture;
    bus_log = Json{{"frames", cap.frames},     {"kernel_drops", cap.kernel_drops}, {"steps_back", cap.steps_back},
                   {"first_us", cap.first_us}, {"last_us", cap.last_us},           {"complete", cap.complete()},
                   {"error", cap.error}};
  }
  return Json{{"status", rep.ok() ? "ok" : "error"}, {"bus", rep.bus}, {"out", rep.out}, {"gammas", rep.gammas},
              {"runs", runs}, {"scalars", scalars}, {"commissioning", commissioning}, {"bus_log", bus_log},
              {"plots", rep.plots}};
}

}  // namespace settle::app
