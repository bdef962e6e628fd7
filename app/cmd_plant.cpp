// SPDX-License-Identifier: Apache-2.0
// settle plant: the simulated CiA 402 drive with a plant behind it, as a node on a SocketCAN bus.
// SYNC-driven: it advances the plant by exactly one period per SYNC. Runs until SIGINT/SIGTERM
// (or --duration), then writes its log and prints a summary.
#include <csignal>
#include <cstdio>
#include <ctime>

#include "commands.hpp"
#include "eds_option.hpp"
#include "io/json.hpp"
#include "options.hpp"
#include "plant_options.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "socketcan_open.hpp"
#include "settle/testbed/simulated_drive.hpp"
#include "settle/testbed/sync_log.hpp"

namespace settle::app {

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

std::uint64_t now_us() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000ULL + static_cast<std::uint64_t>(ts.tv_nsec) / 1000;
}

}  // namespace

int cmd_plant(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("plant", argc, argv, args); rc >= 0) return rc;
  const bool json = args.json();
  RequestError err;
  plant::ModalPlant plant{};
  if (!parse_plant(args, plant, err)) return report_bad_request(err, json);
  plant::PositionUnit unit{};  // of the log's load and base columns
  if (!plant_unit(args, plant.kind(), unit, err)) return report_bad_request(err, json);
  testbed::DriveAxisConfig axis_cfg{};
  if (!parse_drive(args, plant, axis_cfg, err)) return report_bad_request(err, json);
  axis_cfg.load_noise_counts = args.real_or_default("--noise");  // the load encoder's (settle identify's e2e)
  axis_cfg.noise_seed = static_cast<std::uint64_t>(args.integer("--seed"));
  // Each in its table range: node 1..127, heartbeat 10..10000 ms, loss 1..255 periods; the
  // defaults are the table's, the loss under the --timing preset.
  const long long node = args.integer("--node");
  const long long heartbeat = args.integer("--heartbeat-ms");
  const long long loss = args.integer("--sync-loss-periods");
  const double duration = args.has("--duration") ? args.real_or_default("--duration") : 0.0;  // table: "0 (until ...)"
  const std::string iface = args.text_or_default("--bus");

  // The drive: the EDS's when one is given (checked before the bus is opened), else the default
  // drive, which hal/eds/settle_drive.eds describes exactly (tests/testbed/test_drive_from_eds.cpp).
  const auto eds = args.text("--eds");
  EdsOption description;
  const std::uint8_t nodes[] = {static_cast<std::uint8_t>(node)};
  if (const int rc = load_eds_option(args, "plant", nodes, description); rc >= 0) return rc;
  testbed::LoadFeedback load{};
  if (const int rc = parse_load_feedback(args, description.description.get(), load); rc >= 0) return rc;
  testbed::SimulatedDriveSpec spec{};
  spec.load_position = load.served_at();  // the master's --load-feedback, on another vendor's drive
  spec.node = static_cast<hal::canopen::NodeId>(node);
  spec.eds = description.description.get();
  spec.axis = axis_cfg;
  spec.plant = plant;
  spec.sync_period_us = axis_cfg.scale.period_us;
  if (!eds || args.has("--heartbeat-ms")) spec.heartbeat_period_ms = static_cast<std::uint16_t>(heartbeat);
  // An EDS's 0x2001 stands unless the option or a --timing preset is given.
  if (!eds || args.has("--sync-loss-periods") || args.has("--timing")) {
    spec.communication_loss_periods = static_cast<std::uint8_t>(loss);
  }
  testbed::SimulatedDriveError why;
  testbed::SimulatedDrive drive = testbed::build_simulated_drive(spec, why);
  if (!why.eds.empty()) return report_bad_request({"bad_eds", "--eds", "--eds: " + *eds + ": " + why.eds}, json);
  if (!drive.node) return kExitFailure;
  testbed::PlantNode& pn = *drive.node;

  hal::SocketCanBus bus;
  const hal::OpenStatus os = open_socketcan(bus, iface);
  if (os != hal::OpenStatus::ok) {
    std::fprintf(stderr, "settle plant: cannot open %s: %s\n", iface.c_str(), hal::to_string(os));
    return kExitFailure;
  }
  // Every SYNC's record streams to the file as it is made (bounded memory for any run length).
  testbed::SyncCsvLog log;
  const auto log_path = args.text("--log");
  if (log_path && !log.open(*log_path, unit)) {
    std::fprintf(stderr, "settle plant: cannot write %s\n", log_path->c_str());
    return kExitFailure;
  }
  if (log_path) pn.set_sink(&log);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  const std::uint64_t t0 = now_us();
  pn.start(t0, bus);
  std::fprintf(stderr, "settle plant: node %d on %s, %s plant, %u us period\n", static_cast<int>(node), iface.c_str(),
               to_string(plant.kind()), axis_cfg.scale.period_us);
  hal::CanFrame f{};
  std::uint64_t now = t0;  // when the last frame was taken
  while (g_stop == 0) {
    if (duration > 0 && static_cast<double>(now_us() - t0) * 1e-6 > duration) break;
    hal::ReceiveStatus rs = bus.receive(f, 2000);
    // Frames already queued are taken before the timeouts are judged: a SYNC still waiting in this
    // process's own queue (it was not scheduled for a while: a loaded host, SIGSTOP) is not a lost
    // SYNC. At most 256 at a time, so the heartbeat goes out even while the plant catches up.
    for (int queued = 0; rs == hal::ReceiveStatus::received && queued < 256; ++queued) {
      now = now_us();
      (void)pn.on_frame(f, now, bus);
      rs = bus.receive(f, 0);
    }
    if (rs == hal::ReceiveStatus::error) {
      std::fprintf(stderr, "settle plant: receive failed (errno %d)\n", bus.last_errno());
      break;
    }
    // The timeouts are judged at a time taken *before* the queue is seen empty. When frames are
    // still there (the batch limit; the wait ended by a stop and continue, or its timeout ran out
    // while the process was stopped; a stop just now), they are judged as of the last frame taken,
    // and the queue is taken next: a process that was not running never blames the bus for it.
    const std::uint64_t judged = now_us();
    if (rs != hal::ReceiveStatus::received) rs = bus.receive(f, 0);
    if (rs == hal::ReceiveStatus::received) {
      pn.poll(now, bus);
      now = now_us();
      (void)pn.on_frame(f, now, bus);
      continue;
    }
    pn.poll(judged, bus);
    now = judged;
  }
  if (log_path && !log.close()) {
    std::fprintf(stderr, "settle plant: cannot write %s\n", log_path->c_str());
    return kExitFailure;
  }
  const auto& c = pn.node().counters();
  const auto& bc = bus.counters();
  const Json summary{{"syncs", static_cast<long long>(c.syncs)},
                     {"rpdos_applied", static_cast<long long>(c.rpdos_applied)},
                     {"rpdos_missing", static_cast<long long>(c.rpdos_missing)},
                     {"sync_gaps", static_cast<long long>(c.sync_gaps)},
                     {"emcy_sent", static_cast<long long>(c.emcy_sent)},
                     {"frames_sent", static_cast<long long>(bc.sent)},
                     {"frames_received", static_cast<long long>(bc.received)},
                     {"tx_busy", static_cast<long long>(bc.tx_busy)},
                     {"rx_overflow_drops", static_cast<long long>(bc.rx_overflow_drops)},
                     {"state", hal::canopen::to_string(pn.node().state())}};
  print_json(summary, json ? stdout : stderr);
  return pn.status() == plant::SimStatus::ok ? kExitOk : kExitFailure;
}

}  // namespace settle::app
