// SPDX-License-Identifier: Apache-2.0
#pragma once
// The periodic servo loop: each tick it takes the drives' feedback, evaluates every axis's active
// move, converts it to drive counts, sends one RPDO per axis and one SYNC, and keeps statistics.
// Generic over the evaluation scalar, the number of axes and the queue depth; time is given by
// the caller (the runner owns the clock), so the same loop runs under a Linux timer, a Cortex-M
// SysTick or a test's virtual clock. No heap, no exceptions, bounded work per tick.
//
// Fail-safe rules:
// - One period is one unit: every axis's RPDO, then the SYNC that applies them. The SYNC goes out
//   only if every RPDO of the tick did; if anything of the unit could not be sent (busy or error),
//   no SYNC goes out and the next tick resends the same setpoints: the moves' clock holds for that
//   period, so the drive applies every setpoint exactly once, in order, and never skips one.
//   LoopConfig::send_failure_periods such ticks in a row halt every axis (send_failed).
// - Feedback watchdog: AxisConfig::feedback_timeout_periods SYNCs in a row without a TPDO1 back
//   halt the axis (feedback_timeout).
// - A move is reported completed only when the drive's feedback shows it within one count of the
//   move's final setpoint; anything that takes the drive out of operation first voids it.
// - A SYNC the loop did not send (a second producer) halts every axis and the loop's SYNC.
// - Bus-off halts every axis; the loop asks the controller to restart (CanBus::restart) and, when
//   the bus is back, runs every drive's start-up again before anything is streamed.
// A halted axis is sent nothing (its drive's own RPDO/SYNC-loss supervision then stops it) until
// restart(axis) or, for bus-off, the bus's recovery. Everything that happens is in events().
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

#include "settle/core/axis_scale.hpp"
#include "settle/core/enum_text.hpp"
#include "settle/core/limits.hpp"
#include "settle/core/mode.hpp"
#include "settle/core/multi_axis.hpp"  // plan_path_online: a path's change, planned once
#include "settle/core/planner.hpp"
#include "settle/core/setpoints.hpp"
#include "settle/runtime/evaluation.hpp"
#include "settle/runtime/fixed_queue.hpp"
#include "settle/runtime/online_change.hpp"
#include "settle/runtime/setpoint_sequence.hpp"
#include "settle/hal/can_bus.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sync.hpp"

namespace settle::runtime {

// Each enum below is made from one list, in order: its enumerator, which is also its code
// (to_string), and the sentence describe() gives (core/enum_text.hpp).
#define SETTLE_LOOP_STATUSES(X) \
  X(ok, "accepted") \
  /* see the core::Status returned with it */ \
  X(plan_failed, "the planner refused the request") \
  X(queue_full, "the axis's move queue is full") \
  X(no_such_axis, "no axis has that index") \
  X(too_many_axes, "more axes than the loop holds") \
  X(exceeds_axis_velocity, "the move's true peak velocity is over the axis's vmax") \
  X(does_not_fit_counts, "the move would leave the int32 count range") \
  /* fixed point: see the core::Status */ \
  X(evaluation_refused, "the evaluator cannot hold the move") \
  X(bad_axis_config, "the axis configuration is invalid") \
  X(position_limit, "the move's path leaves the drive's software position limits (0x607D)") \
  X(exceeds_drive_velocity, "the move's peak velocity is over the drive's max profile velocity (0x607F)")
enum class LoopStatus : std::uint8_t { SETTLE_LOOP_STATUSES(SETTLE_ENUM_ENUMERATOR) };

[[nodiscard]] const char* to_string(LoopStatus s) noexcept;
[[nodiscard]] const char* describe(LoopStatus s) noexcept;

// Why the loop stopped a move or streaming to an axis.
#define SETTLE_AXIS_FAULTS(X) \
  X(none, "no fault") \
  X(heartbeat_lost, "the drive's heartbeat timed out") \
  X(drive_restarted, "boot-up: the drive was power-cycled or reset") \
  X(drive_left_enabled, "statusword: fault or quick stop") \
  X(drive_not_operational, "heartbeat: pre-operational or stopped (someone else's NMT command)") \
  X(start_up_failed, "configuration refused or timed out, or enabling timed out") \
  X(feedback_timeout, "feedback_timeout_periods SYNCs in a row without a TPDO1 back") \
  X(following_error, "the following error exceeded its limit") \
  X(step_guard, "a setpoint step over the axis's vmax x period + margin was refused") \
  X(not_in_position, "the feedback never showed the move's final setpoint (within one count)") \
  X(foreign_sync, "a SYNC the loop did not send: a second SYNC producer on the bus") \
  X(bus_off, "the controller went bus-off") \
  X(send_failed, "send_failure_periods ticks in a row the RPDO + SYNC unit did not go out")
enum class AxisFault : std::uint8_t { SETTLE_AXIS_FAULTS(SETTLE_ENUM_ENUMERATOR) };

[[nodiscard]] const char* to_string(AxisFault f) noexcept;
[[nodiscard]] const char* describe(AxisFault f) noexcept;

// What the loop did or saw, in order (drain events() as the feedback log).
#define SETTLE_LOOP_EVENT_KINDS(X) \
  X(drive_ready, "axis: operation enabled; streaming may begin") \
  X(move_started, "axis: a move started") \
  X(move_completed, "axis: the feedback showed the final setpoint within one count") \
  X(move_voided, "axis, fault: the move (active, finishing or queued) will never complete") \
  X(axis_stopped, "axis, fault: streaming to it stopped") \
  X(start_up_rerun, "axis: NMT, SDO configuration and enabling run again") \
  X(foreign_sync, "bus: a SYNC the loop did not send") \
  /* bus: the controller's state, as the bus reports it */ \
  X(bus_error_warning, "bus: error warning") \
  X(bus_error_passive, "bus: error passive") \
  X(bus_error_active, "bus: error active") \
  X(bus_off, "bus: bus-off") \
  X(bus_restart_requested, "bus: CanBus::restart() accepted") \
  X(bus_restart_refused, "bus: restart not supported (vcan) or failed; the loop waits for the bus")
enum class LoopEventKind : std::uint8_t { SETTLE_LOOP_EVENT_KINDS(SETTLE_ENUM_ENUMERATOR) };

[[nodiscard]] const char* to_string(LoopEventKind k) noexcept;
[[nodiscard]] const char* describe(LoopEventKind k) noexcept;

inline constexpr std::uint8_t kBusEvent = 0xFF;  // LoopEvent::axis of an event of the bus

struct LoopEvent {
  std::uint32_t tick{0};  // the tick it happened in (low 32 bits of LoopStats::ticks)
  LoopEventKind kind{LoopEventKind::drive_ready};
  std::uint8_t axis{kBusEvent};
  AxisFault fault{AxisFault::none};
};

inline constexpr std::size_t kEventLogCapacity = 16;

// Defaults of the supervision (documented in firmware/README.md).
inline constexpr std::uint16_t kDefaultFeedbackTimeoutPeriods = 10;
inline constexpr std::uint16_t kDefaultInPositionTimeoutPeriods = 2000;
inline constexpr std::uint16_t kDefaultSendFailurePeriods = 10;

struct LoopConfig {
  // Ticks in a row whose RPDO + SYNC unit could not be sent before every axis halts (send_failed).
  std::uint16_t send_failure_periods{kDefaultSendFailurePeriods};
};

// What the loop keeps of an axis's configuration (the drive's part lives in its RemoteDrive).
struct AxisLoopConfig {
  // Counts per unit (e.g. 1 count = 1 µm for the seed-000 beam) and the period, which must be the
  // loop's (add_axis refuses another: bad_axis_config).
  core::AxisScale scale{};
  double vmax{1.0};                      // actuator limit, units/s: moves above it are refused
  std::int32_t step_margin_counts{2};    // setpoint-step guard: vmax * period + this
  std::uint32_t following_error_counts{0};  // 0 = off
  // SYNCs in a row the drive may leave without a TPDO1 before the axis halts (feedback_timeout).
  // 0 switches the watchdog off (the drive's heartbeat is then the only supervision).
  std::uint16_t feedback_timeout_periods{kDefaultFeedbackTimeoutPeriods};
  // Periods after a move's final setpoint within which the feedback must show it (within one
  // count); otherwise the move is void (not_in_position). 0 = wait as long as it takes.
  std::uint16_t in_position_timeout_periods{kDefaultInPositionTimeoutPeriods};
};

struct AxisConfig : AxisLoopConfig {
  hal::canopen::RemoteDriveConfig drive{};
};

// What one axis did in the last tick: the runner copies it out to log or plot.
struct TickRecord {
  std::uint64_t tick{0};
  std::int32_t target{0};         // counts commanded this tick (held when not moving)
  bool sent{false};               // an RPDO carrying it and the SYNC applying it left this tick
  bool moving{false};
  bool move_end{false};           // this tick's RPDO carried a move's final setpoint
  std::int32_t position_actual{0};
  std::int32_t load_position{0};
  std::int32_t velocity_actual{0};
  std::uint64_t feedback_count{0};  // TPDO1s received so far
};

// One period's feedback as the drive published it (TPDO1 + TPDO2), kept in arrival order so that
// a late frame is never mistaken for another period's.
struct FeedbackSample {
  std::int32_t position_actual{0};
  std::int32_t load_position{0};
  std::int32_t velocity_actual{0};
};

struct AxisStats {
  std::uint64_t rpdo_sent{0};
  std::uint64_t rpdo_busy{0};
  std::uint64_t rpdo_errors{0};
  std::uint64_t moves_started{0};
  std::uint64_t moves_completed{0};
  std::uint64_t moves_aborted{0};
  std::uint64_t step_guard_trips{0};
  std::uint64_t following_error_trips{0};
  std::uint64_t heartbeat_losses{0};
  std::uint64_t emcy_received{0};
  std::uint64_t restarts{0};  // the drive booted again and start-up re-ran
  std::uint64_t feedback_timeouts{0};
  std::uint64_t not_in_position{0};
  std::uint32_t max_following_error{0};  // counts, the shorter way round the int32 wrap
  std::uint64_t feedback_overflows{0};  // samples dropped because feedback_log() was not drained
};

// Feedback samples kept per axis until the owner drains them (every tick): one arrives per
// period, so this is 16 periods of slack; 12 bytes each, per axis, on a microcontroller. The
// loop's FeedbackCapacity parameter; a master on a host that can stall asks for more.
inline constexpr std::size_t kFeedbackLogCapacity = 16;

struct LoopStats {
  std::uint64_t ticks{0};
  std::uint64_t sync_sent{0};
  std::uint64_t sync_busy{0};    // SYNC sends that failed (busy or error)
  std::uint64_t frames_received{0};
  std::uint64_t units_held{0};   // ticks whose RPDO + SYNC unit did not go out: the moves' clock held
  std::uint64_t foreign_syncs{0};  // SYNC frames received (the loop never hears its own)
  std::uint64_t bus_offs{0};
  std::uint64_t events_dropped{0};  // events() was full
};

// Bus: hal::CanBus (any backend, through its virtual hooks) or a backend's own type such as
// hal::MailboxBus, whose send and receive are then direct calls the compiler inlines: what
// firmware that knows its controller does (firmware/README.md: what the Cortex-M0 tick costs).
//
// Online: whether the loop offers halt()/retarget() (docs/online.md). They need the
// planned Move<double> of every queued move (its state and mode memory at the switch; its modes'
// memory at its end is taken at submit, OnlineQueued) and two blend slots (the plan in double and
// in the evaluation's scalar): about 3.7 KB per queued move on x86-64 (OnlineQueued: 3 696 bytes,
// 608 of them its end memory's piece sums) and
// 2.9 KiB (float) or 5.3 KiB (fixed) per axis, and service() builds a fixed-point blend's 4.2 KiB
// Motion on its stack. On by default for the double evaluation (a master on Linux), asked for by the
// others; never where SETTLE_ONLINE_CHANGES is 0 (the Cortex-M0).
//
// FeedbackCapacity: feedback samples kept per axis between two drains (kFeedbackLogCapacity).
template <typename Scalar = double, std::size_t MaxAxes = 1, std::size_t QueueDepth = 4,
          typename Evaluation = FloatEvaluation<Scalar>, typename Bus = hal::CanBus,
          bool Online = kOnlineChangesAvailable && std::is_same_v<Evaluation, FloatEvaluation<double>>,
          std::size_t FeedbackCapacity = kFeedbackLogCapacity>
class ServoLoop {
  static_assert(std::is_base_of_v<hal::CanBus, Bus>, "Bus is hal::CanBus or one of its backends");
  static_assert(!Online || kOnlineChangesAvailable, "online changes are switched off (SETTLE_ONLINE_CHANGES=0)");

 public:
  // Without online changes halt()/retarget() return false and nothing is stored for them.
  static constexpr bool kOnlineChanges = Online;
  static constexpr std::size_t kMaxAxes = MaxAxes;
  using EvaluationType = Evaluation;

  ServoLoop(Bus& bus, std::uint32_t period_us, const LoopConfig& config = {}) noexcept
      : bus_{bus}, period_us_{period_us}, config_{config}, sync_{period_us} {}
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  // add_axis and submit run outside the tick; cold: built for size (a Cortex-M image's flash).
  [[nodiscard, gnu::cold]] LoopStatus add_axis(const AxisConfig& cfg) noexcept {
    if (count_ == MaxAxes) return LoopStatus::too_many_axes;
    if (!cfg.scale.valid() || cfg.scale.period_us != period_us_ || !(cfg.vmax > 0.0) ||
        !std::isfinite(cfg.vmax) || cfg.step_margin_counts < 0) {
      return LoopStatus::bad_axis_config;
    }
    const std::uint8_t node = cfg.drive.node;
    if (node == 0 || node > 127 || axis_of_node_[node] != kNoAxis) return LoopStatus::bad_axis_config;
    Axis& a = axes_[count_];
    axis_of_node_[node] = static_cast<std::uint8_t>(count_);
    a.cfg = static_cast<const AxisLoopConfig&>(cfg);  // the drive's part is kept by its RemoteDrive
    hal::canopen::RemoteDriveConfig drive = cfg.drive;
    drive.sync_period_us = period_us_;
    a.drive.emplace(drive);
    // In whole counts, once: the tick compares integers. At or past 2^31 no step can exceed it.
    const double guard = std::floor(cfg.vmax * cfg.scale.counts_per_unit * cfg.scale.period_s()) + cfg.step_margin_counts;
    a.guard = guard < 2147483648.0 ? static_cast<std::uint32_t>(guard) : std::uint32_t{1} << 31U;
    if constexpr (kOnlineChanges) a.online.period_s = cfg.scale.period_s();
    ++count_;
    return LoopStatus::ok;
  }

  // Starts every drive (NMT, SDO configuration, enable sequence); tick() must run from now on.
  void start(std::uint64_t now_us) noexcept {
    for (std::size_t i = 0; i < count_; ++i) axes_[i].drive->start(now_us, bus_);
    sync_blocked_ &= static_cast<std::uint8_t>(~kSyncNotStarted);
  }

  // After a halt (feedback timeout, foreign SYNC, send failures, a drive someone else took out of
  // operation): the application has decided to go on. Runs the drive's start-up again; streaming
  // resumes once it is enabled, with new moves only. Clears the loop's own SYNC halt.
  void restart(std::size_t axis, std::uint64_t now_us) noexcept {
    if (axis >= MaxAxes || axis >= count_) return;
    Axis& a = axes_[axis];
    sync_blocked_ &= static_cast<std::uint8_t>(~kSyncForeign);
    if (bus_state_ == hal::BusState::bus_off) return;  // the bus's recovery restarts it
    a.halt = AxisFault::none;
    a.have_target = false;
    a.unanswered = 0;
    a.drive->start(now_us, bus_);
    note(LoopEventKind::start_up_rerun, static_cast<std::uint8_t>(axis), AxisFault::none);
  }

  // Plans a request and queues it. Runs in the caller's context, never inside tick(): planning
  // a shaped move can take a millisecond. On any refusal nothing changes.
  [[nodiscard]] LoopStatus submit(std::size_t axis, const core::MoveRequest& req,
                                  core::Status* plan_status = nullptr) noexcept {
    core::Move<double> m{};
    const core::Status st = core::plan(req, m);
    if (plan_status != nullptr) *plan_status = st;
    if (st != core::Status::ok) return LoopStatus::plan_failed;
    return submit(axis, m);
  }

  [[nodiscard, gnu::cold]] LoopStatus submit(std::size_t axis, const core::Move<double>& m,
                                            core::Status* why = nullptr) noexcept {
    if (axis >= MaxAxes || axis >= count_) return LoopStatus::no_such_axis;
    Axis& a = axes_[axis];
    // A velocity step (seed 001's command) is streamable: sampled, it is a jump of at most
    // peak |v| * period, which the step guard allows whenever peak |v| is within vmax.
    if (!(m.peaks().v <= a.cfg.vmax * (1.0 + core::kLimitSlack))) return LoopStatus::exceeds_axis_velocity;
    const double cpu = a.cfg.scale.counts_per_unit;
    const double counts = std::fabs(m.distance()) * cpu;
    if (!(counts < static_cast<double>(std::numeric_limits<std::int32_t>::max()) / 2)) {
      return LoopStatus::does_not_fit_counts;
    }
    if (a.queue.full()) return LoopStatus::queue_full;
    // Prepared in place in the queue's free slot, which joins the queue only on success: a
    // refusal leaves the queue as it was, and no second copy of a move is ever held.
    const core::Status st = Evaluation::prepare(m, a.cfg.scale, a.queue.back_slot().eval);
    if (why != nullptr) *why = st;
    if (st != core::Status::ok) return LoopStatus::evaluation_refused;
    // What the drive said at start-up (nothing before it ran, or when it has neither object).
    const hal::canopen::RemoteDriveLimits& limits = a.drive->limits();
    if (limits.max_profile_velocity != 0 &&
        !(m.peaks().v * cpu <= static_cast<double>(limits.max_profile_velocity) * (1.0 + core::kLimitSlack))) {
      return LoopStatus::exceeds_drive_velocity;
    }
    const std::int32_t origin = move_origin(a);
    if (limits.has_position_limits() &&
        !path_within(Evaluation::sampled_move(a.queue.back_slot().eval, m), origin, cpu, limits)) {
      return LoopStatus::position_limit;
    }
    if constexpr (kOnlineChanges) {
      OnlineQueued& q = a.queue.back_slot().online;
      q.move = m;
      q.config = 0;  // the slot's previous move's
      if (a.online.configured) (void)take_end_memory(a, q);  // cannot fail: configure_online checked the modes
    }
    a.queue.commit_back();
    a.queued_end = static_cast<std::int32_t>(static_cast<std::int64_t>(origin) + core::round_half_away(m.distance() * cpu));
    return LoopStatus::ok;
  }

  // The modes and limits an axis's halts and retargets respect (outside the tick). Refused:
  // evaluation_refused without kOnlineChanges, bad_axis_config for a mode or limit out of range,
  // exceeds_axis_velocity for a vmax over the axis's (AxisConfig::vmax): every blend is planned
  // within these limits, so every step it makes is one the step guard admits.
  [[nodiscard]] LoopStatus configure_online(std::size_t axis, const OnlineConfig& c) noexcept {
    if constexpr (!kOnlineChanges) {
      (void)axis;
      (void)c;
      return LoopStatus::evaluation_refused;
    } else {
      if (axis >= MaxAxes || axis >= count_) return LoopStatus::no_such_axis;
      const core::OnlineLimits& l = c.limits;
      bool ok = c.mode_count <= core::kMaxOnlineModes && c.lead_ticks >= 1 && std::isfinite(l.vmax) && std::isfinite(l.amax) &&
                std::isfinite(l.jmax) && l.vmax > 0.0 && l.amax > 0.0 && l.jmax > 0.0;
      for (std::size_t i = 0; ok && i < c.mode_count; ++i) {
        ok = core::mode_status(c.modes[i]) == core::Status::ok;
      }
      if (!ok) return LoopStatus::bad_axis_config;
      // The same tolerance as submit()'s: a blend at exactly the axis's vmax is streamable.
      if (!(l.vmax <= axes_[axis].cfg.vmax * (1.0 + core::kLimitSlack))) return LoopStatus::exceeds_axis_velocity;
      axes_[axis].online.config = c;
      axes_[axis].online.configured = true;
      ++axes_[axis].online.config_serial;  // the queued moves' end memories are for the configuration before
      return LoopStatus::ok;
    }
  }

  // From any context, lock-free (a single producer per axis): ask for the running move to stop as
  // fast as the axis's online limits allow, leaving its modes at rest. False when the axis has no
  // online configuration or four commands are already waiting for service().
  [[nodiscard]] bool halt(std::size_t axis) noexcept { return post_online(axis, {OnlineKind::halt, 0.0}); }
  // The same, to end at rest at `distance` from the running move's start (move units).
  [[nodiscard]] bool retarget(std::size_t axis, double distance) noexcept {
    return std::isfinite(distance) && post_online(axis, {OnlineKind::retarget, distance});
  }

  // Outside the tick, where submit() runs: plans what halt()/retarget() asked for, at most one
  // command per axis per call, for a switch lead_ticks (OnlineConfig) setpoints ahead of the running move,
  // and converts the blend to the evaluation's scalar; the tick switches to it at exactly that
  // setpoint. While a blend runs, the command changes the blend (a halt after a retarget): planned
  // from the blend's state and its own mode memory, streamed from the other slot. A command with
  // no running move (or while a blend waits for its switch) is dropped and counted in
  // online_missed(). Returns plan_failed if a blend could not be planned,
  // evaluation_refused if the evaluation cannot hold it (why: the core::Status),
  // exceeds_drive_velocity if it would step faster than the drive's 0x607F; the move then runs on
  // unchanged.
  [[nodiscard]] LoopStatus service(core::Status* why = nullptr) noexcept {
    LoopStatus result = LoopStatus::ok;
    if constexpr (kOnlineChanges) {
      if constexpr (MaxAxes > 1) service_path(why, result);
      for (std::size_t i = 0; i < count_; ++i) {
        Axis& a = axes_[i];
        auto& o = a.online;
        OnlineCommand c{};
        if (o.ready.load(std::memory_order_acquire) != 0 || !o.mailbox.take(c)) continue;
        if (!a.active) {
          o.missed.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
        const ChangeAt at = change_at(a);
        core::Status st = change_request(a, c, at);
        core::OnlinePlan plan{};
        if (st == core::Status::ok) st = core::plan_online(o.request[at.slot], plan);
        if (st != core::Status::ok) {
          if (why != nullptr) *why = st;
          result = LoopStatus::plan_failed;
          continue;
        }
        hand_over(a, at, plan, why, result);
      }
    }
    return result;
  }
  // Blends the tick switched to, and commands or blends that came too late (see service()).
  [[nodiscard]] std::uint32_t online_switches(std::size_t axis) const noexcept {
    if constexpr (kOnlineChanges) return axes_[axis].online.switches.load(std::memory_order_relaxed);
    return 0;
  }
  // Halts that let the running move (or blend) finish, at rest on its target sooner than any blend
  // could stop short of it (core::OnlineChoice::finish); the moves queued behind it are voided.
  [[nodiscard]] std::uint32_t online_finishes(std::size_t axis) const noexcept {
    if constexpr (kOnlineChanges) return axes_[axis].online.finishes.load(std::memory_order_relaxed);
    return 0;
  }
  [[nodiscard]] std::uint32_t online_missed(std::size_t axis) const noexcept {
    if constexpr (kOnlineChanges) return axes_[axis].online.missed.load(std::memory_order_relaxed);
    return 0;
  }

  // One servo period. Bounded: drains at most kMaxFramesPerTick received frames.
  void tick(std::uint64_t now_us) noexcept {
    ++stats_.ticks;
    receive_all(now_us);
    if (bus_.bus_state() != bus_state_) on_bus_state(now_us);
    if (foreign_sync_seen_) on_foreign_sync();
    for (std::size_t i = 0; i < count_; ++i) supervise(axes_[i], now_us);
    bool unit_ok = true;
    for (std::size_t i = 0; i < count_; ++i) unit_ok = stream(axes_[i]) && unit_ok;
    bool sync_sent = false;
    if (sync_blocked_ == 0) {
      // The SYNC applies this tick's RPDOs: it goes out only with all of them.
      if (unit_ok) {
        if (!sync_unsent_) sync_frame_ = &sync_.next();
        if (bus_.send(*sync_frame_) == hal::SendStatus::sent) {
          ++stats_.sync_sent;
          sync_sent = true;
        } else {
          ++stats_.sync_busy;
        }
        sync_unsent_ = !sync_sent;
      }
      if (sync_sent) {
        unsent_run_ = 0;
      } else {
        ++stats_.units_held;
        if (unsent_run_ < 0xFFFF) ++unsent_run_;
        if (unsent_run_ >= config_.send_failure_periods) halt_all(AxisFault::send_failed);
      }
    }
    // stream() applied each sent RPDO's setpoint as if its SYNC would follow; it did not.
    if (!sync_sent) {
      for (std::size_t i = 0; i < count_; ++i) take_back(axes_[i]);
    }
  }

  // One received frame: routed to its axis's drive, its feedback logged. tick() calls it for every
  // frame it drains; a caller that reads the bus itself (after the session, say) calls it too.
  void receive(const hal::CanFrame& f, std::uint64_t now_us) noexcept {
    ++stats_.frames_received;
    if (!route_process(f, now_us)) route_other(f, now_us);
  }

  // Stops streaming on an axis: the active move and the queue are dropped, the axis holds.
  void abort(std::size_t axis) noexcept {
    if (axis >= MaxAxes || axis >= count_) return;
    abandon(axes_[axis], AxisFault::none);
  }

  // Ends streaming on an axis (as abort) and asks its drive to leave operation enabled before the
  // master goes quiet (RemoteDrive::release: Shutdown, the last setpoint held); ready() is false
  // from now on, and a drive enabled again later starts from where it is.
  void release(std::size_t axis) noexcept {
    if (axis >= MaxAxes || axis >= count_) return;
    abandon(axes_[axis], AxisFault::none);
    axes_[axis].have_target = false;
    axes_[axis].drive->release();
  }

  [[nodiscard]] std::size_t axis_count() const noexcept { return count_; }
  [[nodiscard]] const hal::canopen::RemoteDrive& drive(std::size_t i) const noexcept { return *axes_[i].drive; }
  [[nodiscard]] const TickRecord& record(std::size_t i) const noexcept { return axes_[i].record; }
  [[nodiscard]] const AxisStats& axis_stats(std::size_t i) const noexcept { return axes_[i].stats; }
  // Feedback samples in arrival order (one per SYNC the drive processed); drain every tick.
  [[nodiscard]] FixedQueue<FeedbackSample, FeedbackCapacity>& feedback_log(std::size_t i) noexcept {
    return axes_[i].feedback_log;
  }
  [[nodiscard]] const LoopStats& stats() const noexcept { return stats_; }
  // What happened, in order; the owner drains it (a full log counts LoopStats::events_dropped).
  [[nodiscard]] FixedQueue<LoopEvent, kEventLogCapacity>& events() noexcept { return events_; }
  // Streaming may go on: the drive is operation enabled and the loop has not halted the axis.
  [[nodiscard]] bool ready(std::size_t i) const noexcept { return axes_[i].halt == AxisFault::none && axes_[i].drive->ready(); }
  [[nodiscard]] bool all_ready() const noexcept {
    for (std::size_t i = 0; i < count_; ++i) {
      if (!ready(i)) return false;
    }
    return count_ > 0;
  }
  // Why the axis last stopped (none: it never did since add_axis).
  [[nodiscard]] AxisFault fault(std::size_t i) const noexcept { return axes_[i].fault; }
  // The loop sends nothing to this axis until restart(i) (or the bus's recovery, for bus_off).
  [[nodiscard]] bool halted(std::size_t i) const noexcept { return axes_[i].halt != AxisFault::none; }
  [[nodiscard]] hal::BusState bus_state() const noexcept { return bus_state_; }
  // Nothing active, nothing waiting for its feedback to show it done and nothing queued on any axis.
  [[nodiscard]] bool idle() const noexcept {
    for (std::size_t i = 0; i < count_; ++i) {
      if (axes_[i].active || axes_[i].finishing || !axes_[i].queue.empty()) return false;
    }
    return true;
  }
  [[nodiscard]] std::uint32_t period_us() const noexcept { return period_us_; }

  static constexpr std::size_t kMaxFramesPerTick = 16 * MaxAxes + 16;
  // The bus lets the loop read its received records in place (receive_all).
  static constexpr bool kReceivesInPlace = requires(Bus& b, std::size_t i, hal::CanFrame& f) {
    b.received(i);
    b.received_frame(i, f);
    b.consume_received(i);
  };

 private:
  // A queued move: prepared for the evaluation, and as planned where online changes need it.
  struct Queued {
    typename Evaluation::Stored eval{};
    [[no_unique_address]] std::conditional_t<kOnlineChanges, OnlineQueued, NoOnline> online{};
  };

  // What every tick touches comes first: a Cortex-M0 reaches only the first 32 bytes of a struct
  // with one byte load and the first 128 with one word load; the queue's prepared moves are large.
  struct Axis {
    bool active{false};
    bool have_target{false};
    bool sent_prev_valid{false};
    bool end_pending{false};      // the final setpoint of a move is in the unit not yet applied
    bool finishing{false};        // a move's final setpoint was applied: waiting for the feedback
    AxisFault halt{AxisFault::none};   // not none: the loop sends this axis nothing
    AxisFault fault{AxisFault::none};  // why it last stopped
    std::uint32_t unanswered{0};  // SYNCs sent while ready since the last TPDO1
    std::uint16_t finish_wait{0}; // periods spent finishing
    std::int32_t target{0};       // last target commanded (applied by a SYNC)
    std::int32_t sent_prev{0};    // target sent in the previous tick (what the feedback answers)
    std::int32_t final_target{0}; // while finishing: where the feedback must show the drive
    std::uint32_t guard{0};       // largest setpoint step allowed per tick, counts (2^31: any)
    std::optional<std::int32_t> pending{};  // computed, not yet applied (unit not sent): resent first
    std::uint64_t fb_seen{0};
    SetpointStepper<Evaluation, kOnlineChanges> sequence{};  // the setpoints of the active move and its changes
    TickRecord record{};
    AxisStats stats{};
    FixedQueue<FeedbackSample, FeedbackCapacity> feedback_log{};
    std::optional<hal::canopen::RemoteDrive> drive{};
    std::int32_t queued_end{0};   // where the last move queued (or running) ends, counts
    AxisLoopConfig cfg{};
    FixedQueue<Queued, QueueDepth> queue{};
    [[no_unique_address]] std::conditional_t<kOnlineChanges, OnlineSlot<Evaluation>, NoOnline> online{};
  };

  // Where service() plans a change of axis `a` (online changes only): on the running blend (the
  // tick's stepper and streaming slot: service() runs between ticks) into the other slot, else on
  // the move; for the switch lead_ticks setpoints ahead.
  struct ChangeAt {
    bool on_blend{false};
    std::uint8_t slot{0};
    std::uint32_t serial{0};
    std::int32_t index{0};
  };
  ChangeAt change_at(const Axis& a) const noexcept {
    const auto& o = a.online;
    ChangeAt at{};
    at.on_blend = a.sequence.on_blend();
    at.slot = at.on_blend ? static_cast<std::uint8_t>(1U - o.streaming) : std::uint8_t{0};
    at.serial = at.on_blend ? o.switches.load(std::memory_order_relaxed) : o.move_serial.load(std::memory_order_acquire);
    at.index = a.sequence.index() + o.config.lead_ticks;
    return at;
  }
  // A queued move's end memory for the axis's online configuration, unless it has it already.
  static core::Status take_end_memory(const Axis& a, OnlineQueued& q) noexcept {
    const auto& o = a.online;
    if (q.config != 0 && q.config == o.config_serial) return core::Status::ok;
    const core::Status st = core::end_memory(q.move, o.config.modes.data(), o.config.mode_count, q.end);
    if (st == core::Status::ok) q.config = o.config_serial;
    return st;
  }
  // The change's request, into o.request[at.slot].
  core::Status change_request(Axis& a, const OnlineCommand& c, const ChangeAt& at) noexcept {
    auto& o = a.online;
    const std::optional<double> target =
        c.kind == OnlineKind::retarget ? std::optional<double>{c.target} : std::nullopt;
    const double t = static_cast<double>(at.index) * o.period_s;
    if (at.on_blend) return core::online_request(o.blend[o.streaming], o.request[o.streaming], t, target, o.request[at.slot]);
    OnlineQueued& q = a.queue.front().online;
    const core::Status st = take_end_memory(a, q);
    if (st != core::Status::ok) return st;
    return core::online_request(q.move, q.end, t, o.config.modes.data(), o.config.mode_count, o.config.limits, target,
                                o.request[at.slot]);
  }
  // Checks, prepares and hands a planned change to the tick (one `ready` store), or says in
  // `result` (and `why`) why the move runs on unchanged.
  void hand_over(Axis& a, const ChangeAt& at, const core::OnlinePlan& plan, core::Status* why,
                 LoopStatus& result) noexcept {
    auto& o = a.online;
    // The drive's own velocity limit (0x607F, as it said at start-up) holds for a blend as for
    // a move: a blend over it would fault the drive at its first such step.
    const std::uint32_t drive_vmax = a.drive->limits().max_profile_velocity;
    if (plan.choice != core::OnlineChoice::finish && drive_vmax != 0 &&
        !(plan.blend.peaks().v * a.cfg.scale.counts_per_unit <= static_cast<double>(drive_vmax) * (1.0 + core::kLimitSlack))) {
      result = LoopStatus::exceeds_drive_velocity;
      return;
    }
    // A halt whose best is to finish what runs (docs/online.md): nothing to prepare.
    o.finish = plan.choice == core::OnlineChoice::finish;
    core::Status st = core::Status::ok;
    if (!o.finish) o.blend[at.slot] = plan.blend;
    if (!o.finish) st = Evaluation::prepare(o.blend[at.slot], a.cfg.scale, o.evaluated[at.slot]);
    if (st != core::Status::ok) {
      if (why != nullptr) *why = st;
      result = LoopStatus::evaluation_refused;
      return;
    }
    o.slot = at.slot;
    o.from_blend = at.on_blend;
    o.switch_index = at.index;
    o.blend_serial = at.serial;
    o.ready.store(1, std::memory_order_release);
  }
  // Path axes (OnlineConfig::path, a moving command each) whose commands all wait, each for the
  // same setpoint index: a halt, or a retarget on the line, is planned once for all of them
  // (core::plan_path_online: the first one's blend, scaled to each axis's distance, the same
  // segment length on every axis) and every axis switches at that index. Anything else (a path
  // axis without a command yet, a retarget off the line, different indices) is left to each axis's
  // own planning in service(). Host loops only (MaxAxes > 1): MaxAxes plans on the stack.
  void service_path(core::Status* why, LoopStatus& result) noexcept {
    std::array<const core::OnlineRequest*, MaxAxes> req{};
    std::array<double, MaxAxes> distance{};
    std::array<ChangeAt, MaxAxes> at{};
    std::size_t members = 0;
    std::int32_t index = 0;
    for (std::size_t i = 0; i < count_; ++i) {
      Axis& a = axes_[i];
      auto& o = a.online;
      if (!o.configured || !o.config.path || (a.active && a.queue.front().online.move.distance() == 0.0)) continue;
      OnlineCommand c{};
      if (o.ready.load(std::memory_order_acquire) != 0 || !a.active || !o.mailbox.peek(c)) return;
      at[i] = change_at(a);
      if (members == 0) index = at[i].index;
      if (at[i].index != index || change_request(a, c, at[i]) != core::Status::ok) return;
      req[i] = &o.request[at[i].slot];
      distance[i] = a.queue.front().online.move.distance();
      ++members;
    }
    if (members < 2 || !core::path_change(req.data(), distance.data(), count_)) return;
    std::array<core::OnlinePlan, MaxAxes> plans{};
    std::size_t ref = MaxAxes;
    const core::Status st = core::plan_path_online(req.data(), distance.data(), count_, plans.data(), ref);
    for (std::size_t i = 0; i < count_; ++i) {
      OnlineCommand c{};
      if (req[i] == nullptr || !axes_[i].online.mailbox.take(c)) continue;
      if (st == core::Status::ok) hand_over(axes_[i], at[i], plans[i], why, result);
    }
    if (st != core::Status::ok) {
      if (why != nullptr) *why = st;
      result = LoopStatus::plan_failed;
    }
  }

  [[nodiscard]] bool post_online(std::size_t axis, const OnlineCommand& c) noexcept {
    if constexpr (!kOnlineChanges) {
      (void)axis;
      (void)c;
      return false;
    } else {
      if (axis >= MaxAxes || axis >= count_ || !axes_[axis].online.configured) return false;
      return axes_[axis].online.mailbox.post(c);
    }
  }

  // The active move's next setpoint, or its change's (setpoint_sequence.hpp: the one stepper that
  // stream_setpoints drives too) once the pending change is due.
  [[nodiscard]] std::int32_t next_setpoint(Axis& a, bool& last) noexcept {
    if constexpr (kOnlineChanges) {
      auto& o = a.online;
      if (o.ready.load(std::memory_order_acquire) != 0) {
        // Valid while what it was planned on still runs: the same move, or the same blend.
        const bool on_blend = a.sequence.on_blend();
        const bool valid = o.from_blend ? on_blend && o.blend_serial == o.switches.load(std::memory_order_relaxed)
                                        : !on_blend && o.blend_serial == o.move_serial.load(std::memory_order_relaxed);
        const SwitchPoint p =
            valid ? a.sequence.offer(o.switch_index, o.finish ? nullptr : &o.evaluated[o.slot]) : SwitchPoint::passed;
        if (p == SwitchPoint::passed) {
          o.missed.fetch_add(1, std::memory_order_relaxed);  // planned for what has ended or passed
          o.ready.store(0, std::memory_order_release);
        } else if (p == SwitchPoint::due && o.finish) {
          o.halting = true;  // what runs is the halt: it goes on, and nothing queued follows it
          o.finishes.fetch_add(1, std::memory_order_relaxed);
          o.ready.store(0, std::memory_order_release);
        } else if (p == SwitchPoint::due) {
          o.streaming = o.slot;
          o.switches.fetch_add(1, std::memory_order_relaxed);
          o.ready.store(0, std::memory_order_release);
        }
      }
    }
    return a.sequence.next(last);
  }

  // The active move's final setpoint (its own, or its blend's) is applied.
  void finish_active(Axis& a) noexcept {
    if constexpr (kOnlineChanges) {
      auto& o = a.online;
      if (o.ready.load(std::memory_order_acquire) != 0) {
        o.ready.store(0, std::memory_order_release);  // planned for a switch the move never reached
        o.missed.fetch_add(1, std::memory_order_relaxed);
      }
      if (a.sequence.on_blend() || o.halting) {
        // Moves queued behind a halted or retargeted one were planned from its old end: void.
        a.sequence.end();
        o.halting = false;
        if (a.queue.size() > 1) note(LoopEventKind::move_voided, index_of(a), AxisFault::none);
        a.queue.clear();
        return;
      }
    }
    a.queue.drop_front();
  }

  // |a - b| in counts on the wrapping int32 scale every position lives on (streams wrap modulo
  // 2^32, as drives' position counters do): the shorter way round, at most 2^31. A move that
  // crosses the wrap steps by its true step, and every operation is a 32-bit one.
  [[nodiscard]] static std::uint32_t distance_counts(std::int32_t a, std::int32_t b) noexcept {
    const std::uint32_t d = static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b);
    return d <= 0x8000'0000U ? d : 0U - d;
  }

  // Where a move submitted now starts: the end of the moves before it, or where the axis holds.
  [[nodiscard]] static std::int32_t move_origin(const Axis& a) noexcept {
    if (a.active || !a.queue.empty()) return a.queued_end;
    return a.have_target ? a.target : a.drive->feedback().position_actual;
  }
  // The move's path from `origin` stays within the drive's software position limits: its ends
  // and 256 samples between them (a shaper with negative impulses overshoots the end), each as
  // the setpoint the stream sends (to_counts: rounded to a count). The move sampled is the one
  // the evaluation holds (Evaluation::sampled_move): in float on a Cortex-M4F, where evaluating
  // the Move<double> would link soft-double sin, cos and pow into the image (12 KiB of flash).
  template <typename S>
  [[nodiscard]] static bool path_within(const core::Move<S>& m, std::int32_t origin, double cpu,
                                        const hal::canopen::RemoteDriveLimits& limits) noexcept {
    constexpr int samples = 256;
    const S scale = static_cast<S>(cpu);
    for (int k = 0; k <= samples; ++k) {
      const S p = k == samples ? m.distance() : m.at(m.duration() * static_cast<S>(k) / static_cast<S>(samples)).p;
      const double at = static_cast<double>(origin) + static_cast<double>(std::nearbyint(p * scale));
      if (!(at >= static_cast<double>(limits.position_min) && at <= static_cast<double>(limits.position_max))) {
        return false;
      }
    }
    return true;
  }

  [[nodiscard]] std::uint8_t index_of(const Axis& a) const noexcept {
    return static_cast<std::uint8_t>(&a - axes_.data());
  }

  void note(LoopEventKind kind, std::uint8_t axis, AxisFault fault) noexcept {
    if (!events_.push(LoopEvent{static_cast<std::uint32_t>(stats_.ticks), kind, axis, fault})) ++stats_.events_dropped;
  }

  // Drops the active move, the one waiting for its feedback and everything queued (a move in
  // flight is counted as aborted: it never completes); the axis holds. `why` (none: the
  // application's abort) goes to the event log.
  void abandon(Axis& a, AxisFault why) noexcept {
    const bool in_flight = a.active || a.finishing;
    if (in_flight || !a.queue.empty()) note(LoopEventKind::move_voided, index_of(a), why);
    if (in_flight) ++a.stats.moves_aborted;
    a.active = false;
    a.finishing = false;
    a.pending.reset();
    a.end_pending = false;
    a.queue.clear();
    if constexpr (kOnlineChanges) {
      a.sequence.end();
      a.online.halting = false;
      a.online.ready.store(0, std::memory_order_release);
    }
  }

  // Streaming to the axis stopped for `why`: every move is void. A halted axis keeps the reason it
  // was halted for (what the drive does next, starved of setpoints, is a consequence).
  void stopped(Axis& a, AxisFault why) noexcept {
    if (a.halt == AxisFault::none || a.halt == why) {
      a.fault = why;
      note(LoopEventKind::axis_stopped, index_of(a), why);
    }
    abandon(a, why);
  }

  // The loop stops sending to the axis until restart() (or the bus's recovery).
  void halt(Axis& a, AxisFault why) noexcept {
    if (a.halt != AxisFault::none) return;
    a.halt = why;
    a.have_target = false;
    a.sent_prev_valid = false;
    stopped(a, why);
  }

  void halt_all(AxisFault why) noexcept {
    for (std::size_t i = 0; i < count_; ++i) halt(axes_[i], why);
  }

  void receive_all(std::uint64_t now_us) noexcept {
    if constexpr (kReceivesInPlace) {
      // A controller whose received records can be read where they are (hal::MailboxBus): the
      // drives' process data and heartbeats are taken from the record, and only other frames are
      // copied out; the frames are dropped and counted once for the tick, not one by one.
      std::size_t n = bus_.pending_rx();
      if (n > kMaxFramesPerTick) n = kMaxFramesPerTick;
      for (std::size_t i = 0; i < n; ++i) {
        if (route_process(bus_.received(i), now_us)) continue;
        bus_.received_frame(i, rx_);
        route_other(rx_, now_us);
      }
      bus_.consume_received(n);
      stats_.frames_received += n;
    } else {
      for (std::size_t n = 0; n < kMaxFramesPerTick; ++n) {
        if (bus_.receive(rx_, 0) != hal::ReceiveStatus::received) break;
        receive(rx_, now_us);
      }
    }
  }

  // CANopen puts the sending node in the low 7 bits of every node-specific COB-ID (TPDO, SDO,
  // EMCY, heartbeat): route there, so a tick costs O(axes), not O(axes^2). Node 0 (NMT, SYNC,
  // time) and extended ids go to every axis (route_other).
  // route_process takes a node-specific frame inline, where it lies (a CanFrame or a controller's
  // record): another node's is dropped, an axis's process data or heartbeat decoded; false for
  // every other frame, which route_other then takes.
  template <typename Frame>
  [[nodiscard]] bool route_process(const Frame& f, std::uint64_t now_us) noexcept {
    const std::uint32_t node = f.id & 0x7F;
    if (f.is_extended() || node == 0) return false;
    const std::uint8_t target = axis_of_node_[node];
    if (target == kNoAxis) return true;
    Axis& a = axes_[target];
    auto what = hal::canopen::RemoteFrame::ignored;
    if (!a.drive->on_process_frame(f, now_us, bus_, what)) return false;
    if (what == hal::canopen::RemoteFrame::tpdo2) log_feedback(a);
    return true;
  }
  // An axis's service frames and other TPDO layouts, and the frames for every axis.
  void route_other(const hal::CanFrame& f, std::uint64_t now_us) noexcept {
    const std::uint32_t node = f.id & 0x7F;
    if (!f.is_extended() && node != 0) {
      Axis& a = axes_[axis_of_node_[node]];
      if (a.drive->on_other_frame(f, now_us, bus_) == hal::canopen::RemoteFrame::tpdo2) log_feedback(a);
      return;
    }
    if (f.id == hal::canopen::cob::sync && !f.is_extended()) {
      // The loop never hears its own SYNC: this one is another producer's.
      ++stats_.foreign_syncs;
      foreign_sync_seen_ = true;
    }
    for (std::size_t i = 0; i < count_; ++i) axes_[i].drive->on_other_frame(f, now_us, bus_);
  }
  void log_feedback(Axis& a) noexcept {
    const auto& fb = a.drive->feedback();
    if (!a.feedback_log.push({fb.position_actual, fb.load_position, fb.velocity_actual})) {
      ++a.stats.feedback_overflows;
    }
  }

  // A second SYNC producer: two clocks would drive the drives; stop the loop's and every axis.
  [[gnu::noinline, gnu::cold]] void on_foreign_sync() noexcept {
    foreign_sync_seen_ = false;
    if ((sync_blocked_ & kSyncForeign) != 0) return;
    sync_blocked_ |= kSyncForeign;
    note(LoopEventKind::foreign_sync, kBusEvent, AxisFault::foreign_sync);
    halt_all(AxisFault::foreign_sync);
  }

  // The controller's state changed (an error frame, the driver's report, a restart).
  [[gnu::noinline, gnu::cold]] void on_bus_state(std::uint64_t now_us) noexcept {
    const hal::BusState before = bus_state_;
    bus_state_ = bus_.bus_state();
    if (bus_state_ == hal::BusState::bus_off) {
      sync_blocked_ |= kSyncBusOff;
    } else {
      sync_blocked_ &= static_cast<std::uint8_t>(~kSyncBusOff);
    }
    switch (bus_state_) {
      case hal::BusState::error_active: note(LoopEventKind::bus_error_active, kBusEvent, AxisFault::none); break;
      case hal::BusState::error_warning: note(LoopEventKind::bus_error_warning, kBusEvent, AxisFault::none); break;
      case hal::BusState::error_passive: note(LoopEventKind::bus_error_passive, kBusEvent, AxisFault::none); break;
      case hal::BusState::bus_off: {
        ++stats_.bus_offs;
        note(LoopEventKind::bus_off, kBusEvent, AxisFault::bus_off);
        halt_all(AxisFault::bus_off);
        const hal::BusStatus st = bus_.restart();
        note(st == hal::BusStatus::ok ? LoopEventKind::bus_restart_requested : LoopEventKind::bus_restart_refused,
             kBusEvent, AxisFault::none);
        return;
      }
    }
    if (before != hal::BusState::bus_off) return;
    // Back on the bus: nothing the drives were told can be trusted (frames were lost both ways,
    // a drive may have faulted or restarted meanwhile). Start-up runs again before streaming.
    sync_unsent_ = false;
    unsent_run_ = 0;
    for (std::size_t i = 0; i < count_; ++i) {
      Axis& a = axes_[i];
      if (a.halt != AxisFault::bus_off) continue;
      a.halt = AxisFault::none;
      a.unanswered = 0;
      a.drive->start(now_us, bus_);
      note(LoopEventKind::start_up_rerun, static_cast<std::uint8_t>(i), AxisFault::none);
    }
  }

  [[gnu::noinline]] void on_drive_events(Axis& a, std::uint16_t ev) noexcept {
    namespace re = hal::canopen::remote_event;
    if ((ev & re::emcy) != 0) ++a.stats.emcy_received;
    if ((ev & re::heartbeat_lost) != 0) {
      ++a.stats.heartbeat_losses;
      stopped(a, AxisFault::heartbeat_lost);
    }
    if ((ev & re::boot_up) != 0) {
      ++a.stats.restarts;
      // A boot-up before the loop ever streamed is the drive coming up, not a fault.
      if (a.have_target) stopped(a, AxisFault::drive_restarted);
    }
    if ((ev & re::left_enabled) != 0) stopped(a, AxisFault::drive_left_enabled);
    if ((ev & re::left_operational) != 0) stopped(a, AxisFault::drive_not_operational);
    if ((ev & re::failed) != 0) stopped(a, AxisFault::start_up_failed);
    // Whatever took the drive out of operation voided the moves above: the axis is no longer where
    // they were planned from. Nothing resumes by itself; the application decides, once the drive
    // is ready again.
    if ((ev & (re::boot_up | re::heartbeat_lost | re::left_enabled | re::left_operational)) != 0) a.have_target = false;
    if ((ev & re::became_ready) != 0) {
      a.unanswered = 0;
      note(LoopEventKind::drive_ready, index_of(a), AxisFault::none);
    }
  }

  void supervise(Axis& a, std::uint64_t now_us) noexcept {
    hal::canopen::RemoteDrive& d = *a.drive;
    d.poll(now_us, bus_);
    if (const std::uint16_t ev = d.take_events(); ev != 0) on_drive_events(a, ev);

    const auto& fb = d.feedback();
    if (fb.tpdo1_received != a.fb_seen) {
      a.fb_seen = fb.tpdo1_received;
      a.unanswered = 0;
      // Following error: the feedback that arrived since the last tick answers the target sent in
      // the previous tick (the drive reaches a target one period after the SYNC that applies it).
      if (d.ready() && a.sent_prev_valid) {
        const std::uint32_t mag = distance_counts(fb.position_actual, a.sent_prev);
        if (mag > a.stats.max_following_error) a.stats.max_following_error = mag;
        if (a.cfg.following_error_counts != 0 && mag > a.cfg.following_error_counts) {
          ++a.stats.following_error_trips;
          a.fault = AxisFault::following_error;
          abandon(a, AxisFault::following_error);
        }
      }
      // Done is what the drive says, not what was sent: at the final setpoint within one count.
      if (a.finishing && d.ready() && distance_counts(fb.position_actual, a.final_target) <= 1) {
        a.finishing = false;
        ++a.stats.moves_completed;
        note(LoopEventKind::move_completed, index_of(a), AxisFault::none);
      }
    } else if (a.unanswered >= a.cfg.feedback_timeout_periods && a.cfg.feedback_timeout_periods != 0 &&
               a.halt == AxisFault::none && d.ready()) {
      ++a.stats.feedback_timeouts;
      halt(a, AxisFault::feedback_timeout);
    }
    if (a.finishing && a.cfg.in_position_timeout_periods != 0 && ++a.finish_wait > a.cfg.in_position_timeout_periods) {
      ++a.stats.not_in_position;
      a.fault = AxisFault::not_in_position;
      abandon(a, AxisFault::not_in_position);
    }
  }

  // Builds and sends the axis's RPDO of this tick's unit; false if it had one that did not go out.
  [[nodiscard]] bool stream(Axis& a) noexcept {
    hal::canopen::RemoteDrive& d = *a.drive;
    a.record.tick = stats_.ticks;
    a.record.sent = false;
    a.record.move_end = false;
    if (a.halt != AxisFault::none) {
      a.record.moving = false;
      return true;  // nothing for a halted axis
    }
    const bool ready = d.ready();
    if (ready && !a.have_target) {
      // Entering operation: hold where the drive is.
      a.target = d.feedback().position_actual;
      a.have_target = true;
    }
    std::int32_t target = a.target;
    if (ready) {
      if (a.pending) {
        target = *a.pending;  // the unit did not go out last tick: the same setpoint again
      } else {
        if (!a.active && !a.finishing && !a.queue.empty()) {
          a.active = true;
          a.sequence.start(a.queue.front().eval, a.target);
          if constexpr (kOnlineChanges) a.online.move_serial.fetch_add(1, std::memory_order_release);
          ++a.stats.moves_started;
          note(LoopEventKind::move_started, index_of(a), AxisFault::none);
        }
        if (a.active) {
          bool last = false;
          const std::int32_t next = next_setpoint(a, last);
          if (distance_counts(next, a.target) > a.guard) {
            // Never command a jump the actuator cannot make: abandon the move, hold position.
            ++a.stats.step_guard_trips;
            a.fault = AxisFault::step_guard;
            abandon(a, AxisFault::step_guard);
          } else {
            target = next;
            a.end_pending = last;
          }
        }
      }
    }
    const bool have_rpdo = d.rpdo(target, tx_);
    a.record.moving = a.active;
    a.record.target = target;
    const auto& fb = d.feedback();
    a.record.position_actual = fb.position_actual;
    a.record.load_position = fb.load_position;
    a.record.velocity_actual = fb.velocity_actual;
    a.record.feedback_count = fb.tpdo1_received;
    if (!have_rpdo) {
      a.sent_prev_valid = false;
      return true;
    }
    const hal::SendStatus st = bus_.send(tx_);
    if (st == hal::SendStatus::sent) {
      // Applied as if the SYNC follows, which it nearly always does; take_back() undoes this
      // tick's part when it did not.
      ++a.stats.rpdo_sent;
      a.record.sent = true;
      a.pending.reset();
      a.sent_prev = target;
      a.sent_prev_valid = ready;
      if (!ready) return true;
      a.target = target;
      ++a.unanswered;
      if (a.end_pending) {
        // The move's final setpoint is applied: it is done when the feedback shows it.
        a.record.move_end = true;
        a.end_pending = false;
        a.active = false;
        finish_active(a);
        a.finishing = true;
        a.finish_wait = 0;
        a.final_target = target;
      }
      return true;
    }
    // Busy or error: not queued and not retried now (no bursts). No SYNC goes out this tick, and
    // the same target goes out next tick: the move's clock waits for it.
    ++(st == hal::SendStatus::busy ? a.stats.rpdo_busy : a.stats.rpdo_errors);
    if (ready) a.pending = target;
    a.sent_prev_valid = false;
    return false;
  }

  // The tick's SYNC did not go out: the RPDO this axis sent was never applied. Its setpoint goes
  // out again next tick (the moves' clock holds); if it was a move's last, the move is finishing
  // from the tick it is applied in (the drive's feedback decides either way).
  [[gnu::noinline]] static void take_back(Axis& a) noexcept {
    if (!a.record.sent) return;
    a.record.sent = false;
    a.record.move_end = false;
    a.sent_prev_valid = false;
    if (!a.drive->ready()) return;
    a.pending = a.target;
    --a.unanswered;
  }

  static constexpr std::uint8_t kNoAxis = 0xFF;
  static_assert(MaxAxes < kNoAxis);
  static constexpr std::array<std::uint8_t, 128> no_axes() noexcept {
    std::array<std::uint8_t, 128> a{};
    for (auto& x : a) x = kNoAxis;
    return a;
  }

  // Per-tick state first (short offsets on a Cortex-M0), the axes last.
  Bus& bus_;
  std::size_t count_{0};
  // Why the loop sends no SYNC (0: it does): not started, a foreign SYNC seen (until restart()),
  // the bus is off. One byte, so that the tick tests one thing.
  static constexpr std::uint8_t kSyncNotStarted = 1;
  static constexpr std::uint8_t kSyncForeign = 2;
  static constexpr std::uint8_t kSyncBusOff = 4;
  std::uint8_t sync_blocked_{kSyncNotStarted};
  bool sync_unsent_{false};       // the last SYNC built did not go out: resend that frame
  bool foreign_sync_seen_{false};
  hal::BusState bus_state_{hal::BusState::error_active};
  std::uint16_t unsent_run_{0};   // ticks in a row whose unit did not go out
  std::uint32_t period_us_;
  LoopConfig config_;
  LoopStats stats_{};
  hal::canopen::SyncProducer sync_;
  const hal::CanFrame* sync_frame_{nullptr};
  // The frames a tick receives into and builds its RPDOs in: kept, so that a tick neither zeroes
  // nor copies a whole (FD-sized) frame; encoders write the header and the bytes they carry.
  hal::CanFrame rx_{};
  hal::CanFrame tx_{};
  std::array<std::uint8_t, 128> axis_of_node_{no_axes()};
  FixedQueue<LoopEvent, kEventLogCapacity> events_{};
  std::array<Axis, MaxAxes> axes_{};
};

}  // namespace settle::runtime
