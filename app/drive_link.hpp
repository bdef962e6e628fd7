// SPDX-License-Identifier: Apache-2.0
#pragma once
// What `settle drive` talks to: the bus with a clock every command uses (testbed::ClockedBus), on
// which SDO transfers run to their end. Two kinds: a SocketCAN interface in real time (a `settle
// plant` process, a real drive), and --bus loopback, the simulated drive in this process
// (testbed::build_simulated_drive: the one the --eds description describes, as `settle plant
// --eds` builds it, or the default drive, at the requested node id), in virtual time.
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/eds_reader.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "settle/testbed/clocked_bus.hpp"

namespace settle::app {

// What a SocketCAN link lets through by default: the SDO answers (0x580..0x5FF).
inline constexpr hal::CanFilter kSdoAnswers{0x580, 0x780, hal::FrameFormat::standard};

// The interface named by --bus: "loopback" (the in-process drive as `node`, described by `eds`
// when there is one), else a SocketCAN interface opened on `socketcan` (which must outlive the
// result) with only the frames `accept` matches let through (settle drive nmt: the node's
// heartbeat). nullptr with `error` set when it cannot be opened (or, loopback, when the drive
// cannot be built from `eds`).
[[nodiscard]] std::unique_ptr<testbed::ClockedBus> open_drive_link(const std::string& bus, hal::canopen::NodeId node,
                                                         const hal::eds::Description* eds,
                                                         hal::SocketCanBus& socketcan, std::string& error,
                                                         const hal::CanFilter& accept = kSdoAnswers);

// Runs the transfers already started on `clients` until none is busy: each answer goes to the
// client it belongs to, and each times out on its own (its own abort on the bus).
void finish_transfers(testbed::ClockedBus& link, std::span<hal::canopen::SdoClient> clients);

// Hands a received frame to every busy client, then lets each time out if its time has come.
void serve_clients(testbed::ClockedBus& link, std::span<hal::canopen::SdoClient> clients, const hal::CanFrame* frame);

// Starts a transfer: `start(now, bus)` is retried while the bus has no room for the request
// (a full transmit queue), for at most about a second; meanwhile the transfers already running
// on `running` go on. False when it never went out.
template <typename Start>
[[nodiscard]] bool start_transfer(testbed::ClockedBus& link, std::span<hal::canopen::SdoClient> running, Start&& start) {
  for (int attempt = 0; attempt < 1000; ++attempt) {
    if (start(link.now_us(), link.link())) return true;
    hal::CanFrame f{};
    const bool got = link.receive(f, 1000);
    serve_clients(link, running, got ? &f : nullptr);
  }
  return false;
}

// One transfer on one client, to its end. A request that never went out ends as a timeout.
template <typename Start>
[[nodiscard]] hal::canopen::SdoResult transfer(testbed::ClockedBus& link, hal::canopen::SdoClient& client, Start&& start) {
  if (!start_transfer(link, {}, start)) {
    hal::canopen::SdoResult r{};
    r.status = hal::canopen::SdoClientStatus::timed_out;
    r.abort = hal::canopen::SdoAbort::timeout;
    r.abort_raw = static_cast<std::uint32_t>(hal::canopen::SdoAbort::timeout);
    return r;
  }
  finish_transfers(link, {&client, 1});
  return client.result();
}

}  // namespace settle::app
