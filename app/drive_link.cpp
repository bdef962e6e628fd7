// SPDX-License-Identifier: Apache-2.0
#include "drive_link.hpp"

#include <algorithm>

#include "settle/runtime/linux/periodic.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "settle/testbed/simulated_drive.hpp"
#include "socketcan_open.hpp"

namespace settle::app {

namespace {

using hal::canopen::NodeId;

// Real time: a SocketCAN interface, only the SDO answers (0x580 + node) let through.
class SocketCanDriveLink final : public DriveLink {
 public:
  hal::OpenStatus open(const std::string& iface) {
    const hal::OpenStatus os = open_socketcan(bus_, iface);
    if (os != hal::OpenStatus::ok) return os;
    const hal::CanFilter sdo_answers{0x580, 0x780, hal::FrameFormat::standard};
    (void)bus_.set_filters({&sdo_answers, 1});  // without filters every frame comes: still correct
    return os;
  }
  hal::CanBus& bus() override { return bus_; }
  std::uint64_t now_us() override { return runtime::linux_rt::monotonic_ns() / 1000; }
  bool receive(hal::CanFrame& frame, std::uint32_t wait_us) override {
    return bus_.receive(frame, wait_us) == hal::ReceiveStatus::received;
  }

 private:
  hal::SocketCanBus bus_;
};

// Virtual time: the drive in this process. Each wait first lets the drive take every frame sent
// to it (and answer at once); time moves only when nothing is left to take.
class LoopbackDriveLink final : public DriveLink {
 public:
  explicit LoopbackDriveLink(testbed::SimulatedDrive drive) : drive_{std::move(drive)} { drive_.node->start(now_, drive_port_); }
  hal::CanBus& bus() override { return master_; }
  std::uint64_t now_us() override { return now_; }
  bool receive(hal::CanFrame& frame, std::uint32_t wait_us) override {
    hal::CanFrame f{};
    while (drive_port_.receive(f) == hal::ReceiveStatus::received) (void)drive_.node->on_frame(f, now_, drive_port_);
    drive_.node->poll(now_, drive_port_);
    if (master_.receive(frame) == hal::ReceiveStatus::received) return true;
    now_ += std::max<std::uint32_t>(wait_us, 1);
    hub_.set_time_us(now_);
    drive_.node->poll(now_, drive_port_);
    return false;
  }

 private:
  std::uint64_t now_{0};
  hal::LoopbackHub hub_;
  hal::LoopbackBus<256> master_{hub_};
  hal::LoopbackBus<256> drive_port_{hub_};
  testbed::SimulatedDrive drive_;
};

// How long one wait lasts while transfers run: their timeouts are judged at least this often.
constexpr std::uint32_t kWaitUs = 10'000;

}  // namespace

std::unique_ptr<DriveLink> open_drive_link(const std::string& bus, NodeId node, const hal::eds::Description* eds,
                                           std::string& error) {
  if (bus == "loopback") {
    // The simulated drive (testbed::build_simulated_drive): the one the --eds description
    // describes, as `settle plant --eds` builds it, or the default drive, as `node`.
    testbed::SimulatedDriveSpec spec{};
    spec.node = node;
    spec.eds = eds;
    testbed::SimulatedDriveError why;
    testbed::SimulatedDrive drive = testbed::build_simulated_drive(spec, why);
    if (!drive.node) {
      error = why.message();
      return nullptr;
    }
    return std::make_unique<LoopbackDriveLink>(std::move(drive));
  }
  auto link = std::make_unique<SocketCanDriveLink>();
  if (const hal::OpenStatus os = link->open(bus); os != hal::OpenStatus::ok) {
    error = "cannot open " + bus + ": " + hal::to_string(os) + " (try --bus loopback)";
    return nullptr;
  }
  return link;
}

void serve_clients(DriveLink& link, std::span<hal::canopen::SdoClient> clients, const hal::CanFrame* frame) {
  for (hal::canopen::SdoClient& c : clients) {
    if (frame != nullptr && c.busy()) (void)c.on_frame(*frame, link.now_us(), link.bus());
    c.poll(link.now_us(), link.bus());
  }
}

void finish_transfers(DriveLink& link, std::span<hal::canopen::SdoClient> clients) {
  while (std::any_of(clients.begin(), clients.end(), [](const hal::canopen::SdoClient& c) { return c.busy(); })) {
    hal::CanFrame f{};
    const bool got = link.receive(f, kWaitUs);
    serve_clients(link, clients, got ? &f : nullptr);
  }
}

}  // namespace settle::app
