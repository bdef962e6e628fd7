// SPDX-License-Identifier: Apache-2.0
#pragma once
// What to tell the user when a stream or an excitation lost its drive: the drive's own EMCY (its
// code, what it means, which rule fired) and the options that set the timeouts involved. One
// place for settle stream and settle identify.
#include <optional>
#include <string>

#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/emcy.hpp"
#include "settle/testbed/stream.hpp"

namespace settle::app {

// "" unless the run ended with the drive lost or silent, or the drive sent an error EMCY.
[[nodiscard]] inline std::string drive_advice(const testbed::StreamReport& r) {
  namespace co = hal::canopen;
  const runtime::SessionOutcome o = r.session.outcome;
  const bool lost = o == runtime::SessionOutcome::drive_lost || o == runtime::SessionOutcome::feedback_timeout;
  // Axis 1's drive (the EMCY the report's single-axis fields show).
  const std::optional<co::EmcyMessage>& emcy = r.axes.empty() ? std::nullopt : r.axes.front().drive_emcy;
  if (!lost && !emcy) return {};
  const std::string loop = "the loop's --heartbeat-ms " + std::to_string(r.heartbeat_ms) +
                           ", --feedback-timeout-periods " + std::to_string(r.feedback_timeout_periods);
  if (!emcy) {
    return "the drive sent no EMCY; it stopped answering within " + loop +
           " (on a loaded host use --timing sim, or raise these)";
  }
  const co::EmcyMessage& e = *emcy;
  std::string s = "the drive reported " + testbed::emcy_text(e);
  const std::uint8_t cause = e.data[0];
  const bool sync_or_rpdo = (e.error_code == co::emcy_code::communication &&
                             (cause == co::emcy_cause::sync_loss || cause == co::emcy_cause::none)) ||
                            e.error_code == co::emcy_code::rpdo_timeout;
  if (sync_or_rpdo) {
    s += "; the master's SYNCs or setpoints came too late for the drive: on a loaded host run the drive (settle "
         "plant) with --timing sim or raise its --sync-loss-periods, and the loop with --timing sim (" + loop + ")";
  } else if (e.error_code == co::emcy_code::life_guard) {
    s += "; the drive stopped hearing the master's heartbeat (its 0x1016): on a loaded host run the loop with "
         "--timing sim";
  }
  return s;
}

}  // namespace settle::app
