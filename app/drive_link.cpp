// SPDX-License-Identifier: Apache-2.0
#include "drive_link.hpp"

#include <algorithm>
#include <vector>

#include "settle/testbed/simulated_drive.hpp"
#include "settle/testbed/clocked_bus.hpp"
#include "socketcan_open.hpp"

namespace settle::app {

namespace {

// How long one wait lasts while transfers run: their timeouts are judged at least this often.
constexpr std::uint32_t kWaitUs = 10'000;

}  // namespace

std::unique_ptr<testbed::ClockedBus> open_drive_link(const std::string& bus, hal::canopen::NodeId node,
                                           const hal::eds::Description* eds, hal::SocketCanBus& socketcan,
                                           std::string& error, const hal::CanFilter& accept) {
  if (bus == "loopback") {
    testbed::SimulatedDriveSpec drive{};
    drive.node = node;
    drive.eds = eds;
    auto link = std::make_unique<testbed::LoopbackClockedBus>();
    error = link->open(drive.axis.scale.period_us, {drive});
    if (!error.empty()) return nullptr;
    return link;
  }
  if (const hal::OpenStatus os = open_socketcan(socketcan, bus); os != hal::OpenStatus::ok) {
    error = "cannot open " + bus + ": " + hal::to_string(os) + " (try --bus loopback)";
    return nullptr;
  }
  (void)socketcan.set_filters({&accept, 1});  // without filters every frame comes: still correct
  return std::make_unique<testbed::SocketCanClockedBus>(socketcan, bus, std::string{}, 0, false);
}

void serve_clients(testbed::ClockedBus& link, std::span<hal::canopen::SdoClient> clients, const hal::CanFrame* frame) {
  for (hal::canopen::SdoClient& c : clients) {
    if (frame != nullptr && c.busy()) (void)c.on_frame(*frame, link.now_us(), link.link());
    c.poll(link.now_us(), link.link());
  }
}

void finish_transfers(testbed::ClockedBus& link, std::span<hal::canopen::SdoClient> clients) {
  while (std::any_of(clients.begin(), clients.end(), [](const hal::canopen::SdoClient& c) { return c.busy(); })) {
    hal::CanFrame f{};
    const bool got = link.receive(f, kWaitUs);
    serve_clients(link, clients, got ? &f : nullptr);
  }
}

}  // namespace settle::app
