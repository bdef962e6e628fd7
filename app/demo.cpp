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

std::vector<PaperVerdict> paper_verdicts(const DemoReport& rep) {
  std::vector<PaperVerdict> v;
  for (std::size_t m = 0; m < rep.runs.size(); ++m) {
    const PaperScenario& ms = rep.runs[m].scenario;
    if (ms.baseline) continue;
    for (std::size_t b = 0; b < rep.runs.size(); ++b) {
      const PaperScenario& bs = rep.runs[b].scenario;
      if (!bs.baseline || bs.paper != ms.paper || bs.when != ms.when) continue;
      const ResidualVerdict r = compare_residuals(rep.runs[m].stream, rep.runs[b].stream);
      v.push_back(PaperVerdict{m, b, r.ratio, r.less});
      break;
    }
  }
  return v;
}

bool DemoReport::ok() const {
  for (const DemoRun& r : runs) {
    if (!run_ok(r, socketcan)) return false;
  }
  if (capture && !(capture->complete() && capture->steps_back == 0)) return false;
  const std::vector<PaperVerdict> verdicts = paper_verdicts(*this);
  std::size_t methods = 0;
  for (const DemoRun& r : runs) methods += r.scenario.baseline ? 0 : 1;
  if (verdicts.size() != methods) return false;  // a method without its baseline
  for (const PaperVerdict& v : verdicts) {
    if (!v.less) return false;
  }
  for (const DemoScalarRuns& s : scalars) {
    for (std::size_t k = 1; k < kDemoScalars.size(); ++k) {
      if (!check_scalar(s.runs[k], s.runs[0]).agrees) return false;
    }
  }
  return !runs.empty() && scalars.size() == runs.size() && commissioning.ok();
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
  rep.papers = scenarios.papers;
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
    std::fprintf(stderr, "settle demo: %s on %s\n", s.label.c_str(), rep.socketcan ? spec.bus.c_str() : "loopback");
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
    const std::string title = run.scenario.label + ": commanded and measured over CAN";
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

constexpr std::size_t kWidth = 100;  // no line of the report is wider

bool has_number(const Json& j, const char* key) { return j.contains(key) && j.at(key).is_number(); }

std::string cell(const Json& j, const char* key, const char* f = "%.3e") {
  return has_number(j, key) ? num(f, j.at(key).get<double>()) : "-";
}

long long integer(const Json& j, const char* key) { return has_number(j, key) ? j.at(key).get<long long>() : 0; }

std::string text(const Json& j, const char* key) {
  return j.contains(key) && j.at(key).is_string() ? j.at(key).get<std::string>() : "-";
}

// Columns a UTF-8 string takes on a terminal (every character one column: no wide characters here).
std::size_t columns(const std::string& s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

// `s` padded to `w` columns, on the right (left-aligned) or on the left (right-aligned).
std::string pad(const std::string& s, std::size_t w, bool right = false) {
  const std::size_t n = columns(s);
  const std::string fill(n < w ? w - n : 0, ' ');
  return right ? fill + s : s + fill;
}

// A paragraph, its words wrapped at kWidth columns; its leading spaces start the first line, and
// `indent` every line after it.
void paragraph(std::FILE* out, const std::string& words, const std::string& indent = "") {
  std::size_t at = words.find_first_not_of(' ');
  if (at == std::string::npos) return;
  std::string line = words.substr(0, at);
  bool fresh = true;  // nothing but the indent on the line yet
  while (at < words.size()) {
    std::size_t end = words.find(' ', at);
    if (end == std::string::npos) end = words.size();
    const std::string word = words.substr(at, end - at);
    at = end + 1;
    if (word.empty()) continue;
    if (!fresh && columns(line) + 1 + columns(word) > kWidth) {
      std::fprintf(out, "%s\n", line.c_str());
      line = indent;
      fresh = true;
    }
    line += (fresh ? "" : " ") + word;
    fresh = false;
  }
  std::fprintf(out, "%s\n", line.c_str());
}

// A residual with its unit and its PRV: "7.609e-05 m 0.0779 %".
std::string residual_cell(const DemoRun& run) {
  if (!run.stream || !has_number(*run.stream, "residual_can") || text(*run.stream, "status") != "ok") {
    return "no result";
  }
  return cell(*run.stream, "residual_can") + " " + run.scenario.unit + " " +
         cell(*run.stream, "prv_can_percent", "%.3g") + " %";
}

// One paper's table: a row per move time, the method's and the baseline's residual over CAN.
void print_paper(const DemoReport& rep, std::size_t paper, const std::vector<PaperVerdict>& verdicts,
                 std::FILE* out) {
  const Paper& p = rep.papers.at(paper);
  std::fputc('\n', out);
  paragraph(out, p.title, "  ");
  paragraph(out, "  " + p.machine, "  ");
  const std::string head = pad("  move time", 37) + pad(p.method, 25) + pad(p.baseline, 25) +
                           pad("ratio", 6, true) + "  less?";
  std::fprintf(out, "%s\n", head.c_str());
  for (const PaperVerdict& v : verdicts) {
    const DemoRun& m = rep.runs.at(v.method);
    if (m.scenario.paper != paper) continue;
    const DemoRun& b = rep.runs.at(v.baseline);
    const std::string ratio = std::isfinite(v.ratio) ? num(v.ratio >= 10.0 ? "%.0f" : "%.2g", v.ratio) + "×" : "-";
    const std::string row = pad("  " + m.scenario.when, 37) + pad(residual_cell(m), 25) +
                            pad(residual_cell(b), 25) + pad(ratio, 6, true) + "  " + (v.less ? "yes" : "NO");
    std::fprintf(out, "%s\n", row.c_str());
    for (const DemoRun* r : {&m, &b}) {  // a run that failed: why, on a line of its own
      if (run_ok(*r, rep.socketcan)) continue;
      const std::string why = !r->error.empty()                   ? r->error
                              : !r->stream                         ? "no result"
                              : text(*r->stream, "status") != "ok" ? text(*r->stream, "outcome")
                                                                   : "bus log incomplete";
      paragraph(out, "    <- " + r->scenario.label + ": " + why, "       ");
    }
  }
}

// The frames and the timing of every run.
void print_transport(const DemoReport& rep, std::FILE* out) {
  std::fprintf(out, "\nTransport and timing of each run (%s)\n", rep.socketcan ? rep.bus.c_str() : "loopback bus");
  const char* row = "%-28s %7s %8s %7s %5s %5s %8s %7s %12s\n";
  std::fprintf(out, row, "run", "sent", "received", "logged", "lost", "late", "overruns", "skipped", "CAN - replay");
  long long log_total = 0, frames_total = 0;
  for (const DemoRun& run : rep.runs) {
    if (!run.stream) {
      paragraph(out, pad(run.scenario.label, 28) + " no result (" + run.error + ")", "  ");
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
    std::fprintf(out, row, run.scenario.label.c_str(), std::to_string(integer(r, "frames_sent")).c_str(),
                 std::to_string(integer(r, "frames_received")).c_str(), logged.c_str(), std::to_string(lost).c_str(),
                 std::to_string(integer(r, "feedback_late_ticks")).c_str(), std::to_string(integer(r, "overruns")).c_str(),
                 std::to_string(integer(r, "skipped_periods")).c_str(), cell(r, "agreement", "%.1e").c_str());
  }
  if (rep.socketcan && log_total != frames_total) {
    std::fprintf(out, "\nthe streams' logs: %lld lines, their frames sent + received: %lld -- INCOMPLETE\n", log_total,
                 frames_total);
  }
  if (rep.capture) {
    const hal::BusCaptureResult& c = *rep.capture;
    std::fprintf(out, "\nbus.log: %llu frames captured on %s, %.1f s, %llu kernel drops, %llu out of time order%s%s\n",
                 static_cast<unsigned long long>(c.frames), rep.bus.c_str(),
                 c.frames > 0 ? static_cast<double>(c.last_us - c.first_us) / 1e6 : 0.0,
                 static_cast<unsigned long long>(c.kernel_drops), static_cast<unsigned long long>(c.steps_back),
                 c.complete() && c.steps_back == 0 ? " (complete)" : " -- INCOMPLETE", c.error.empty() ? "" : (": " + c.error).c_str());
  }
  std::fputc('\n', out);
  for (const char* line : {
           "sent, received: CAN frames the servo loop sent (NMT, SDO, SYNC, setpoint RPDOs) and received",
           "logged: lines of the loop's own bus log, every frame it sent and received (= sent + received)",
           "lost: frames dropped by a full receive queue or a failed send, in the loop or the drive",
           "late: servo ticks whose feedback arrived after the next tick began (matched by its SYNC, not lost)",
           "overruns: times the Linux timer woke the loop a whole period or more late (the host is not",
           "  real-time); skipped: the periods those wake-ups missed, skipped and not caught up: the move",
           "  lasts that much longer, while the drive, stepped by SYNC, moves the machine exactly the same",
           "CAN - replay: |residual measured over CAN - residual of the offline replay of the same",
           "  setpoints|, in the residual's unit: 0 when every setpoint was applied once and in order",
       }) {
    std::fprintf(out, "%s\n", line);
  }
}

// The commissioning table: each mode's truth against what was identified, the tuned plan, and
// the PRV of that plan measured from the drive's CAN feedback.
void print_commissioning(const DemoReport& rep, std::FILE* out) {
  const CommissioningScenario& c = rep.commissioning_scenario;
  const CommissioningResult& r = rep.commissioning;
  std::string truth;
  for (const std::string& a : c.plant) truth += (truth.empty() ? "" : " ") + a;
  std::fputc('\n', out);
  paragraph(out, "Commissioning: a machine whose modes only the drive process knows (" + truth +
                     "), its load encoder noisy (" + num("%.3g", c.noise_counts) +
                     " load counts, 1 % of the excitation's peak deflection " + num("%.4g", c.peak_deflection * 1e3) +
                     " mm): settle identify measures the modes from the drive's frames, settle tune plans the "
                     "fastest move for them, settle stream --plan-from streams it.");
  const char* row = "%-4s %8s %28s %9s %6s %23s %7s %s\n";
  const std::string head = pad("mode", 4) + pad("true ω", 9, true) + pad("identified ω [95 % interval]", 29, true) +
                           pad("error", 10, true) + pad("true ζ", 7, true) + pad("identified ζ [interval]", 24, true) +
                           pad("error", 8, true) + " within";
  std::fprintf(out, "%s\n", head.c_str());
  for (std::size_t j = 0; j < r.modes.size(); ++j) {
    const ModeCheck& m = r.modes[j];
    std::fprintf(out, row, std::to_string(j + 1).c_str(), num("%.4f", m.truth.omega).c_str(),
                 (num("%.4f", m.found.omega) + " [" + num("%.4f", m.found.omega_lo) + ", " + num("%.4f", m.found.omega_hi) + "]").c_str(),
                 (num("%+.3f", m.omega_error * 100.0) + " %").c_str(), num("%.4f", m.truth.zeta).c_str(),
                 (num("%.4f", m.found.zeta) + " [" + num("%.4f", m.found.zeta_lo) + ", " + num("%.4f", m.found.zeta_hi) + "]").c_str(),
                 num("%+.4f", m.zeta_error).c_str(), m.within ? "yes" : "NO");
  }
  if (r.identify && r.identify->value("status", "") == "ok" && r.modes.size() != c.modes.size()) {
    std::fprintf(out, "  <- %zu modes identified, %zu true\n", r.identify->value("modes", Json::array()).size(),
                 c.modes.size());
  }
  std::fprintf(out, "ω in rad/s; within: ω within %.3g %% and ζ within %.3g of the truth\n", c.omega_tolerance * 100.0,
               c.zeta_tolerance);
  if (r.tune && r.tune->value("status", "") == "ok") {
    const Json& t = *r.tune;
    const std::string name = t.contains("candidate") ? t["candidate"].value("name", std::string{"-"}) : "-";
    paragraph(out, "tuned plan: " + name + ", " + cell(t, "duration", "%.4f") +
                       " s; its worst residual over the identified intervals " + cell(t, "worst_residual", "%.4g") +
                       " of an unshaped step's (bound " + cell(t, "residual_max", "%.4g") + ")");
  }
  if (r.stream) {
    const Json& s = *r.stream;
    paragraph(out, "streamed: " + text(s, "profile") + ", " + cell(s, "duration", "%.4f") +
                       " s; PRV measured from the drive's CAN feedback " + cell(s, "prv_can_percent", "%.4f") +
                       " % (offline replay " + cell(s, "prv_offline_percent", "%.4f") + " %, bound " +
                       num("%.3g", c.prv_max_percent) + " %): " + (r.prv_ok ? "yes" : "NO"));
  }
  paragraph(out, "commissioning: " + (r.ok() ? std::string{"ok"} : "FAILED" + (r.error.empty() ? "" : ": " + r.error)),
            "  ");
}

// The float/fixed table: per run, double's residual, then for float and for fixed the largest
// setpoint difference (counts) and the residual's difference (percent and load counts).
void print_scalars(const DemoReport& rep, std::FILE* out) {
  std::fputc('\n', out);
  paragraph(out, "The loop's number formats (settle stream --scalar, loopback bus): float and fixed point must leave "
                 "the move's residual equal to double's within 1 % or within one load count (the measurement's "
                 "resolution); the demo fails otherwise.");
  const char* row = "%-28s %10s | %5s %8s %7s %4s | %5s %8s %7s %4s\n";
  std::fprintf(out, row, "run", "double", "sp", "res %", "counts", "ok", "sp", "res %", "counts", "ok");
  int agree = 0, total = 0;
  for (const DemoScalarRuns& s : rep.scalars) {
    const std::optional<Json>& d = s.runs[0];
    const ScalarCheck f = check_scalar(s.runs[1], d), x = check_scalar(s.runs[2], d);
    total += 2;
    agree += (f.agrees ? 1 : 0) + (x.agrees ? 1 : 0);
    const auto cells = [](const ScalarCheck& c, const std::optional<Json>& r) {
      const bool have = c.why.empty() && r;
      return std::array<std::string, 4>{have ? std::to_string(integer(*r, "setpoints_vs_double_max_counts")) : "-",
                                        have ? cell(*r, "residual_vs_double_percent", "%.3g") : "-",
                                        have ? cell(*r, "residual_vs_double_load_counts", "%.2g") : "-",
                                        c.agrees ? "yes" : "NO"};
    };
    const auto fc = cells(f, s.runs[1]), xc = cells(x, s.runs[2]);
    std::fprintf(out, row, s.scenario.label.c_str(), d ? cell(*d, "residual_can", "%.4e").c_str() : "-", fc[0].c_str(),
                 fc[1].c_str(), fc[2].c_str(), fc[3].c_str(), xc[0].c_str(), xc[1].c_str(), xc[2].c_str(), xc[3].c_str());
    for (const auto& [name, c] : {std::pair{"float", f}, std::pair{"fixed", x}}) {
      if (!c.why.empty()) std::fprintf(out, "  <- %s: %s\n", name, c.why.c_str());
    }
  }
  std::fprintf(out, "\nfloat and fixed agree with double on %d of %d runs\n", agree, total);
  for (const char* line : {
           "left: float; right: fixed point. double: the residual double leaves, in the run's unit",
           "sp: largest |setpoint - double's setpoint|, in counts (shown, not judged)",
           "res %: |residual - double's| / double's; counts: the same difference in load counts",
       }) {
    std::fprintf(out, "%s\n", line);
  }
}

}  // namespace

void print_demo(const DemoReport& rep, std::FILE* out) {
  std::fprintf(out, "\nSettle demo: each paper's move streamed over CAN to a simulated drive and machine\n");
  std::fprintf(out, "bus: %s\n\n", rep.bus.c_str());
  paragraph(out, "Residual vibration left after each move, measured from the drive's CAN feedback, as an "
                 "amplitude and as PRV (% of what an unshaped step of the same distance leaves); ratio: the "
                 "baseline's residual over the method's; less?: the method leaves less residual than its "
                 "baseline (the demo fails otherwise).");
  const std::vector<PaperVerdict> verdicts = paper_verdicts(rep);
  for (std::size_t p = 0; p < rep.papers.size(); ++p) print_paper(rep, p, verdicts, out);
  print_transport(rep, out);
  print_commissioning(rep, out);
  print_scalars(rep, out);
  std::fprintf(out, "\nresults, logs and plots: %s\n", rep.out.c_str());
  paragraph(out,
            std::string{"  bus.log (candump format: "} +
                (rep.socketcan ? "what the bus saw, every process's frames in time order, kernel timestamps"
                               : "each session's in-process bus, one after another, each in virtual time from 0") +
                "), stream-*.json/csv/log (servo loop), feedback-*.csv (aligned), plant-*.csv (drive), identify-, "
                "tune-, stream-commissioning.* (commissioning), *.png" +
                (rep.gnuplot ? "" : " (gnuplot not found: .gp scripts written, PNGs not rendered)"),
            "  ");
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
    // Whether float and fixed left double's residual within the bound (check_scalar).
    for (std::size_t k = 1; k < kDemoScalars.size(); ++k) {
      j[std::string{kDemoScalars[k]} + "_agrees"] = check_scalar(s.runs[k], s.runs[0]).agrees;
    }
    scalars.push_back(j);
  }
  Json verdicts = Json::array();
  for (const PaperVerdict& v : paper_verdicts(rep)) {
    const PaperScenario& m = rep.runs.at(v.method).scenario;
    verdicts.push_back(Json{{"paper", m.paper},
                            {"when", m.when},
                            {"method", m.id},
                            {"baseline", rep.runs.at(v.baseline).scenario.id},
                            {"ratio", finite_or_null(v.ratio)},
                            {"less", v.less}});
  }
  Json papers = Json::array();
  for (const Paper& p : rep.papers) papers.push_back(Json{{"title", p.title}, {"machine", p.machine}});
  const CommissioningResult& c = rep.commissioning;
  Json modes = Json::array();
  for (const ModeCheck& m : c.modes) {
    modes.push_back(Json{{"true", Json{{"omega", m.truth.omega}, {"zeta", m.truth.zeta}, {"gain", m.truth.gain}}},
                         {"omega", m.found.omega},
                         {"zeta", m.found.zeta},
                         {"omega_ci", Json::array({m.found.omega_lo, m.found.omega_hi})},
                         {"zeta_ci", Json::array({m.found.zeta_lo, m.found.zeta_hi})},
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
              {"papers", papers}, {"runs", runs}, {"verdicts", verdicts}, {"scalars", scalars},
              {"commissioning", commissioning}, {"bus_log", bus_log}, {"plots", rep.plots}};
}

}  // namespace settle::app
