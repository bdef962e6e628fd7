#include "settle/firmware/servo_loop.hpp"
#include "settle/firmware/session.hpp"

namespace settle::firmware {

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
  }
  return "unknown";
}

const char* to_string(SessionOutcome o) noexcept {
  switch (o) {
    case SessionOutcome::completed: return "completed";
    case SessionOutcome::enable_failed: return "enable_failed";
    case SessionOutcome::drive_lost: return "drive_lost";
    case SessionOutcome::rejected: return "rejected";
    case SessionOutcome::timeout: return "timeout";
  }
  return "unknown";
}

}  // namespace settle::firmware
