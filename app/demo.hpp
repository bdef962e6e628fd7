// SPDX-License-Identifier: Apache-2.0
#pragma once
// settle demo: every paper scenario (paper_scenarios.hpp) streamed to the simulated drive, and the
// table that says whether each machine ended at rest; then the commissioning scenario
// (commissioning.hpp): settle identify against a drive process, settle tune on what it measured,
// settle stream of the tuned plan to a drive process again, and its table. On a SocketCAN interface the drive + plant
// (`settle plant`) and the servo loop (`settle stream`) run as two processes: the drive is up once
// its boot-up or heartbeat is on the bus, and it is stopped only once it has answered a barrier
// SDO sent after the loop's last frame (readiness by frames, never by sleeping). On the loopback
// bus each scenario is one `settle stream --bus loopback` process. Then every scenario once more
// with each of the loop's evaluations (--scalar double|float|fixed, loopback), and a plot per
// scenario (figures.hpp). Each process writes its JSON, logs and CSV into the output directory;
// the report is read back from those files.
#include <array>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "commissioning.hpp"
#include "demo_verdicts.hpp"
#include "settle/hal/bus_capture.hpp"
#include "io/json.hpp"
#include "paper_scenarios.hpp"

namespace settle::app {

struct DemoSpec {
  std::string settle;  // the settle executable the processes run
  std::string bus;     // a SocketCAN interface, or "loopback"
  std::string out;     // the output directory (created)
};

// One scenario streamed on the demo's bus.
struct DemoRun {
  PaperScenario scenario;
  std::optional<Json> stream;  // settle stream's JSON (its field names are that command's)
  std::optional<Json> plant;   // SocketCAN: settle plant's summary
  long long logged{-1};        // SocketCAN: lines of the loop's own bus log (-1: not counted)
  std::string error;           // why there is no (complete) result
};

inline constexpr std::array<const char*, 3> kDemoScalars{"double", "float", "fixed"};

// One scenario once per evaluation, on the loopback bus.
struct DemoScalarRuns {
  PaperScenario scenario;
  std::array<std::optional<Json>, 3> runs;  // in kDemoScalars order
};

struct DemoReport {
  std::string bus;  // what was used: the interface, or the loopback bus
  bool socketcan{false};
  std::vector<double> gammas;  // seed 004's exponents (optimised)
  std::vector<Paper> papers;   // the papers the runs' scenarios name
  std::vector<DemoRun> runs;
  std::vector<DemoScalarRuns> scalars;
  CommissioningScenario commissioning_scenario;
  CommissioningResult commissioning;  // identify -> tune -> stream, judged (commissioning.hpp)
  // SocketCAN: bus.log, the capture of the bus from before the first session to after the last.
  std::optional<hal::BusCaptureResult> capture;
  std::vector<std::string> plots;  // PNGs written
  bool gnuplot{false};
  std::string out;

  // Every scenario completed, with its feedback aligned with the replay, and (SocketCAN) a bus
  // log holding every frame its counters count, and bus.log complete and in time order; every
  // paper's method left less residual than its baseline at each move time (paper_verdicts); float
  // and fixed left double's residual within the bound on every scenario (check_scalar); the
  // commissioning identified the modes within the tolerances and its tuned move's PRV measured
  // over CAN is within its bound.
  [[nodiscard]] bool ok() const;
};

// Runs the demo. False (with `why`) only when it could not run at all: the output directory or
// the bus could not be opened; a scenario that fails is reported in its row.
[[nodiscard]] bool run_demo(const DemoSpec& spec, const PaperScenarios& scenarios,
                            const CommissioningScenario& commissioning, DemoReport& report, std::string& why);

// The two tables and the notes under them, as the demo prints them.
void print_demo(const DemoReport& report, std::FILE* out);
// The same as one JSON object (settle demo --json).
[[nodiscard]] Json demo_json(const DemoReport& report);

// One paper at one move time: its method's run against its baseline's, both measured over CAN.
struct PaperVerdict {
  std::size_t method{0}, baseline{0};  // indices into DemoReport::runs
  double ratio{0.0};                   // the baseline's residual over the method's (NaN: one not measured)
  bool less{false};                    // the method left less residual than its baseline
};
// A verdict per method run, paired with the baseline run of the same paper and move time.
[[nodiscard]] std::vector<PaperVerdict> paper_verdicts(const DemoReport& report);


// Whether a run's row is good: its outcome, and on SocketCAN its log against its counters.
[[nodiscard]] bool run_ok(const DemoRun& run, bool socketcan);

}  // namespace settle::app
