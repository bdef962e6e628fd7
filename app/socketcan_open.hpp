// SPDX-License-Identifier: Apache-2.0
#pragma once
// How both ends of a settle run (settle plant, settle stream) open their SocketCAN interface.
#include <string>

#include "settle/hal/socketcan_bus.hpp"

namespace settle::app {

// A large receive queue: a stalled process (a busy host, a user-mode-linux guest) falls behind
// without dropping frames, and the kernel's drop counter tells us if it ever does. The kernel
// doubles the request and charges about 768 bytes per queued CAN frame: 16 MB holds some 43 000
// frames, about 20 s of one axis at 1 kHz (1 MB held 1.3 s, and a stalled guest outlasted it).
// Only frames actually queued use the memory.
[[nodiscard]] inline hal::OpenStatus open_socketcan(hal::SocketCanBus& bus, const std::string& iface) {
  hal::SocketCanOptions options{};
  options.receive_buffer_bytes = 16 << 20;
  return bus.open(iface.c_str(), options);
}

}  // namespace settle::app
