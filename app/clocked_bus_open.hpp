// SPDX-License-Identifier: Apache-2.0
#pragma once
// The bus a streaming master command (settle stream, settle identify) runs on, from its options:
// --bus loopback (the simulated drive in this process, virtual time) or a SocketCAN interface with
// --rt-priority and --pm-qos, both with --candump. One place for both commands.
#include <memory>
#include <string>

#include "options.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "settle/testbed/clocked_bus.hpp"
#include "socketcan_open.hpp"

namespace settle::app {

// The bus, or nullptr with `error` saying why the interface cannot be opened. `socketcan` must
// outlive the returned bus.
[[nodiscard]] inline std::unique_ptr<testbed::ClockedBus> open_clocked_bus(const ParsedArgs& args, hal::SocketCanBus& socketcan,
                                                                     std::string& error) {
  const std::string bus_name = args.text_or_default("--bus");
  const std::string candump = args.text("--candump").value_or("");
  if (bus_name == "loopback") return std::make_unique<testbed::LoopbackClockedBus>(candump);
  if (const hal::OpenStatus os = open_socketcan(socketcan, bus_name); os != hal::OpenStatus::ok) {
    error = "cannot open " + bus_name + ": " + hal::to_string(os) + " (try --bus loopback)";
    return nullptr;
  }
  const auto priority = static_cast<int>(args.integer("--rt-priority", 0));  // 0..99
  const bool pm_qos = args.text_or_default("--pm-qos") == "on";
  return std::make_unique<testbed::SocketCanClockedBus>(socketcan, bus_name, candump, priority, pm_qos);
}

}  // namespace settle::app
