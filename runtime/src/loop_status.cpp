// SPDX-License-Identifier: Apache-2.0
#include "settle/runtime/servo_loop.hpp"
#include "settle/runtime/session.hpp"

namespace settle::runtime {

const char* to_string(LoopStatus s) noexcept {
  switch (s) {
    case LoopStatus::ok: return "ok";
    case LoopStatus::plan_failed: return "plan_failed";
    case LoopStatus::queue_full: return "queue_full";
    case LoopStatus::no_such_axis: return "no_such_axis";
    case LoopStatus::too_many_axes: return "too_many_axes";
    case LoopStatus::exceeds_axis_velocity: return "exceeds_axis_velocity";
    case LoopStatus::does_not_fit_counts: return "does_not_fit_counts";
    case LoopStatus::bad_axis_config: return "bad_axis_config";
    case LoopStatus::evaluation_refused: return "evaluation_refused";
    case LoopStatus::position_limit: return "position_limit";
    case LoopStatus::exceeds_drive_velocity: return "exceeds_drive_velocity";
  }
  return "unknown";
}

const char* to_string(AxisFault f) noexcept {
  switch (f) {
    case AxisFault::none: return "none";
    case AxisFault::heartbeat_lost: return "heartbeat_lost";
    case AxisFault::drive_restarted: return "drive_restarted";
    case AxisFault::drive_left_enabled: return "drive_left_enabled";
    case AxisFault::drive_not_operational: return "drive_not_operational";
    case AxisFault::start_up_failed: return "start_up_failed";
    case AxisFault::feedback_timeout: return "feedback_timeout";
    case AxisFault::following_error: return "following_error";
    case AxisFault::step_guard: return "step_guard";
    case AxisFault::not_in_position: return "not_in_position";
    case AxisFault::foreign_sync: return "foreign_sync";
    case AxisFault::bus_off: return "bus_off";
    case AxisFault::send_failed: return "send_failed";
  }
  return "unknown";
}

const char* to_string(LoopEventKind k) noexcept {
  switch (k) {
    case LoopEventKind::drive_ready: return "drive_ready";
    case LoopEventKind::move_started: return "move_started";
    case LoopEventKind::move_completed: return "move_completed";
    case LoopEventKind::move_voided: return "move_voided";
    case LoopEventKind::axis_stopped: return "axis_stopped";
    case LoopEventKind::start_up_rerun: return "start_up_rerun";
    case LoopEventKind::foreign_sync: return "foreign_sync";
    case LoopEventKind::bus_error_warning: return "bus_error_warning";
    case LoopEventKind::bus_error_passive: return "bus_error_passive";
    case LoopEventKind::bus_error_active: return "bus_error_active";
    case LoopEventKind::bus_off: return "bus_off";
    case LoopEventKind::bus_restart_requested: return "bus_restart_requested";
    case LoopEventKind::bus_restart_refused: return "bus_restart_refused";
  }
  return "unknown";
}

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

const char* to_string(SessionOutcome o) noexcept {
  switch (o) {
    case SessionOutcome::completed: return "completed";
    case SessionOutcome::enable_failed: return "enable_failed";
    case SessionOutcome::drive_lost: return "drive_lost";
    case SessionOutcome::rejected: return "rejected";
    case SessionOutcome::timeout: return "timeout";
    case SessionOutcome::feedback_timeout: return "feedback_timeout";
    case SessionOutcome::drive_not_operational: return "drive_not_operational";
    case SessionOutcome::foreign_sync: return "foreign_sync";
    case SessionOutcome::bus_off: return "bus_off";
    case SessionOutcome::send_failed: return "send_failed";
    case SessionOutcome::not_in_position: return "not_in_position";
    case SessionOutcome::step_guard: return "step_guard";
  }
  return "unknown";
}

}  // namespace settle::runtime
