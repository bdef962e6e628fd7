// SPDX-License-Identifier: Apache-2.0
// settle stream: the composition root of sim's run_stream (settle/testbed/stream.hpp). The options
// become a StreamSpec, --bus picks where it runs (loopback: the simulated drive in this process,
// in virtual time; any SocketCAN interface: real time, against a `settle plant` process or a
// drive), and the report goes out as text or --json, with the --log and --feedback-log CSVs.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "drive_advice.hpp"
#include "eds_option.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/hal/canopen/bus_load.hpp"
#include "settle/hal/eds_reader.hpp"
#include "move_options.hpp"
#include "online_options.hpp"
#include "options.hpp"
#include "plant_options.hpp"
#include "settle/testbed/stream.hpp"
#include "settle/testbed/clocked_bus.hpp"
#include "settle/testbed/stream_report.hpp"
#include "clocked_bus_open.hpp"

namespace settle::app {

namespace {

// The cyclic frames of one SYNC period (the SYNC, and every axis's RPDO and TPDOs as the layout in
// use makes them: Settle's default, or the one --eds gives) must fit in the period at --bitrate
// with worst-case bit stuffing (hal/canopen/bus_load.hpp, docs/multi_axis.md). Exit 2 or -1.
int check_bus_load(const ParsedArgs& args, const testbed::StreamSpec& spec, std::uint32_t axes) {
  hal::canopen::ProcessDataLayout layout{};
  if (spec.eds) {
    hal::canopen::RemoteDriveConfig base{};
    base.node = spec.axes.front().node;
    const hal::eds::DriveConfigResult d = hal::eds::drive_config_from_eds(*spec.eds, base, testbed::streaming_feedback(*spec.eds, spec.load_feedback));
    if (d.ok()) layout = d.config.layout;  // otherwise start-up refuses the description, naming it
  }
  const auto bitrate = static_cast<std::uint32_t>(args.integer("--bitrate"));
  const std::uint32_t period_us = spec.drive.scale.period_us;
  const hal::canopen::CyclicLoad load = hal::canopen::cyclic_load(layout, axes);
  const std::uint64_t available = hal::canopen::bits_per_period(bitrate, period_us);
  if (load.bits_worst_case <= available) return -1;
  return report_bad_request(
      {"bus_overload", "--bitrate",
       "--bitrate: " + std::to_string(axes) + (axes == 1 ? " axis needs " : " axes need ") +
           std::to_string(load.bits_worst_case) + " bits per SYNC period with worst-case bit stuffing (" +
           std::to_string(load.bits_unstuffed) + " without), " + std::to_string(available) + " available: " +
           std::to_string(bitrate) + " bit/s x " + std::to_string(period_us) +
           " us (a higher --bitrate, a longer --period-us or fewer axes)"},
      args.json());
}

// StreamSpec's form of a change the options asked for.
testbed::StreamChange stream_change(const OnlineChange& c) {
  return {c.at, c.target, c.modes, c.limits, c.blend, c.choice == core::OnlineChoice::finish};
}

// --axes N (docs/multi_axis.md): the coordinated plan's command on every axis (core::axis_command):
// one per axis in spec.axes, on nodes 1..N or --nodes (N
// distinct whole numbers, each 1..127: the table's range); with --halt-at or --retarget-at every
// moving axis's change (parse_axes_online_change). Exit status or -1.
int parse_axes(const ParsedArgs& args, const DesignFallback& fundamental, testbed::StreamSpec& spec) {
  const bool json = args.json();
  for (const char* o : {"--plan-from", "--node"}) {
    if (args.has(o)) {
      return report_bad_request({"conflicting_options", o,
                                 std::string{o} + ": one axis at a time; not with --axes" +
                                     (std::string{o} == "--node" ? " (give --nodes)" : "")},
                                json);
    }
  }
  RequestError err;
  core::MultiAxisRequest req{};
  if (!parse_axes_request(args, req, err, &fundamental)) return report_bad_request(err, json);
  core::MultiAxisPlan plan{};
  if (!plan_axes(req, plan, err)) return report_bad_request(err, json);
  std::vector<std::optional<OnlineChange>> changes;
  if (!parse_axes_online_change(args, req, plan, &spec.plant, spec.drive.scale.period_s(), changes, err)) {
    return report_bad_request(err, json);
  }
  std::vector<hal::canopen::NodeId> nodes;
  if (args.has("--nodes")) {
    const std::vector<double> given = args.list("--nodes");
    if (given.size() != req.count) {
      return report_bad_request({"bad_list", "--nodes",
                                 "--nodes: --axes " + std::to_string(req.count) + " needs " +
                                     std::to_string(req.count) + " node ids, got " + std::to_string(given.size())},
                                json);
    }
    // The ids up to the first that is no whole number (each in 1..127: the table's range); a node
    // given twice among them is named first, as the list reads.
    for (const double v : given) {
      if (static_cast<double>(static_cast<long long>(v)) != v) break;
      nodes.push_back(static_cast<hal::canopen::NodeId>(v));
    }
    if (const std::optional<testbed::NodeClash> c = testbed::shared_node(nodes)) {
      return report_bad_request({"bad_list", "--nodes",
                                 "--nodes: node " + std::to_string(c->node) + " given twice; one drive per node"},
                                json);
    }
    if (nodes.size() != given.size()) {
      return report_bad_request({"out_of_range", "--nodes", "--nodes: node ids are whole numbers in [1, 127]"}, json);
    }
  } else {
    for (std::size_t i = 0; i < req.count; ++i) nodes.push_back(static_cast<hal::canopen::NodeId>(i + 1));
  }
  spec.axes.clear();
  for (std::size_t i = 0; i < req.count; ++i) {
    core::Move<double> m{};
    if (const core::Status st = core::axis_command(req, plan, i, m); st != core::Status::ok) {
      return report_bad_request({core::to_string(st), "--distance",
                                 "--distance: axis " + std::to_string(i + 1) + ": " + core::describe(st)},
                                json);
    }
    std::optional<testbed::StreamChange> change;
    if (changes[i]) change = stream_change(*changes[i]);
    // Path sync: the loop plans the path's halt, or retarget on its line, once for every axis.
    if (change) change->path = plan.sync() == core::SyncMode::path;
    spec.axes.push_back({m, nodes[i], change});
  }
  return -1;
}

// What the loop would refuse once the drives are up (a move or a blend faster than the axis's
// vmax or, on loopback, than the simulated drive's 0x607F; a move the --scalar evaluation cannot
// hold), refused before anything is sent. Exit 2 or -1.
int refuse_unstreamable(const ParsedArgs& args, const testbed::StreamSpec& spec) {
  const testbed::StreamRefusal r = testbed::check_streamable(spec, args.text_or_default("--bus") == "loopback");
  if (r.status == runtime::LoopStatus::ok) return -1;
  const std::string who = spec.axes.size() == 1 ? std::string{} : "axis " + std::to_string(r.axis + 1) + ": ";
  const std::string change = args.has("--halt-at") ? "--halt-at" : "--retarget-at";
  const std::string what = r.in_change ? "the " + change + " blend may reach " : "the move peaks at ";
  switch (r.status) {
    case runtime::LoopStatus::exceeds_axis_velocity:
      return report_bad_request({"exceeds_axis_velocity", "--axis-vmax",
                                 "--axis-vmax: " + who + what + format_number(r.peak) +
                                     " unit/s, over the axis's step guard " + format_number(r.limit) + " unit/s" +
                                     (r.in_change ? " (a higher --axis-vmax, or a lower --vmax for the blend)" : "")},
                                args.json());
    case runtime::LoopStatus::exceeds_drive_velocity:
      return report_bad_request({"exceeds_drive_velocity", "--counts-per-unit",
                                 "--counts-per-unit: " + who + what + format_number(r.peak) +
                                     " counts/s at this scale, over the simulated drive's max profile velocity "
                                     "(0x607F) " + format_number(r.limit) + " counts/s"},
                                args.json());
    default: break;
  }
  return report_bad_request({core::to_string(r.why), "--scalar",
                             "--scalar: " + who + "the " + testbed::to_string(spec.scalar) + " evaluation cannot hold " +
                                 (r.in_change ? "the " + change + " blend" : std::string{"the move"}) + ": " +
                                 core::describe(r.why)},
                            args.json());
}

// The options as a spec, each already in its table range (options.cpp), and the sizes bounded
// before anything is allocated: the session's records, the offline replay and the continuous
// simulation (1e-4 s grid) all grow with the move and the settle time. Exit status or -1.
int parse_spec(const ParsedArgs& args, testbed::StreamSpec& spec) {
  const bool json = args.json();
  RequestError err;
  if (!parse_plant(args, spec.plant, err)) return report_bad_request(err, json);
  if (!parse_drive(args, spec.plant, spec.drive, err)) return report_bad_request(err, json);
  // Without --omega a move that designs for a mode is designed for the plant's fundamental, as
  // simulate does.
  const DesignFallback fundamental{spec.plant.fundamental().omega, spec.plant.fundamental().zeta};
  const bool axes = wants_axes(args);
  if (axes) {
    if (const int rc = parse_axes(args, fundamental, spec); rc >= 0) return rc;
  } else if (args.has("--nodes")) {
    return report_bad_request({"bad_option", "--nodes", "--nodes: the nodes of --axes N; give --axes too"}, json);
  } else if (!move_from_args(args, spec.axes.front().move, err, &fundamental)) {
    return report_bad_request(err, json);
  }
  const core::Move<double>& move = spec.axes.front().move;
  // Node 1..127, heartbeat 10..10000 ms, SDO timeout 1..60000 ms, settle time (0, 600) s, axis
  // vmax (0, 1e9], feedback timeout 0..65535 periods.
  // The timeouts' defaults are the option table's under the --timing preset in force.
  if (!axes) spec.axes.front().node = static_cast<hal::canopen::NodeId>(args.integer("--node"));
  spec.heartbeat_ms = static_cast<std::uint16_t>(args.integer("--heartbeat-ms"));
  spec.sdo_timeout_us = static_cast<std::uint32_t>(args.integer("--sdo-timeout-ms") * 1000);
  spec.feedback_timeout_periods = static_cast<std::uint16_t>(args.integer("--feedback-timeout-periods"));
  spec.settle_time_s = args.real_or_default("--settle-time");
  spec.axis_vmax = args.real("--axis-vmax");
  const std::string scalar = args.text_or_default("--scalar");
  spec.scalar = scalar == "float"   ? testbed::StreamScalar::single_precision
                : scalar == "fixed" ? testbed::StreamScalar::fixed_point
                                    : testbed::StreamScalar::double_precision;

  // A halt or retarget blends with the design modes and limits of the move options; a plan file
  // carries its own, which the blend does not read yet: the two are refused together.
  core::MoveRequest req{};
  if (axes) {
    // parse_axes planned every axis's change.
  } else if (args.has("--plan-from")) {
    for (const char* o : {"--halt-at", "--retarget-at"}) {
      if (args.has(o)) {
        return report_bad_request(
            {"conflicting_options", o, std::string{o} + ": not with --plan-from (give the move options instead)"}, json);
      }
    }
  } else if (!parse_move_request(args, req, err, &fundamental)) {
    return report_bad_request(err, json);  // not reached: move_from_args parsed the same options
  }
  std::optional<OnlineChange> change;
  if (!axes && !parse_online_change(args, req, move, &spec.plant, spec.drive.scale.period_s(), change, err)) {
    return report_bad_request(err, json);
  }
  if (change) spec.axes.front().change = stream_change(*change);
  double reach_distance = 0.0, move_s = 0.0, command_s = 0.0;
  const auto extend = [&](const core::Move<double>& m, const std::optional<testbed::StreamChange>& c) {
    reach_distance = std::fmax(reach_distance, std::fabs(m.distance()));
    move_s = std::fmax(move_s, m.duration());
    command_s = std::fmax(command_s, m.duration());
    if (c) {
      reach_distance = std::fmax(reach_distance, std::fabs(c->blend.end_position()));
      if (!c->finish) command_s = std::fmax(command_s, c->at + c->blend.duration());
    }
  };
  for (const testbed::StreamAxis& a : spec.axes) extend(a.move, a.change);
  // What makes the command long: a change that runs past the move, the settle time, or the move
  // (its --time, or with limits the one that binds, or the plan file).
  const std::string change_option = args.has("--halt-at") ? "--halt-at" : "--retarget-at";
  const char* move_option = args.has("--time")        ? "--time"
                            : args.has("--plan-from") ? "--plan-from"
                                                      : binding_limit(move.distance(), limits_of(args), "--time");
  const char* longest = command_s - move_s > std::fmax(move_s, spec.settle_time_s) ? change_option.c_str()
                        : move_s >= spec.settle_time_s                            ? move_option
                                                                                  : "--settle-time";
  if (command_s + spec.settle_time_s > kMaxSeconds) {
    return report_bad_request({"too_long", longest,
                               std::string{longest} + ": the move lasts " + format_number(move_s) + " s" +
                                   (command_s > move_s ? ", with the change " + format_number(command_s) + " s"
                                                       : std::string{}) +
                                   ", the settle time " + format_number(spec.settle_time_s) +
                                   " s; at most 3600 s of command + settle time"},
                              json);
  }
  const double periods = (5.0 + command_s + spec.settle_time_s) * 1e6 / spec.drive.scale.period_us;
  if (periods > kMaxStreamPeriods) {
    const char* who = longest;
    return report_bad_request({"too_many_samples", who,
                               std::string{who} + ": " + format_number(periods) +
                                   " periods of start-up (5 s) + move + settle time; at most 1e6 (or a longer "
                                   "--period-us)"},
                              json);
  }
  if (const char* who =
          counts_reach_exceeded(reach_distance, spec.drive.scale.counts_per_unit, spec.drive.load_counts_per_unit)) {
    return report_bad_request(
        {"out_of_range", who, std::string{who} + ": --distance x " + who + " exceeds 32-bit counts (1e9)"}, json);
  }
  // The drive's description, read before anything is sent (what it says is checked at start-up).
  std::vector<std::uint8_t> nodes;
  for (const testbed::StreamAxis& a : spec.axes) nodes.push_back(a.node);
  EdsOption eds;
  if (const int rc = load_eds_option(args, "stream", nodes, eds); rc >= 0) return rc;
  spec.eds = eds.description;
  if (const int rc = parse_load_feedback(args, spec.eds.get(), spec.load_feedback); rc >= 0) return rc;
  if (const int rc = refuse_unstreamable(args, spec); rc >= 0) return rc;
  return check_bus_load(args, spec, static_cast<std::uint32_t>(spec.axes.size()));
}

// A CSV file written by one of the report's writers; false when it cannot be.
template <typename Writer>
bool write_file(const std::string& path, Writer&& write) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  const bool written = write(f);
  return std::fclose(f) == 0 && written;
}

int failed(const ParsedArgs& args, const std::string& code, const std::string& why) {
  return report_failure("stream", code, why, args.json());
}

}  // namespace

int cmd_stream(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("stream", argc, argv, args); rc >= 0) return rc;
  testbed::StreamSpec spec{};
  if (const int rc = parse_spec(args, spec); rc >= 0) return rc;

  hal::SocketCanBus socketcan;
  std::string error;
  const std::unique_ptr<testbed::ClockedBus> bus = open_clocked_bus(args, socketcan, error);
  if (!bus) return failed(args, "bus", error);

  const testbed::StreamReport report = testbed::run_stream(spec, *bus);
  if (!report.failure.empty()) return failed(args, "run_failed", report.failure);
  if (const auto path = args.text("--log");
      path && !write_file(*path, [&](std::FILE* f) { return testbed::write_tick_csv(report, f); })) {
    return failed(args, "write_failed", "cannot write " + *path);
  }
  // Commanded and measured motion per drive period, aligned: what the plots show.
  if (const auto path = args.text("--feedback-log");
      path && report.axes.front().aligned() && !write_file(*path, [&](std::FILE* f) { return testbed::write_feedback_csv(report, f); })) {
    return failed(args, "write_failed", "cannot write " + *path);
  }
  if (args.json()) {
    std::printf("%s\n", testbed::stream_json(report).c_str());
  } else {
    testbed::write_stream_text(report, stdout);
  }
  if (!report.measured()) {
    if (const std::string advice = drive_advice(report); !advice.empty()) std::fprintf(stderr, "settle stream: %s\n", advice.c_str());
  }
  return report.measured() ? kExitOk : kExitFailure;
}

}  // namespace settle::app
