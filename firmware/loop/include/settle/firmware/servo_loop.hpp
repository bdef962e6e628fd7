#pragma once
// The periodic servo loop: each tick it takes the drives' feedback, evaluates every axis's active
// move, converts it to drive counts, sends one RPDO per axis and one SYNC, and keeps statistics.
// Generic over the evaluation scalar, the number of axes and the queue depth; time is given by
// the caller (the runner owns the clock), so the same loop runs under a Linux timer, a Cortex-M
// SysTick or a test's virtual clock. No heap, no exceptions, bounded work per tick.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

#include "settle/core/planner.hpp"
#include "settle/firmware/evaluation.hpp"
#include "settle/firmware/fixed_queue.hpp"
#include "settle/hal/can_bus.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sync.hpp"

namespace settle::firmware {

enum class LoopStatus : std::uint8_t {
  ok,
  plan_failed,            // the planner refused the request (see the core::Status returned with it)
  queue_full,
  no_such_axis,
  too_many_axes,
  exceeds_axis_velocity,  // the move's true peak velocity is over the axis's vmax
  does_not_fit_counts,    // the move would leave the int32 count range
  evaluation_refused,     // the evaluator cannot hold the move (fixed point: see the core::Status)
  bad_axis_config,
};

[[nodiscard]] const char* to_string(LoopStatus s) noexcept;

struct AxisConfig {
  hal::canopen::RemoteDriveConfig drive{};
  double counts_per_unit{1e6};           // e.g. 1 count = 1 µm for the seed-000 beam
  double vmax{1.0};                      // actuator limit, units/s: moves above it are refused
  std::int32_t step_margin_counts{2};    // setpoint-step guard: vmax * period + this
  std::uint32_t following_error_counts{0};  // 0 = off
};

// What one axis did in the last tick: the runner copies it out to log or plot.
struct TickRecord {
  std::uint64_t tick{0};
  std::int32_t target{0};         // counts commanded this tick (held when not moving)
  bool sent{false};               // an RPDO carrying it left this tick
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
  std::uint32_t max_following_error{0};  // counts, the shorter way round the int32 wrap
  std::uint64_t feedback_overflows{0};  // samples dropped because feedback_log() was not drained
};

// Feedback samples kept per axis until the owner drains them (every tick): one arrives per
// period, so this is 16 periods of slack; 12 bytes each, per axis, on a microcontroller.
inline constexpr std::size_t kFeedbackLogCapacity = 16;

struct LoopStats {
  std::uint64_t ticks{0};
  std::uint64_t sync_sent{0};
  std::uint64_t sync_busy{0};
  std::uint64_t frames_received{0};
};

// Bus: hal::CanBus (any backend, through its virtual hooks) or a backend's own type such as
// hal::MailboxBus, whose send and receive are then direct calls the compiler inlines: what
// firmware that knows its controller does (firmware/README.md: what the Cortex-M0 tick costs).
template <typename Scalar = double, std::size_t MaxAxes = 1, std::size_t QueueDepth = 4,
          typename Evaluation = FloatEvaluation<Scalar>, typename Bus = hal::CanBus>
class ServoLoop {
  static_assert(std::is_base_of_v<hal::CanBus, Bus>, "Bus is hal::CanBus or one of its backends");

 public:
  ServoLoop(Bus& bus, std::uint32_t period_us) noexcept
      : bus_{bus}, period_us_{period_us}, sync_{period_us} {}
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  [[nodiscard]] LoopStatus add_axis(const AxisConfig& cfg) noexcept {
    if (count_ == MaxAxes) return LoopStatus::too_many_axes;
    if (!(cfg.counts_per_unit > 0.0) || !std::isfinite(cfg.counts_per_unit) || !(cfg.vmax > 0.0) ||
        !std::isfinite(cfg.vmax) || cfg.step_margin_counts < 0) {
      return LoopStatus::bad_axis_config;
    }
    const std::uint8_t node = cfg.drive.node;
    if (node == 0 || node > 127 || axis_of_node_[node] != kNoAxis) return LoopStatus::bad_axis_config;
    Axis& a = axes_[count_];
    axis_of_node_[node] = static_cast<std::uint8_t>(count_);
    a.cfg = cfg;
    a.cfg.drive.sync_period_us = period_us_;
    a.drive.emplace(a.cfg.drive);
    // In whole counts, once: the tick compares integers. At or past 2^31 no step can exceed it.
    const double guard = std::floor(cfg.vmax * cfg.counts_per_unit * period_us_ * 1e-6) + cfg.step_margin_counts;
    a.guard = guard < 2147483648.0 ? static_cast<std::uint32_t>(guard) : std::uint32_t{1} << 31U;
    ++count_;
    return LoopStatus::ok;
  }

  // Starts every drive (NMT, SDO configuration, enable sequence); tick() must run from now on.
  void start(std::uint64_t now_us) noexcept {
    for (std::size_t i = 0; i < count_; ++i) axes_[i].drive->start(now_us, bus_);
    started_ = true;
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

  [[nodiscard]] LoopStatus submit(std::size_t axis, const core::Move<double>& m,
                                  core::Status* why = nullptr) noexcept {
    if (axis >= MaxAxes || axis >= count_) return LoopStatus::no_such_axis;
    Axis& a = axes_[axis];
    // A velocity step (seed 001's command) is streamable: sampled, it is a jump of at most
    // peak |v| * period, which the step guard allows whenever peak |v| is within vmax.
    if (!(m.peaks().v <= a.cfg.vmax * (1.0 + 1e-9))) return LoopStatus::exceeds_axis_velocity;
    const double counts = std::fabs(m.distance()) * a.cfg.counts_per_unit;
    if (!(counts < static_cast<double>(std::numeric_limits<std::int32_t>::max()) / 2)) {
      return LoopStatus::does_not_fit_counts;
    }
    if (a.queue.full()) return LoopStatus::queue_full;
    // Prepared in place in the queue's free slot, which joins the queue only on success: a
    // refusal leaves the queue as it was, and no second copy of a move is ever held.
    const core::Status st = Evaluation::prepare(m, period_us_, a.cfg.counts_per_unit, a.queue.back_slot());
    if (why != nullptr) *why = st;
    if (st != core::Status::ok) return LoopStatus::evaluation_refused;
    a.queue.commit_back();
    return LoopStatus::ok;
  }

  // One servo period. Bounded: drains at most kMaxFramesPerTick received frames.
  void tick(std::uint64_t now_us) noexcept {
    ++stats_.ticks;
    receive_all(now_us);
    for (std::size_t i = 0; i < count_; ++i) supervise(axes_[i], now_us);
    for (std::size_t i = 0; i < count_; ++i) stream(axes_[i]);
    if (started_) {
      const hal::SendStatus st = bus_.send(sync_.next());
      if (st == hal::SendStatus::sent) {
        ++stats_.sync_sent;
      } else {
        ++stats_.sync_busy;
      }
    }
  }

  // One received frame: routed to its axis's drive, its feedback logged. tick() calls it for every
  // frame it drains; a caller that reads the bus itself (after the session, say) calls it too.
  void receive(const hal::CanFrame& f, std::uint64_t now_us) noexcept {
    ++stats_.frames_received;
    // CANopen puts the sending node in the low 7 bits of every node-specific COB-ID (TPDO,
    // SDO, EMCY, heartbeat): route there, so a tick costs O(axes), not O(axes^2). Node 0
    // (NMT, SYNC, time) and extended ids go to every axis.
    const std::uint32_t node = f.id & 0x7F;
    const std::uint8_t target = f.is_extended() || node == 0 ? kNoAxis : axis_of_node_[node];
    if (target != kNoAxis) {
      Axis& a = axes_[target];
      if (a.drive->on_frame(f, now_us, bus_) == hal::canopen::RemoteFrame::tpdo2) {
        const auto& fb = a.drive->feedback();
        if (!a.feedback_log.push({fb.position_actual, fb.load_position, fb.velocity_actual})) {
          ++a.stats.feedback_overflows;
        }
      }
    } else if (f.is_extended() || node == 0) {
      for (std::size_t i = 0; i < count_; ++i) axes_[i].drive->on_frame(f, now_us, bus_);
    }
  }

  // Stops streaming on an axis: the active move and the queue are dropped, the axis holds.
  void abort(std::size_t axis) noexcept {
    if (axis >= MaxAxes || axis >= count_) return;
    abandon(axes_[axis]);
  }

  [[nodiscard]] std::size_t axis_count() const noexcept { return count_; }
  [[nodiscard]] const hal::canopen::RemoteDrive& drive(std::size_t i) const noexcept { return *axes_[i].drive; }
  [[nodiscard]] const TickRecord& record(std::size_t i) const noexcept { return axes_[i].record; }
  [[nodiscard]] const AxisStats& axis_stats(std::size_t i) const noexcept { return axes_[i].stats; }
  // Feedback samples in arrival order (one per SYNC the drive processed); drain every tick.
  [[nodiscard]] FixedQueue<FeedbackSample, kFeedbackLogCapacity>& feedback_log(std::size_t i) noexcept {
    return axes_[i].feedback_log;
  }
  [[nodiscard]] const LoopStats& stats() const noexcept { return stats_; }
  [[nodiscard]] bool ready(std::size_t i) const noexcept { return axes_[i].drive->ready(); }
  [[nodiscard]] bool all_ready() const noexcept {
    for (std::size_t i = 0; i < count_; ++i) {
      if (!axes_[i].drive->ready()) return false;
    }
    return count_ > 0;
  }
  // Nothing active and nothing queued on any axis.
  [[nodiscard]] bool idle() const noexcept {
    for (std::size_t i = 0; i < count_; ++i) {
      if (axes_[i].active || !axes_[i].queue.empty()) return false;
    }
    return true;
  }
  [[nodiscard]] std::uint32_t period_us() const noexcept { return period_us_; }

  static constexpr std::size_t kMaxFramesPerTick = 16 * MaxAxes + 16;

 private:
  // What every tick touches comes first: a Cortex-M0 reaches only the first 32 bytes of a struct
  // with one byte load and the first 128 with one word load; the queue's prepared moves are large.
  struct Axis {
    bool active{false};
    bool have_target{false};
    bool sent_prev_valid{false};
    bool end_pending{false};      // the final setpoint of a move is waiting to be sent
    std::int32_t target{0};       // last target commanded
    std::int32_t sent_prev{0};    // target sent in the previous tick (what the feedback answers)
    std::uint32_t guard{0};       // largest setpoint step allowed per tick, counts (2^31: any)
    std::optional<std::int32_t> pending{};  // computed but not yet sent (tx busy): resent first
    std::uint64_t fb_seen{0};
    typename Evaluation::Stream setpoints{};
    TickRecord record{};
    AxisStats stats{};
    FixedQueue<FeedbackSample, kFeedbackLogCapacity> feedback_log{};
    std::optional<hal::canopen::RemoteDrive> drive{};
    AxisConfig cfg{};
    FixedQueue<typename Evaluation::Stored, QueueDepth> queue{};
  };

  // |a - b| in counts on the wrapping int32 scale every position lives on (streams wrap modulo
  // 2^32, as drives' position counters do): the shorter way round, at most 2^31. A move that
  // crosses the wrap steps by its true step, and every operation is a 32-bit one.
  [[nodiscard]] static std::uint32_t distance_counts(std::int32_t a, std::int32_t b) noexcept {
    const std::uint32_t d = static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b);
    return d <= 0x8000'0000U ? d : 0U - d;
  }

  // Drops the active move (counted as aborted) and everything queued; the axis holds.
  static void abandon(Axis& a) noexcept {
    if (a.active) ++a.stats.moves_aborted;
    a.active = false;
    a.pending.reset();
    a.end_pending = false;
    a.queue.clear();
  }

  void receive_all(std::uint64_t now_us) noexcept {
    for (std::size_t n = 0; n < kMaxFramesPerTick; ++n) {
      if (bus_.receive(rx_, 0) != hal::ReceiveStatus::received) break;
      receive(rx_, now_us);
    }
  }

  void supervise(Axis& a, std::uint64_t now_us) noexcept {
    hal::canopen::RemoteDrive& d = *a.drive;
    d.poll(now_us, bus_);
    const std::uint16_t ev = d.take_events();
    namespace re = hal::canopen::remote_event;
    if ((ev & re::heartbeat_lost) != 0) ++a.stats.heartbeat_losses;
    if ((ev & re::emcy) != 0) ++a.stats.emcy_received;
    if ((ev & re::boot_up) != 0) ++a.stats.restarts;
    // Whatever took the drive out of operation voids the move in flight and every queued one: the
    // axis is no longer where they were planned from. Nothing resumes by itself; the application
    // decides, once the drive is ready again.
    if ((ev & (re::heartbeat_lost | re::left_enabled | re::boot_up | re::failed)) != 0) abandon(a);
    if ((ev & (re::boot_up | re::heartbeat_lost | re::left_enabled)) != 0) a.have_target = false;

    // Following error: the feedback that arrived since the last tick answers the target sent in
    // the previous tick (the drive reaches a target one period after the SYNC that applies it).
    const auto& fb = d.feedback();
    if (fb.tpdo1_received != a.fb_seen) {
      a.fb_seen = fb.tpdo1_received;
      if (d.ready() && a.sent_prev_valid) {
        const std::uint32_t mag = distance_counts(fb.position_actual, a.sent_prev);
        if (mag > a.stats.max_following_error) a.stats.max_following_error = mag;
        if (a.cfg.following_error_counts != 0 && mag > a.cfg.following_error_counts) {
          ++a.stats.following_error_trips;
          abandon(a);
        }
      }
    }
  }

  void stream(Axis& a) noexcept {
    hal::canopen::RemoteDrive& d = *a.drive;
    a.record.tick = stats_.ticks;
    a.record.sent = false;
    a.record.move_end = false;
    if (d.ready() && !a.have_target) {
      // Entering operation: hold where the drive is.
      a.target = d.feedback().position_actual;
      a.have_target = true;
    }
    std::int32_t target = a.target;
    if (d.ready()) {
      if (a.pending) {
        target = *a.pending;
      } else {
        if (!a.active && !a.queue.empty()) {
          a.active = true;
          a.setpoints = Evaluation::start(a.queue.front(), a.target);
          ++a.stats.moves_started;
        }
        if (a.active) {
          bool last = false;
          const std::int32_t next = a.setpoints.next(last);
          if (distance_counts(next, a.target) > a.guard) {
            // Never command a jump the actuator cannot make: abandon the move, hold position.
            ++a.stats.step_guard_trips;
            abandon(a);
          } else {
            target = next;
            if (last) {
              a.end_pending = true;
              a.active = false;
              a.queue.drop_front();
              ++a.stats.moves_completed;
            }
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
      return;
    }
    switch (bus_.send(tx_)) {
      case hal::SendStatus::sent:
        ++a.stats.rpdo_sent;
        a.record.sent = true;
        a.record.move_end = a.end_pending && d.ready();
        a.end_pending = false;
        a.pending.reset();
        if (d.ready()) a.target = target;
        a.sent_prev = target;
        a.sent_prev_valid = d.ready();
        break;
      case hal::SendStatus::busy:
        // Not queued and not retried now (no bursts): the same target goes out next tick,
        // and the move's clock waits for it.
        ++a.stats.rpdo_busy;
        if (d.ready()) a.pending = target;
        a.sent_prev_valid = false;
        break;
      case hal::SendStatus::error:
        ++a.stats.rpdo_errors;
        if (d.ready()) a.pending = target;
        a.sent_prev_valid = false;
        break;
    }
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
  bool started_{false};
  std::uint32_t period_us_;
  LoopStats stats_{};
  hal::canopen::SyncProducer sync_;
  // The frames a tick receives into and builds its RPDOs in: kept, so that a tick neither zeroes
  // nor copies a whole (FD-sized) frame; encoders write the header and the bytes they carry.
  hal::CanFrame rx_{};
  hal::CanFrame tx_{};
  std::array<std::uint8_t, 128> axis_of_node_{no_axes()};
  std::array<Axis, MaxAxes> axes_{};
};

}  // namespace settle::firmware
