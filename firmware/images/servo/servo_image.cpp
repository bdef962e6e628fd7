// SPDX-License-Identifier: Apache-2.0
// The servo-loop images (mps2-an386 / microbit), three builds of this file:
// - servo-<board>: runs servo_session.hpp's program, writes every frame the master sends to
//   servo-<board>.log (candump format) through semihosting, and measures with the exact
//   instruction counter (-icount shift=7) what each servo tick cost;
// - servo_fixed-<board> (SETTLE_SERVO_FIXED=1): the same with the loop on FixedEvaluation, integer
//   only per tick (what a Cortex-M0 without FPU runs), its log servo_fixed-<board>.log;
// - servo_eval-<board> (SETTLE_SERVO_EVALUATORS=1): what each evaluator costs on its own, per
//   tick of the same move (double/float RampCycloid::at and MoveStepper::step, the loop's
//   SetpointStream<float>::next, fixed-point Motion::at_tick, MotionStepper::next and the loop's
//   PositionStepper::next, the last two also through a ZVD shaper). Separate, so the servo
//   image's size is the loop's and the micro:bit's 16 KiB of RAM holds each.
// Reports: servo[_fixed|_eval]-<board>.txt, one `key value...` per line.
#include <cstdint>
#include <variant>

#include "servo_session.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/setpoints.hpp"
#include "settle/core/stepper.hpp"
#include "settle/firmware/instruction_counter.hpp"
#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/firmware/semihosting_can.hpp"
#include "settle/firmware/text.hpp"

#ifndef SETTLE_SERVO_EVALUATORS
#define SETTLE_SERVO_EVALUATORS 0
#endif
#ifndef SETTLE_SERVO_FIXED
#define SETTLE_SERVO_FIXED 0
#endif

namespace {

namespace fw = settle::firmware;
namespace rt = settle::runtime;
namespace core = settle::core;
namespace si = settle::firmware::servo_image;

constexpr std::string_view board{SETTLE_BOARD_NAME};

// Per-call statistics of the ticks timed inside the session.
struct Stats {
  std::uint64_t sum{0};
  std::uint32_t n{0};
  std::uint32_t min{UINT32_MAX};
  std::uint32_t max{0};
  void add(std::uint32_t v) {
    sum += v;
    ++n;
    if (v < min) min = v;
    if (v > max) max = v;
  }
};

class TickTimer {
 public:
  void use(const fw::InstructionCounter& c) { counter_ = &c; }
  void begin() { start_ = fw::InstructionCounter::now(); }
  void end(bool streaming) {
    const std::uint32_t n = counter_->instructions(start_, fw::InstructionCounter::now());
    all.add(n);
    if (streaming) moving.add(n);
  }
  Stats all{};
  Stats moving{};

 private:
  const fw::InstructionCounter* counter_{nullptr};
  std::uint32_t start_{0};
};

template <std::size_t N>
void append_stats(fw::Text<N>& t, std::string_view key, std::uint32_t min, std::int64_t mean_centi, std::uint32_t max,
                  std::uint32_t calls) {
  t.append(key).append(" min ").append_unsigned(min).append(" mean ").append_scaled(mean_centi, 2);
  t.append(" max ").append_unsigned(max).append(" calls ").append_unsigned(calls).append("\n");
}

template <std::size_t N>
void append_cost(fw::Text<N>& t, std::string_view key, const fw::InstructionCost& c) {
  append_stats(t, key, c.min, c.mean_centi, c.max, c.calls);
}

template <std::size_t N>
void append_ticks(fw::Text<N>& t, std::string_view key, const Stats& s) {
  const std::int64_t mean = s.n == 0 ? 0 : static_cast<std::int64_t>((s.sum * 100 + s.n / 2) / s.n);
  append_stats(t, key, s.n == 0 ? 0 : s.min, mean, s.max, s.n);
}

#if SETTLE_SERVO_EVALUATORS
// The move, planned on the host and pinned (servo_session.hpp).
core::Move<double> g_move_d{};
// Evaluator bodies for InstructionCounter::measure: each call evaluates the next 1 ms tick of the
// pinned move, wrapping to its start at the end. Volatile sinks keep the results alive.
core::Move<float> g_move_f{};
core::fixed::Motion g_fixed{};
core::MoveStepper<double> g_step_d{};
core::MoveStepper<float> g_step_f{};
core::fixed::MotionStepper<core::fixed::Motion::kMaxTracks> g_step_q{};
core::SetpointStream<float> g_stream_f{};  // what the loop calls per tick: step + counts (double)
std::int32_t g_n{0};
std::int32_t g_ticks{0};  // ticks in the move, the last one included
volatile double g_sink_d{};
volatile float g_sink_f{};
volatile std::int32_t g_sink_q{};

std::int32_t next_tick() {
  const std::int32_t n = g_n;
  g_n = n + 1 == g_ticks ? 0 : n + 1;
  return n;
}

[[gnu::noinline]] void at_double() {
  const auto& rc = *std::get_if<core::RampCycloid<double>>(&g_move_d.profile().variant());
  g_sink_d = rc.at(static_cast<double>(next_tick()) * 1e-3).p;
}
[[gnu::noinline]] void at_float() {
  const auto& rc = *std::get_if<core::RampCycloid<float>>(&g_move_f.profile().variant());
  g_sink_f = rc.at(static_cast<float>(next_tick()) * 1e-3F).p;
}
[[gnu::noinline]] void step_double() { g_sink_d = g_step_d.step().p; }
[[gnu::noinline]] void step_float() { g_sink_f = g_step_f.step().p; }
[[gnu::noinline]] void setpoint_float() {
  bool last = false;
  g_sink_q = g_stream_f.next(last);
}
[[gnu::noinline]] void at_fixed() { g_sink_q = g_fixed.at_tick(next_tick()).p; }
[[gnu::noinline]] void step_fixed() { g_sink_q = g_step_q.next().p; }
// The loop's fixed-point path (FixedEvaluation): position only, from a plan built outside the tick.
core::fixed::PositionPlan g_plan{};
core::fixed::PositionStepper g_step_pos{};
[[gnu::noinline]] void step_fixed_pos() { g_sink_q = g_step_pos.next(); }

// The same S-curve through a ZVD shaper for the beam's mode (three tracks, impulses between ticks).
core::Status shape_zvd(core::Move<double>& m) {
  core::Shaper<double> s{};
  const core::Status st = core::design_shaper(core::ShaperKind::zvd, 22.04871, 0.0, 0.05, s);
  if (st == core::Status::ok) m = core::Move<double>{m.profile(), s, m.peaks()};  // peaks bound a convex shaper's
  return st;
}

#else
#if SETTLE_SERVO_FIXED
using Evaluation = si::FixedImageEvaluation;
constexpr std::string_view kStem{"servo_fixed-"};
#else
using Evaluation = rt::FloatEvaluation<float>;
constexpr std::string_view kStem{"servo-"};
#endif
// Static: the program holds the loop, two loopback ports and the log buffer (RAM, not stack).
fw::SemihostingLineSink g_sink{};
TickTimer g_timer{};
si::Program<fw::SemihostingLineSink, TickTimer, Evaluation> g_program{g_sink, g_timer};

#endif

template <std::size_t N>
void write_report(const fw::Text<N>& rep, std::string_view stem) {
  fw::Text<40> name{};
  name.append(stem).append(board).append(".txt");
  fw::semihosting::File file{fw::semihosting::File::open(name.view(), fw::semihosting::OpenMode::write)};
  const bool written{file.write(rep.view()) && file.close()};
  static_cast<void>(fw::semihosting::write_console(rep.view()));
  if (!written || rep.overflowed()) fw::fatal("servo: could not write the report\n", 2);
}

}  // namespace

int settle::firmware::image_main() {
  const InstructionCounter counter{InstructionCounter::calibrate()};
  if (!counter.exact()) fatal("servo: the instruction counter is not exact (QEMU needs -icount shift=7)\n", 3);
  // Static (RAM the stack does not need): the evaluator report is the longer one.
  static Text<SETTLE_SERVO_EVALUATORS ? 640 : 448> rep{};
  rep.append("board ").append(board).append("\n");
#if SETTLE_SERVO_EVALUATORS
  g_move_d = si::pinned_move();
  g_move_f = core::Move<float>{g_move_d};
  g_ticks = static_cast<std::int32_t>(g_move_d.duration() / 1e-3) + 2;
  const core::fixed::Scale scale{};
  const core::Status fixed_status = g_fixed.build(g_move_d, scale);
  g_step_d = core::MoveStepper<double>{g_move_d, 1e-3};
  g_step_f = core::MoveStepper<float>{g_move_f, 1e-3F};
  g_step_q = core::fixed::MotionStepper<core::fixed::Motion::kMaxTracks>{g_fixed};
  const auto calls = static_cast<std::uint32_t>(g_ticks);
  g_n = 0;
  append_cost(rep, "at_double", counter.measure(at_double, calls));
  g_n = 0;
  append_cost(rep, "at_float", counter.measure(at_float, calls));
  append_cost(rep, "step_double", counter.measure(step_double, calls));
  append_cost(rep, "step_float", counter.measure(step_float, calls));
  g_stream_f = core::SetpointStream<float>{g_move_f, si::kScale, 0};
  append_cost(rep, "setpoint_float", counter.measure(setpoint_float, calls));
  rep.append("fixed_build ").append(fixed_status == core::Status::ok ? "ok" : "failed").append("\n");
  if (fixed_status == core::Status::ok) {
    g_n = 0;
    append_cost(rep, "at_fixed", counter.measure(at_fixed, calls));
    append_cost(rep, "step_fixed", counter.measure(step_fixed, calls));
  }
  const core::Status plan_status = fixed_status == core::Status::ok ? g_plan.build(g_fixed) : fixed_status;
  if (plan_status == core::Status::ok) {
    g_step_pos = core::fixed::PositionStepper{g_plan};
    append_cost(rep, "step_fixed_pos", counter.measure(step_fixed_pos, calls));
  }
  // Shaped: the whole shaped move, every tick (g_move_d is not needed any more).
  core::Status zvd_status = shape_zvd(g_move_d);
  if (zvd_status == core::Status::ok) zvd_status = g_fixed.build(g_move_d, scale);
  if (zvd_status == core::Status::ok) zvd_status = g_plan.build(g_fixed);
  rep.append("fixed_zvd_build ").append(zvd_status == core::Status::ok ? "ok" : "failed").append("\n");
  if (zvd_status == core::Status::ok) {
    const auto zvd_calls = static_cast<std::uint32_t>(g_fixed.end_tick() + 2);
    g_step_q = core::fixed::MotionStepper<core::fixed::Motion::kMaxTracks>{g_fixed};
    append_cost(rep, "step_fixed_zvd", counter.measure(step_fixed, zvd_calls));
    g_step_pos = core::fixed::PositionStepper{g_plan};
    append_cost(rep, "step_fixed_pos_zvd", counter.measure(step_fixed_pos, zvd_calls));
  }
  rep.append("stack_high_water ").append_unsigned(stack_high_water()).append(" of ");
  rep.append_unsigned(stack_size()).append("\n");
  write_report(rep, "servo_eval-");
  return fixed_status == core::Status::ok && plan_status == core::Status::ok && zvd_status == core::Status::ok ? 0 : 1;
#else
  Text<40> log_name{};
  log_name.append(kStem).append(board).append(".log");
  if (!g_sink.open(log_name.view())) fatal("servo: cannot open the log file\n", 2);
  // Initialised in place (no Move<double> temporary in this frame, which is on the stack for the
  // whole session: submitting a fixed-point move needs that room).
  static const core::Move<double> move{si::pinned_move()};
  g_timer.use(counter);
  const si::RunResult r = g_program.run(move);
  const bool log_written = g_sink.close();
  rep.append("outcome ").append(to_string(r.session.outcome)).append("\n");
  rep.append("ticks ").append_unsigned(r.session.ticks).append(" ready ").append_unsigned(r.session.ready_tick);
  rep.append(" stream_end ").append_unsigned(r.session.stream_end_tick).append("\n");
  rep.append("frames ").append_unsigned(r.frames_logged).append(" format_errors ").append_unsigned(r.format_errors);
  rep.append(" early_flushes ").append_unsigned(r.early_flushes).append(" log_written ");
  rep.append(log_written ? "yes" : "no").append("\n");
  rep.append("final_target ").append_signed(r.final_target).append(" final_position ");
  rep.append_signed(r.final_position).append(" rx_overflows ").append_unsigned(r.rx_overflows).append("\n");
  append_ticks(rep, "tick_all", g_timer.all);
  append_ticks(rep, "tick_moving", g_timer.moving);
  rep.append("stack_high_water ").append_unsigned(stack_high_water()).append(" of ");
  rep.append_unsigned(stack_size()).append("\n");
  write_report(rep, kStem);
  const bool ok = log_written && r.session.outcome == runtime::SessionOutcome::completed && r.format_errors == 0 &&
                  r.final_position == r.final_target && r.rx_overflows == 0;
  return ok ? 0 : 1;
#endif
}
