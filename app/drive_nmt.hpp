// SPDX-License-Identifier: Apache-2.0
#pragma once
// settle drive nmt once its link is open (cmd_drive.cpp opens it): the CiA 301 command sent to one
// node, the node's heartbeat watched for the state the command leads to, and the outcome printed
// with its exit status. Apart from the command, so that a test can put a peer that disobeys on the
// in-process bus, which the simulated drive never does.
#include <cstdint>
#include <cstdio>
#include <string>

#include "io/json.hpp"
#include "settle/hal/can_bus.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/testbed/clocked_bus.hpp"

namespace settle::app {

struct NmtRequest {
  hal::canopen::NodeId node{1};
  std::string word;                      // start, stop, preop, reset or reset-comm (the option table's choices)
  std::uint32_t timeout_us{1'000'000};   // --timeout-ms: the wait for the heartbeat
  bool json{false};
  std::string bus_name;                  // as the output names it
};

// What the link must let through for it: the node's heartbeat (0x700 + node).
[[nodiscard]] hal::CanFilter nmt_heartbeat_filter(hal::canopen::NodeId node);

// Sends the command (COB-ID 0, hal's encode_nmt), then watches the node's heartbeat (hal's
// HeartbeatConsumer) for at most r.timeout_us until it carries the state the command leads to.
// Confirmed: exit 0. No heartbeat at all (0x1017 = 0, or a node that is not there): exit 0, reported
// as not confirmed; nothing is claimed. Heartbeats only of another state: exit 1, nmt_state, naming
// the state it reported (the node did not obey); the command not sent: exit 1, send_failed. The
// report goes to `out` (text or JSON), a failure's text line to `err` (its JSON to `out`).
[[nodiscard]] int run_drive_nmt(testbed::ClockedBus& link, const NmtRequest& r, std::FILE* out, std::FILE* err);

// A runtime failure of `settle drive <command>`: one line on `err`, or with `json` the error object
// (with `detail`'s keys) on `out`. Returns the exit status, 1.
int drive_failure(const std::string& command, const std::string& code, const std::string& message, const Json& detail,
                  bool json, std::FILE* out, std::FILE* err);

}  // namespace settle::app
