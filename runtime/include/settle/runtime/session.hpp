// SPDX-License-Identifier: Apache-2.0
#pragma once
// One streaming session, the same on every target and for any number of axes: start the drives,
// tick until every drive is in operation enabled (refusing to stream before), queue the moves,
// tick until they are done, keep ticking through a settling window (the feedback that proves the
// machine is at rest), take the drives out of operation enabled before going quiet (see
// release_drives), and say how it ended. Generic over the loop, the clock (a Linux periodic
// timer, a SysTick, a test's virtual clock) and an observer called after every tick.
#include <cstddef>
#include <cstdint>

#include "settle/core/move.hpp"
#include "settle/runtime/servo_loop.hpp"

namespace settle::runtime {

// How a session ended, made from one list (core/enum_text.hpp): enumerator (= code) and sentence.
#define SETTLE_SESSION_OUTCOMES(X) \
  X(completed, "every move streamed and the settling window observed") \
  X(enable_failed, "a drive never reached operation enabled (or refused its configuration)") \
  X(drive_lost, "heartbeat lost, fault, restart or following error: streaming stopped") \
  X(rejected, "a move was refused before anything was streamed for it") \
  X(timeout, "the session ran past max_ticks") \
  /* The loop halted the axis (SessionResult::fault says the same): */ \
  X(feedback_timeout, "the drive stopped answering the SYNC (its TPDOs stopped)") \
  X(drive_not_operational, "its heartbeat said pre-operational or stopped: someone else's NMT") \
  X(foreign_sync, "a second SYNC producer on the bus") \
  X(bus_off, "the controller went bus-off (the loop restarts it and the drives' start-up)") \
  X(send_failed, "the RPDO + SYNC unit could not be sent for LoopConfig::send_failure_periods") \
  X(not_in_position, "the feedback never showed the final setpoint within one count") \
  /* the command was not what the plan promised; the drive is fine and holds where it was */ \
  X(step_guard, "the loop's own step guard refused a setpoint (a step over AxisConfig::vmax x period + margin)")
enum class SessionOutcome : std::uint8_t { SETTLE_SESSION_OUTCOMES(SETTLE_ENUM_ENUMERATOR) };

[[nodiscard]] const char* to_string(SessionOutcome o) noexcept;
[[nodiscard]] const char* describe(SessionOutcome o) noexcept;
// The outcome that names the fault (drive_lost for the drive's own stops and the following error).
[[nodiscard]] SessionOutcome session_outcome_for(AxisFault f) noexcept;

struct SessionConfig {
  std::uint64_t enable_timeout_ticks{3000};
  std::uint64_t settle_ticks{1000};
  std::uint64_t max_ticks{600'000};
  // Ticks the drive has, after the session, to confirm it left operation enabled (it takes two:
  // the Shutdown's SYNC, then its feedback); beyond max_ticks.
  std::uint64_t release_ticks{1000};
};

struct SessionResult {
  SessionOutcome outcome{SessionOutcome::completed};
  LoopStatus rejection{LoopStatus::ok};
  AxisFault fault{AxisFault::none};  // why streaming stopped, when it did
  // The axis the outcome is about (enable_failed, rejected, drive_lost and the loop's faults: the
  // first axis found in it, in axis order); 0 when the outcome is completed or timeout.
  std::size_t axis{0};
  std::uint64_t ticks{0};
  std::uint64_t ready_tick{0};      // first tick with every drive ready (every move submitted after it)
  std::uint64_t stream_end_tick{0}; // first tick with every move on every axis done
  std::uint64_t missed_periods{0};  // reported by the clock (overruns skipped, not caught up)
  // Every drive still operation enabled when the session ended (at least one) confirmed the
  // release (RemoteDriveState::released) within release_ticks, after `release_ticks` more ticks.
  bool released{false};
  std::uint64_t release_ticks{0};
};

namespace detail {

// Ends streaming on every axis: the one at fault and the others, which hold where they are.
template <typename Loop>
void abort_all(Loop& loop) noexcept {
  for (std::size_t i = 0; i < loop.axis_count(); ++i) loop.abort(i);
}

// The session up to its outcome (run_session without the release). Every axis of the loop is
// the session's: enabled before anything is submitted, supervised until the end.
template <typename Loop, typename Clock, typename Observer>
SessionResult stream_moves(Loop& loop, Clock& clock, const core::Move<double>* moves, std::size_t move_count,
                           const SessionConfig& cfg, Observer& observe) noexcept {
  SessionResult r{};
  const std::size_t axes = loop.axis_count() < Loop::kMaxAxes ? loop.axis_count() : Loop::kMaxAxes;
  loop.start(clock.now_us());
  enum class Phase { enabling, streaming, settling } phase = Phase::enabling;
  std::uint64_t settle_left = cfg.settle_ticks;
  std::uint64_t aborted_before[Loop::kMaxAxes]{};
  for (r.ticks = 0; r.ticks < cfg.max_ticks; ++r.ticks) {
    r.missed_periods += clock.wait();
    loop.tick(clock.now_us());
    observe(r.ticks, phase != Phase::enabling);
    if (phase == Phase::enabling) {
      if (loop.all_ready()) {
        r.ready_tick = r.ticks;
        // All in this tick: the loop starts every queued move in the next, on the same SYNC.
        for (std::size_t k = 0; k < move_count && axes > 0; ++k) {
          const LoopStatus st = loop.submit(k % axes, moves[k]);
          if (st != LoopStatus::ok) {
            r.outcome = SessionOutcome::rejected;
            r.rejection = st;
            r.axis = k % axes;
            abort_all(loop);
            return r;
          }
        }
        for (std::size_t i = 0; i < axes; ++i) aborted_before[i] = loop.axis_stats(i).moves_aborted;
        phase = Phase::streaming;
        continue;
      }
      for (std::size_t i = 0; i < axes; ++i) {
        r.axis = i;
        if (loop.halted(i)) {  // a foreign SYNC, bus-off, ... before streaming began
          r.fault = loop.fault(i);
          r.outcome = session_outcome_for(r.fault);
          return r;
        }
        if (loop.drive(i).state() == hal::canopen::RemoteDriveState::failed) {
          r.outcome = SessionOutcome::enable_failed;
          return r;
        }
      }
      r.axis = 0;
      if (r.ticks >= cfg.enable_timeout_ticks) {
        while (r.axis + 1 < axes && loop.ready(r.axis)) ++r.axis;  // the first axis not ready
        r.outcome = SessionOutcome::enable_failed;
        return r;
      }
      continue;
    }
    // Streaming or settling: the loss of any drive ends the session (the loop has already
    // stopped streaming to it), and every other axis stops where it is.
    for (std::size_t i = 0; i < axes; ++i) {
      if (!loop.ready(i) || loop.axis_stats(i).moves_aborted != aborted_before[i]) {
        r.fault = loop.fault(i);
        r.outcome = session_outcome_for(r.fault);
        r.axis = i;
        abort_all(loop);
        return r;
      }
    }
    if (phase == Phase::streaming && loop.idle()) {
      r.stream_end_tick = r.ticks;
      phase = Phase::settling;
    }
    if (phase == Phase::settling && settle_left-- == 0) {
      r.outcome = SessionOutcome::completed;
      return r;
    }
  }
  r.outcome = SessionOutcome::timeout;
  return r;
}

}  // namespace detail

// A drive left operation enabled when the master goes quiet detects the silence (SYNC or RPDO
// loss), sends an EMCY and quick-stops: a fault report for a session that went well. So whatever
// the outcome, every drive the loop still streams to (ready: enabled, the axis not halted) is
// released (ServoLoop::release: Shutdown with the last setpoint held) and the session ticks, the
// observer called as before, until every one's statusword confirms it (ready to switch on) or one
// shows anything else, for at most cfg.release_ticks. The outcome is not changed.
template <typename Loop, typename Clock, typename Observer>
void release_drives(Loop& loop, Clock& clock, const SessionConfig& cfg, Observer& observe, SessionResult& r) noexcept {
  const std::size_t axes = loop.axis_count() < Loop::kMaxAxes ? loop.axis_count() : Loop::kMaxAxes;
  bool releasing[Loop::kMaxAxes]{};
  bool any = false;
  for (std::size_t i = 0; i < axes; ++i) {
    releasing[i] = loop.ready(i);
    if (releasing[i]) loop.release(i);
    any = any || releasing[i];
  }
  if (!any) return;
  for (std::uint64_t k = 1; k <= cfg.release_ticks; ++k) {
    r.missed_periods += clock.wait();
    loop.tick(clock.now_us());
    observe(r.ticks + k, true);
    r.release_ticks = k;
    bool waiting = false;
    for (std::size_t i = 0; i < axes; ++i) {
      if (!releasing[i]) continue;
      const hal::canopen::RemoteDriveState state = loop.drive(i).state();
      if (state == hal::canopen::RemoteDriveState::releasing) {
        waiting = true;
      } else if (state != hal::canopen::RemoteDriveState::released) {
        return;  // stopped, lost, ...: not released
      }
    }
    if (!waiting) {
      r.released = true;
      return;
    }
  }
}

// Streams moves[k] to axis k mod N, N the loop's axes: on one axis every move is queued after the
// one before; on N axes N moves are one per axis, submitted in the same tick so that every axis
// starts on the same SYNC. Every axis is supervised until the settling window ends: any axis lost,
// faulted or halted ends the session with that outcome (SessionResult::axis says which) and
// streaming on every axis stops.
// Clock: `std::uint64_t wait()` sleeps to the next period and returns periods missed;
// `std::uint64_t now_us()` the time of the period just begun.
// Observer: `void operator()(std::uint64_t tick, bool streaming)` (streaming: past enabling).
// Loop: ServoLoop's interface (kMaxAxes, axis_count, start, tick, all_ready, submit, ...).
template <typename Loop, typename Clock, typename Observer>
SessionResult run_session(Loop& loop, Clock& clock, const core::Move<double>* moves, std::size_t move_count,
                          const SessionConfig& cfg, Observer&& observe) noexcept {
  SessionResult r = detail::stream_moves(loop, clock, moves, move_count, cfg, observe);
  release_drives(loop, clock, cfg, observe, r);
  return r;
}

// The clock of deterministic runs (tests, the in-process loopback demo): time moves only when
// the session asks for the next period.
class VirtualClock {
 public:
  explicit VirtualClock(std::uint32_t period_us, std::uint64_t start_us = 0) noexcept
      : period_us_{period_us}, now_us_{start_us} {}
  std::uint64_t wait() noexcept {
    now_us_ += period_us_;
    return 0;
  }
  [[nodiscard]] std::uint64_t now_us() const noexcept { return now_us_; }

 private:
  std::uint32_t period_us_;
  std::uint64_t now_us_;
};

}  // namespace settle::runtime
