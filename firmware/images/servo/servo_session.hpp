// SPDX-License-Identifier: Apache-2.0
#pragma once
// The servo-loop image's program, shared by the Cortex-M images and the host build
// (settle_servo_image_host) so that both send the same frames: one axis of ServoLoop<float> on a
// virtual 1 kHz clock streams one move to an ideal CiA 402 drive (hal/testing's IdealDrive, in
// the same program on an in-process loopback bus), and every frame the master sends is written as a
// candump line to the caller's sink. The loop itself runs on a CAN controller's buffers
// (hal::MailboxBus), as it would in drive firmware; the harness plays the controller's wire
// side between ticks, moving frames to and from the loopback bus and the log, so a timed tick
// holds the loop's own work and its driver calls but not the simulated drive's or the log's. Nothing is planned here: the move is the one `core::plan`
// gives for seed 000's beam (S-curve, 0.05 m in 0.8 Tn, omega 22.04871 rad/s), pinned as its
// RampCycloidParams and peaks; the host test checks that plan() still gives exactly these.
#include <cstddef>
#include <cstdint>

#include "settle/core/move.hpp"
#include "settle/core/ramp_cycloid.hpp"
#include "settle/firmware/candump_tap.hpp"
#include "settle/runtime/servo_loop.hpp"
#include "settle/runtime/session.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/mailbox_bus.hpp"
#include "settle/hal/testing/ideal_drive.hpp"

namespace settle::firmware::servo_image {

inline constexpr core::AxisScale kScale{1e6, 1000};  // 1 count = 1 µm, a 1 kHz loop
inline constexpr std::uint8_t kNode = 1;       // `settle plant`'s default node
inline constexpr std::uint64_t kSettleTicks = 1000;
inline constexpr const char* kIface = "vcan0";  // the interface named in the log (canplayer's)

// plan({scurve, D 0.05, T 0.8 * 2 pi / 22.04871, omega 22.04871}) on x86-64, printed with %a.
inline constexpr core::RampCycloidParams kParams{
    0x1.999999999999ap-5,   // distance 0.05 m
    0x1.d2e4677b3e768p-5,   // tau 0.0569937 s
    0.0,                    // cruise
    0x1.ec91887e5a772p+2,   // amplitude 7.69638 m/s^2
    -0x1.8p+4,              // c2 = -24
    0.0,                    // c3
};
inline constexpr core::Peaks<double> kPeaks{0x1.2e5c2de7a3a83p-1, 0x1.f58fe95a64ee7p+4, 0x1.a5ff638fd82d7p+11,
                                            false, false};

// Built in place (Move::assign): no temporary shape, profile or shaper on the stack.
[[nodiscard]] inline core::Move<double> pinned_move() noexcept {
  core::Move<double> m{};
  m.assign<core::RampCycloid<double>>(core::ProfileKind::scurve, kParams, nullptr, kPeaks);
  return m;
}

// The CAN controller the loop runs on: three transmit mailboxes, an 8-frame receive FIFO.
using Controller = hal::MailboxBus<3, 8>;

// One axis, a queue of two moves, on the controller's own type (its driver calls are direct).
// Evaluation: FloatEvaluation<float> (the Cortex-M4F's FPU) or FixedImageEvaluation (integer only
// per tick: the servo_fixed images, the Cortex-M0's).
template <typename Evaluation = runtime::FloatEvaluation<float>>
using LoopOf = runtime::ServoLoop<float, 1, 2, Evaluation, Controller>;
using Loop = LoopOf<>;
// Position plans of up to 8 intervals (every closed form unshaped; ~0.6 KiB a queue slot instead
// of the default 24 intervals' 1.6 KiB): what fits the micro:bit's 16 KiB next to the in-image
// drive and log. A move that needs more is refused at submit (table_too_small).
using FixedImageEvaluation = runtime::BasicFixedEvaluation<8>;

// The far end of the bus: hal/testing's ideal drive (a DriveNode whose axis reaches each target
// one period after the SYNC that applies it), on its own 8-frame loopback port. It only counts
// the setpoints it applies (no record buffer).
using Drive = hal::testing::IdealDrive<hal::LoopbackBus<8>>;
[[nodiscard]] constexpr hal::canopen::DriveNodeConfig drive_config() noexcept {
  hal::canopen::DriveNodeConfig c{};
  c.node = kNode;
  c.sync_period_us = kScale.period_us;
  return c;
}

// What a run did, for the image's report and the host's summary.
struct RunResult {
  runtime::SessionResult session{};
  std::int32_t final_position{0};
  std::int32_t final_target{0};
  std::uint64_t frames_logged{0};
  std::uint64_t format_errors{0};
  std::uint64_t early_flushes{0};
  std::uint64_t applied{0};
  std::uint64_t rx_overflows{0};  // frames a queue of the harness or the controller FIFO dropped: must be 0
};

// Timer: `void begin()`, `void end(bool streaming)` around every tick (the image counts
// instructions there; the host does nothing).
template <typename LineSink, typename Timer, typename Evaluation = runtime::FloatEvaluation<float>>
class Program {
 public:
  Program(LineSink& sink, Timer& timer) noexcept
      : master_port_{hub_}, tap_{master_port_, sink, kIface}, drive_{hub_, drive_config()}, loop_{controller_, kScale.period_us},
        timer_{timer} {}
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  [[nodiscard]] RunResult run(const core::Move<double>& move) noexcept {
    runtime::AxisConfig ac{};
    ac.drive.node = kNode;
    ac.scale = kScale;
    ac.vmax = 1.0;
    RunResult r{};
    if (loop_.add_axis(ac) != runtime::LoopStatus::ok) {
      r.session.outcome = runtime::SessionOutcome::rejected;
      r.session.rejection = runtime::LoopStatus::bad_axis_config;
      return r;
    }
    runtime::VirtualClock clock{kScale.period_us};
    runtime::SessionConfig cfg{};
    cfg.settle_ticks = kSettleTicks;
    cfg.max_ticks = 10'000;
    Timed timed{*this};
    r.session = runtime::run_session(timed, clock, &move, 1, cfg, [this, &clock](std::uint64_t, bool) {
      drive_.process(clock.now_us());
    });
    r.final_position = drive_.position();
    r.final_target = loop_.record(0).target;
    r.frames_logged = tap_.counters().sent;
    r.format_errors = tap_.format_errors();
    r.early_flushes = tap_.early_flushes();
    r.applied = drive_.applied_count();
    r.rx_overflows = drive_.port().counters().rx_overflow_drops + master_port_.counters().rx_overflow_drops +
                     controller_.counters().rx_overflow_drops;
    return r;
  }

 private:
  // The loop as run_session sees it, with the clock handed to the hub and the log, and each
  // tick bracketed by the timer.
  struct Timed {
    static constexpr std::size_t kMaxAxes = LoopOf<Evaluation>::kMaxAxes;
    Program& p;
    void start(std::uint64_t now_us) noexcept {
      p.at(now_us);
      p.drive_.start(now_us);
      p.drive_.process(now_us);
      p.loop_.start(now_us);
      p.transmit();
      p.tap_.flush();
    }
    void tick(std::uint64_t now_us) noexcept {
      p.at(now_us);
      p.arrive();
      const bool streaming = !p.loop_.idle();
      p.timer_.begin();
      p.loop_.tick(now_us);
      p.timer_.end(streaming);
      p.loop_.feedback_log(0).clear();  // the owner drains the feedback every tick (unused here)
      p.transmit();
      p.tap_.flush();
    }
    [[nodiscard]] std::size_t axis_count() const noexcept { return p.loop_.axis_count(); }
    [[nodiscard]] bool all_ready() const noexcept { return p.loop_.all_ready(); }
    [[nodiscard]] runtime::LoopStatus submit(std::size_t axis, const core::Move<double>& m) noexcept {
      return p.loop_.submit(axis, m);
    }
    void abort(std::size_t axis) noexcept { p.loop_.abort(axis); }
    void release(std::size_t axis) noexcept { p.loop_.release(axis); }
    [[nodiscard]] const hal::canopen::RemoteDrive& drive(std::size_t i) const noexcept { return p.loop_.drive(i); }
    [[nodiscard]] bool ready(std::size_t i) const noexcept { return p.loop_.ready(i); }
    [[nodiscard]] const runtime::AxisStats& axis_stats(std::size_t i) const noexcept { return p.loop_.axis_stats(i); }
    [[nodiscard]] bool idle() const noexcept { return p.loop_.idle(); }
    [[nodiscard]] bool halted(std::size_t i) const noexcept { return p.loop_.halted(i); }
    [[nodiscard]] runtime::AxisFault fault(std::size_t i) const noexcept { return p.loop_.fault(i); }
  };

  void at(std::uint64_t now_us) noexcept {
    hub_.set_time_us(now_us);
    tap_.set_time_us(now_us);
  }
  // The controller's wire side. Every frame the drive sent since the last tick reaches the receive
  // FIFO (an overrun there is the loop's to see in its bus counters), and every mailbox the loop
  // filled goes out, through the log, in order.
  void arrive() noexcept {
    hal::CanFrame f{};
    while (tap_.receive(f, 0) == hal::ReceiveStatus::received) (void)controller_.put_received(f);
  }
  void transmit() noexcept {
    hal::CanFrame f{};
    while (controller_.take_sent(f)) (void)tap_.send(f);
  }

  hal::LoopbackHub hub_{};
  hal::LoopbackBus<4> master_port_;
  CandumpTapBus<LineSink> tap_;
  Controller controller_{};
  Drive drive_;
  LoopOf<Evaluation> loop_;
  Timer& timer_;
};

}  // namespace settle::firmware::servo_image
