// SPDX-License-Identifier: Apache-2.0
#include "drive_nmt.hpp"

#include <optional>
#include <string_view>

#include "commands.hpp"
#include "drive_link.hpp"
#include "settle/hal/canopen/heartbeat.hpp"

namespace settle::app {

namespace {

// A command word of settle drive nmt, the CiA 301 command it sends, and the state the node's
// heartbeat carries once it has obeyed (a reset: its boot-up message, state byte 0).
struct NmtWord {
  std::string_view word;
  hal::canopen::NmtCommand command;
  hal::canopen::NmtState expect;
};
constexpr NmtWord kNmtWords[] = {
    {"start", hal::canopen::NmtCommand::start, hal::canopen::NmtState::operational},
    {"stop", hal::canopen::NmtCommand::stop, hal::canopen::NmtState::stopped},
    {"preop", hal::canopen::NmtCommand::enter_pre_operational, hal::canopen::NmtState::pre_operational},
    {"reset", hal::canopen::NmtCommand::reset_node, hal::canopen::NmtState::initialising},
    {"reset-comm", hal::canopen::NmtCommand::reset_communication, hal::canopen::NmtState::initialising},
};

const NmtWord* nmt_word(const std::string& word) {
  for (const NmtWord& w : kNmtWords) {
    if (w.word == word) return &w;
  }
  return nullptr;
}

// A state as the output names it (state byte 0 is only ever seen as the boot-up message).
std::string state_name(hal::canopen::NmtState state) {
  switch (state) {
    case hal::canopen::NmtState::initialising: return "boot-up";
    case hal::canopen::NmtState::stopped: return "stopped";
    case hal::canopen::NmtState::operational: return "operational";
    case hal::canopen::NmtState::pre_operational: return "pre-operational";
  }
  return "unknown";
}

}  // namespace

hal::CanFilter nmt_heartbeat_filter(hal::canopen::NodeId node) {
  return {hal::canopen::cob_id(hal::canopen::cob::heartbeat, node), 0x7FF, hal::FrameFormat::standard};
}

int drive_failure(const std::string& command, const std::string& code, const std::string& message, const Json& detail,
                  bool json, std::FILE* out, std::FILE* err) {
  if (json) {
    Json j{{"status", "error"}, {"error", code}, {"message", message}};
    for (auto it = detail.begin(); it != detail.end(); ++it) j[it.key()] = it.value();
    print_json(j, out);
  } else {
    std::fprintf(err, "settle drive %s: %s\n", command.c_str(), message.c_str());
  }
  return kExitFailure;
}

int run_drive_nmt(testbed::ClockedBus& link, const NmtRequest& r, std::FILE* out, std::FILE* err) {
  const auto failed = [&](const std::string& code, const std::string& message, const Json& detail = Json::object()) {
    return drive_failure("nmt", code, message, detail, r.json, out, err);
  };
  const NmtWord* w = nmt_word(r.word);
  if (w == nullptr) return failed("unknown_command", "unknown NMT command '" + r.word + "'");  // the parser let none through
  const hal::canopen::NodeId node = r.node;
  const std::string who = "node " + std::to_string(node);
  // What the node sent before the command (loopback: its power-on boot-up) says nothing about it.
  hal::CanFrame stale{};
  for (int k = 0; k < 1024 && link.receive(stale, 0); ++k) {
  }
  const hal::CanFrame command = hal::canopen::encode_nmt(w->command, node);
  // Retried while the transmit queue is full, as an SDO request is (drive_link.hpp).
  if (!start_transfer(link, {}, [&](std::uint64_t, hal::CanBus& bus) {
        return bus.send(command) == hal::SendStatus::sent;
      })) {
    return failed("send_failed", who + ": the NMT command could not be sent on " + r.bus_name);
  }
  const std::uint64_t sent_us = link.now_us();
  hal::canopen::HeartbeatConsumer watch{node, static_cast<std::uint16_t>(r.timeout_us / 1000U)};
  std::optional<hal::canopen::NmtState> seen;
  while (link.now_us() - sent_us < r.timeout_us && seen != w->expect) {
    hal::CanFrame f{};
    if (!link.receive(f, 10'000)) continue;
    (void)watch.on_frame(f, link.now_us());  // other frames change nothing
    seen = watch.state();
  }
  const double waited_ms = static_cast<double>(link.now_us() - sent_us) / 1000.0;
  const std::string wait_text = std::to_string(r.timeout_us / 1000U) + " ms";
  const std::string word{w->word};
  if (seen && *seen != w->expect) {
    return failed("nmt_state", who + ": its heartbeat says " + state_name(*seen) + ", not " + state_name(w->expect) +
                                   ", " + wait_text + " after NMT " + word,
                  {{"node", node}, {"command", word}, {"state", state_name(*seen)}});
  }
  if (r.json) {
    print_json({{"status", "ok"},
                {"bus", r.bus_name},
                {"node", node},
                {"command", word},
                {"command_byte", static_cast<unsigned>(w->command)},
                {"confirmed", seen.has_value()},
                {"state", seen ? Json(state_name(*seen)) : Json(nullptr)},
                {"state_byte", seen ? Json(static_cast<unsigned>(*seen)) : Json(nullptr)},
                {"waited_ms", waited_ms}},
               out);
    return kExitOk;
  }
  if (!seen) {
    std::fprintf(out,
                 "%s: NMT %s sent; state not confirmed: no heartbeat within %s (producer heartbeat 0x1017 off, "
                 "or slower than that, or no node %u on %s)\n",
                 who.c_str(), word.c_str(), wait_text.c_str(), static_cast<unsigned>(node), r.bus_name.c_str());
  } else if (*seen == hal::canopen::NmtState::initialising) {
    std::fprintf(out, "%s: NMT %s sent; its boot-up message came: the reset is done (after %.1f ms)\n", who.c_str(),
                 word.c_str(), waited_ms);
  } else {
    std::fprintf(out, "%s: NMT %s sent; its heartbeat says %s (after %.1f ms)\n", who.c_str(), word.c_str(),
                 state_name(*seen).c_str(), waited_ms);
  }
  return kExitOk;
}

}  // namespace settle::app
