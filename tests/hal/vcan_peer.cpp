// SPDX-License-Identifier: Apache-2.0
// The other process of the vcan suites. Modes:
//   vcan_peer drive <node>        a Settle drive (DriveNode, ideal axis) until SIGTERM, then
//                                 prints its counters as key=value lines
//   vcan_peer sink <count>        receives <count> frames with id 0x123, acknowledging on 0x124
//   vcan_peer source <count>      sends <count> frames with id 0x321 under acknowledgements on
//                                 0x322 (vcan_support.hpp), prints the rate
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "vcan_support.hpp"

namespace {

volatile std::sig_atomic_t stop_requested = 0;
void on_signal(int /*signal*/) { stop_requested = 1; }

using namespace settle::hal;

int run_drive(SocketCanBus& bus, canopen::NodeId node) {
  canopen::DriveNodeConfig config{};
  config.node = node;
  // The tolerance the e2e drives get (settle plant --sync-loss-periods 250): a user-mode-linux
  // guest on a busy host runs this lock-step exchange at tens of cycles per second, and the
  // default 3 periods (4.5 ms) made the drive quick-stop mid-test.
  config.communication_loss_periods = 250;
  canopen::DriveNode drive{config};
  drive.start(test::monotonic_us(), bus);
  std::int32_t axis = 0;
  CanFrame f{};
  while (stop_requested == 0) {
    const ReceiveStatus status = bus.receive(f, 1000);
    const std::uint64_t now = test::monotonic_us();
    if (status == ReceiveStatus::received && drive.on_frame(f, now, bus) == canopen::DriveEvent::sync) {
      if (drive.stopping()) {
        drive.stop_complete();  // an ideal axis is at rest at once
      } else if (drive.following()) {
        axis = drive.setpoint();
      }
      drive.publish(canopen::DriveFeedback{axis, 0, axis}, now, bus);
    }
    drive.poll(now, bus);
  }
  const auto& c = drive.counters();
  std::printf("syncs=%llu\nrpdos_applied=%llu\nrpdos_overwritten=%llu\nrpdos_missing=%llu\nrpdos_rejected=%llu\n"
              "sync_gaps=%llu\nemcy_sent=%llu\nstate=%s\n",
              static_cast<unsigned long long>(c.syncs), static_cast<unsigned long long>(c.rpdos_applied),
              static_cast<unsigned long long>(c.rpdos_overwritten), static_cast<unsigned long long>(c.rpdos_missing),
              static_cast<unsigned long long>(c.rpdos_rejected), static_cast<unsigned long long>(c.sync_gaps),
              static_cast<unsigned long long>(c.emcy_sent), canopen::to_string(drive.state()));
  return 0;
}

void print_flow(const test::FlowResult& r, const SocketCanBus& bus) {
  std::printf("frames=%llu\nbusy=%llu\ndrops=%llu\ncomplete=%d\nframes_per_second=%.0f\n",
              static_cast<unsigned long long>(r.frames), static_cast<unsigned long long>(r.busy),
              static_cast<unsigned long long>(bus.counters().rx_overflow_drops), r.complete ? 1 : 0,
              r.frames_per_second());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s drive <node> | sink <count> | source <count>\n", argv[0]);
    return 2;
  }
  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  SocketCanBus bus;
  SocketCanOptions options{};
  options.receive_buffer_bytes = 4 << 20;
  const OpenStatus open = bus.open(test::vcan_interface, options);
  if (open != OpenStatus::ok) {
    std::fprintf(stderr, "vcan_peer: cannot open %s: %s\n", test::vcan_interface, to_string(open));
    return 3;
  }
  const std::string mode = argv[1];
  const unsigned long value = std::strtoul(argv[2], nullptr, 10);
  if (mode == "drive") {
    return run_drive(bus, static_cast<canopen::NodeId>(value));
  }
  if (mode == "sink") {
    // Filters first, then "ready": the master must not send before this socket listens.
    (void)test::listen_only_to(bus, 0x123);
    std::printf("ready\n");
    std::fflush(stdout);
    const test::FlowResult r = test::receive_acking(bus, 0x123, 0x124, value);
    print_flow(r, bus);
    return r.complete ? 0 : 1;
  }
  if (mode == "source") {
    const test::FlowResult r = test::send_windowed(bus, 0x321, 0x322, value);
    print_flow(r, bus);
    return r.complete ? 0 : 1;
  }
  return 2;
}
