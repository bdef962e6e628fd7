// The other process of the vcan suites. Modes:
//   vcan_peer drive <node>        a Settle drive (DriveNode, ideal axis) until SIGTERM, then
//                                 prints its counters as key=value lines
//   vcan_peer sink <count>        receives <count> frames with id 0x123, prints the rate
//   vcan_peer source <count>      sends <count> frames with id 0x321 as fast as the bus takes
//                                 them (a busy bus is retried, never skipped), prints the rate
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>

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

int run_sink(SocketCanBus& bus, unsigned long count) {
  const CanFilter only{0x123, 0x7FF, FrameFormat::standard};
  if (bus.set_filters({&only, 1}) != BusStatus::ok) {
    return 2;
  }
  std::printf("ready\n");
  std::fflush(stdout);
  unsigned long received = 0;
  std::uint64_t first = 0;
  CanFrame f{};
  std::uint64_t last = test::monotonic_us();
  // Ends after `count` frames, or after a second of silence when some were dropped (the
  // drops are counted by the kernel and reported, so the sum is checked, not hoped for).
  while (received + bus.counters().rx_overflow_drops < count && stop_requested == 0 &&
         test::monotonic_us() - last < 1'000'000) {
    if (bus.receive(f, 100'000) == ReceiveStatus::received) {
      last = test::monotonic_us();
      if (received++ == 0) {
        first = last;
      }
    }
  }
  const double seconds = static_cast<double>(test::monotonic_us() - first) * 1e-6;
  std::printf("received=%lu\ndrops=%llu\nframes_per_second=%.0f\n", received,
              static_cast<unsigned long long>(bus.counters().rx_overflow_drops),
              seconds > 0 ? static_cast<double>(received) / seconds : 0.0);
  return 0;
}

int run_source(SocketCanBus& bus, unsigned long count) {
  CanFrame f{};
  f.id = 0x321;
  f.len = 8;
  const std::uint64_t start = test::monotonic_us();
  for (unsigned long i = 0; i < count && stop_requested == 0;) {
    std::memcpy(f.data.data(), &i, sizeof i);
    const SendStatus s = bus.send(f);
    if (s == SendStatus::sent) {
      ++i;
    } else if (s == SendStatus::busy) {
      std::this_thread::yield();  // back-pressure: let the receiver drain
    } else {
      return 1;
    }
  }
  const double seconds = static_cast<double>(test::monotonic_us() - start) * 1e-6;
  std::printf("sent=%llu\nbusy=%llu\nframes_per_second=%.0f\n", static_cast<unsigned long long>(bus.counters().sent),
              static_cast<unsigned long long>(bus.counters().tx_busy),
              seconds > 0 ? static_cast<double>(bus.counters().sent) / seconds : 0.0);
  return 0;
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
  const OpenStatus open = bus.open(test::vcan_interface);
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
    return run_sink(bus, value);
  }
  if (mode == "source") {
    return run_source(bus, value);
  }
  return 2;
}
