// SPDX-License-Identifier: Apache-2.0
#include "settle/runtime/servo_loop.hpp"
#include "settle/runtime/session.hpp"

namespace settle::runtime {

namespace {
constexpr const char* kLoopStatusCodes[] = {SETTLE_LOOP_STATUSES(SETTLE_ENUM_CODE)};
constexpr const char* kLoopStatusTexts[] = {SETTLE_LOOP_STATUSES(SETTLE_ENUM_TEXT)};
constexpr const char* kAxisFaultCodes[] = {SETTLE_AXIS_FAULTS(SETTLE_ENUM_CODE)};
constexpr const char* kAxisFaultTexts[] = {SETTLE_AXIS_FAULTS(SETTLE_ENUM_TEXT)};
constexpr const char* kLoopEventCodes[] = {SETTLE_LOOP_EVENT_KINDS(SETTLE_ENUM_CODE)};
constexpr const char* kLoopEventTexts[] = {SETTLE_LOOP_EVENT_KINDS(SETTLE_ENUM_TEXT)};
constexpr const char* kOutcomeCodes[] = {SETTLE_SESSION_OUTCOMES(SETTLE_ENUM_CODE)};
constexpr const char* kOutcomeTexts[] = {SETTLE_SESSION_OUTCOMES(SETTLE_ENUM_TEXT)};
}  // namespace

const char* to_string(LoopStatus s) noexcept { return core::enum_text(kLoopStatusCodes, s, "unknown"); }
const char* describe(LoopStatus s) noexcept { return core::enum_text(kLoopStatusTexts, s, "unknown"); }
const char* to_string(AxisFault f) noexcept { return core::enum_text(kAxisFaultCodes, f, "unknown"); }
const char* describe(AxisFault f) noexcept { return core::enum_text(kAxisFaultTexts, f, "unknown"); }
const char* to_string(LoopEventKind k) noexcept { return core::enum_text(kLoopEventCodes, k, "unknown"); }
const char* describe(LoopEventKind k) noexcept { return core::enum_text(kLoopEventTexts, k, "unknown"); }
const char* to_string(SessionOutcome o) noexcept { return core::enum_text(kOutcomeCodes, o, "unknown"); }
const char* describe(SessionOutcome o) noexcept { return core::enum_text(kOutcomeTexts, o, "unknown"); }

SessionOutcome session_outcome_for(AxisFault f) noexcept {
  switch (f) {
    case AxisFault::feedback_timeout: return SessionOutcome::feedback_timeout;
    case AxisFault::drive_not_operational: return SessionOutcome::drive_not_operational;
    case AxisFault::foreign_sync: return SessionOutcome::foreign_sync;
    case AxisFault::bus_off: return SessionOutcome::bus_off;
    case AxisFault::send_failed: return SessionOutcome::send_failed;
    case AxisFault::not_in_position: return SessionOutcome::not_in_position;
    case AxisFault::step_guard: return SessionOutcome::step_guard;
    case AxisFault::none:
    case AxisFault::heartbeat_lost:
    case AxisFault::drive_restarted:
    case AxisFault::drive_left_enabled:
    case AxisFault::start_up_failed:
    case AxisFault::following_error: break;
  }
  return SessionOutcome::drive_lost;
}

}  // namespace settle::runtime
