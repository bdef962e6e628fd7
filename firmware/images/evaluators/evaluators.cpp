// SPDX-License-Identifier: Apache-2.0
// evaluators-<board>: instructions per tick of every evaluator on every kind of move, on the target.
// The moves are the golden list's (core/fixed/golden.hpp: both S-curves, ramp-versine, 3-4-5, a
// pseudo-polynomial, a trapezoid, an S-curve through ZV and a damped one through ZVD), planned here
// as the golden image plans them. Per move, each evaluator runs every tick from 0 to the move's end
// (its last tick included), each call timed with the exact instruction counter:
//   float_step  core::MoveStepper<float>::step (single precision; only on a core with an FPU: the
//               Cortex-M0 runs the fixed-point evaluators, and its RAM holds one or the other)
//   fixed_at    fixed::Motion::at_tick (random access)
//   fixed_next  fixed::MotionStepper::next (p, v, a per tick)
//   fixed_pos   fixed::PositionStepper::next (position only: the servo loop's FixedEvaluation)
//   cam_<order>_at / cam_<order>_next   a cam table of the move (linear, cubic, quintic)
// Report evaluators-<board>.txt, one line per measurement:
//   cost <move> <evaluator> min <n> mean <n.nn> max <n> calls <n>
// and `built <move> ok|<status>` per move; the image fails if any build fails. Where there is an
// FPU, also `halt_plan <move> ok|<status>` and `cost <move> halt_plan ...`: the instructions of
// planning a halt of the unshaped S-curves half-way (core/online.hpp), and per tick of
// the planned blend as the servo loop streams it: `blend_float` (core::BasicBlend<float>::at, the
// FloatEvaluation<float>'s) and `blend_fixed_pos` (its fixed-point position plan, FixedEvaluation's).
#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "settle/core/fixed/cam.hpp"
#include "settle/core/fixed/golden.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/position.hpp"
#include "settle/core/stepper.hpp"
#include "settle/core/online.hpp"
#include "settle/firmware/instruction_counter.hpp"
#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/firmware/text.hpp"

namespace {

namespace fw = settle::firmware;
namespace core = settle::core;
namespace fx = settle::core::fixed;

constexpr std::string_view board{SETTLE_BOARD_NAME};

// Room for every move of the list (as golden.cpp sizes it), all static: the stack holds plan().
using CostMotion = fx::BasicMotion<16, 4>;
CostMotion g_motion{};
fx::MotionStepper<CostMotion::kMaxTracks> g_step{};
fx::BasicPositionPlan<16> g_plan{};
fx::PositionStepper g_pos{};
std::array<fx::CamKnot, 64> g_knots{};
fx::CamTable g_cam{};
fx::CamStepper g_cam_step{};
core::Move<double> g_move_d{};
#if defined(__ARM_FP)
constexpr bool kFloat = true;
core::Move<float> g_move_f{};
core::MoveStepper<float> g_step_f{};
volatile float g_sink_f{};
[[gnu::noinline]] void float_step() { g_sink_f = g_step_f.step().p; }
// A halt planned on the target (docs/online.md): the mode memory of the move half-way
// and the blend's search, as a servo loop's service() runs them. Only where there is an FPU: the
// plan is in double, and its ~10 KiB of stack is more than the micro:bit's image leaves.
core::Blend g_blend{};
core::BasicBlend<float> g_blend_f{};
float g_blend_dt{};
fx::BlendMotion g_blend_motion{};
fx::BasicPositionPlan<fx::position_intervals_for(fx::BlendMotion::kMaxSegments, fx::BlendMotion::kMaxTracks)> g_blend_plan{};
core::Mode g_halt_mode{};
core::OnlineLimits g_halt_limits{};
double g_halt_at{0.0};
volatile std::uint8_t g_halt_status{};
[[gnu::noinline]] void halt_plan() {
  core::OnlineRequest r{};
  core::Status st = core::online_request(g_move_d, g_halt_at, &g_halt_mode, 1, g_halt_limits, std::nullopt, r);
  // The blend search itself, as before the halt learnt to finish the move instead: without what the
  // running move does, a halt always plans its fastest blend (the cost measured here).
  r.running.reset();
  if (st == core::Status::ok) st = core::plan_online(r, g_blend);
  g_halt_status = static_cast<std::uint8_t>(st);
}
#else
constexpr bool kFloat = false;
#endif

// The tick at_tick() evaluates next; every body advances one tick per call.
std::int32_t g_n{0};
#if defined(__ARM_FP)
[[gnu::noinline]] void blend_float() { g_sink_f = g_blend_f.at(static_cast<float>(g_n++) * g_blend_dt).p; }
#endif
volatile std::int32_t g_sink_q{};

[[gnu::noinline]] void fixed_at() { g_sink_q = g_motion.at_tick(g_n++).p; }
[[gnu::noinline]] void fixed_next() { g_sink_q = g_step.next().p; }
[[gnu::noinline]] void fixed_pos() { g_sink_q = g_pos.next(); }
[[gnu::noinline]] void cam_at() { g_sink_q = g_cam.at_tick(g_n++).p; }
[[gnu::noinline]] void cam_next() { g_sink_q = g_cam_step.next().p; }

// The report file (image_main's), written a line at a time: RAM is for the stack plan() needs.
fw::semihosting::File* g_file{nullptr};

template <std::size_t N>
void write_line(const fw::Text<N>& line) {
  if (line.overflowed() || !g_file->write(line.view())) fw::fatal("evaluators: could not write the report\n", 2);
}

void report(const fw::InstructionCounter& counter, std::string_view move, std::string_view evaluator,
            void (*body)(), std::uint32_t calls) {
  g_n = 0;
  const fw::InstructionCost c = counter.measure(body, calls);
  fw::Text<96> line{};
  line.append("cost ").append(move).append(" ").append(evaluator).append(" min ").append_unsigned(c.min);
  line.append(" mean ").append_scaled(c.mean_centi, 2).append(" max ").append_unsigned(c.max);
  line.append(" calls ").append_unsigned(c.calls).append("\n");
  write_line(line);
}

// Builds and measures one move; its status (ok, or the first refusal).
core::Status measure_move(const fw::InstructionCounter& counter, const fx::GoldenMove& g) {
  core::Status st = fx::plan_golden(g, g_move_d);
  const fx::Scale scale = fx::golden_scale(g);
  if (st == core::Status::ok) st = g_motion.build(g_move_d, scale);
  if (st == core::Status::ok) st = g_plan.build(g_motion);
  if (st != core::Status::ok) return st;
  const std::string_view name{g.name};
  const auto calls = static_cast<std::uint32_t>(g_motion.end_tick() + 1);  // ticks 0 .. end_tick

#if defined(__ARM_FP)
  g_move_f = core::Move<float>{g_move_d};
  g_step_f = core::MoveStepper<float>{g_move_f, static_cast<float>(g.scale.period_s())};
  report(counter, name, "float_step", float_step, calls);
  // The halt plan of the undamped S-curve only (a plan is ~1e5 instructions; three calls).
  if (g.kind == core::ProfileKind::scurve && g.shaper == core::ShaperKind::none) {
    const core::Peaks<double>& pk = g_move_d.peaks();
    g_halt_mode = {g.omega, g.zeta};
    g_halt_limits = {1.2 * pk.v, 1.2 * pk.a, 1.2 * pk.j};
    g_halt_at = 0.5 * g_move_d.duration();
    halt_plan();
    fw::Text<96> line{};
    line.append("halt_plan ").append(name).append(" ")
        .append(core::to_string(static_cast<core::Status>(g_halt_status))).append("\n");
    write_line(line);
    if (g_halt_status == 0) {
      report(counter, name, "halt_plan", halt_plan, 3);
      const auto blend_calls = static_cast<std::uint32_t>(g_blend.duration() / g.scale.period_s()) + 2;
      g_blend_f = core::BasicBlend<float>{g_blend};
      g_blend_dt = static_cast<float>(g.scale.period_s());
      report(counter, name, "blend_float", blend_float, blend_calls);
      st = g_blend_motion.build(g_blend, scale);
      if (st == core::Status::ok) st = g_blend_plan.build(g_blend_motion);
      if (st != core::Status::ok) return st;
      g_pos = fx::PositionStepper{g_blend_plan};
      report(counter, name, "blend_fixed_pos", fixed_pos, blend_calls);
    }
  }
#endif
  report(counter, name, "fixed_at", fixed_at, calls);
  g_step = fx::MotionStepper<CostMotion::kMaxTracks>{g_motion};
  report(counter, name, "fixed_next", fixed_next, calls);
  g_pos = fx::PositionStepper{g_plan};
  report(counter, name, "fixed_pos", fixed_pos, calls);

  constexpr struct {
    fx::CamOrder order;
    std::string_view at, next;
  } kCams[] = {{fx::CamOrder::linear, "cam_linear_at", "cam_linear_next"},
               {fx::CamOrder::cubic, "cam_cubic_at", "cam_cubic_next"},
               {fx::CamOrder::quintic, "cam_quintic_at", "cam_quintic_next"}};
  for (const auto& cam : kCams) {
    // The finest knot spacing the 64 knots allow; the tolerance only has to accept it (the cost
    // per tick does not depend on the spacing; the accuracy is the unit suite's business).
    st = fx::build_cam_table(g_move_d, scale, cam.order, g_knots, g_cam, 1e9);
    if (st != core::Status::ok) return st;
    const auto cam_calls = static_cast<std::uint32_t>(g_cam.end_tick() + 1);
    report(counter, name, cam.at, cam_at, cam_calls);
    g_cam_step = fx::CamStepper{g_cam};
    report(counter, name, cam.next, cam_next, cam_calls);
  }
  return core::Status::ok;
}

}  // namespace

int settle::firmware::image_main() {
  const InstructionCounter counter{InstructionCounter::calibrate()};
  if (!counter.exact()) fatal("evaluators: the instruction counter is not exact (QEMU needs -icount shift=7)\n", 3);
  Text<40> name{};
  name.append("evaluators-").append(board).append(".txt");
  semihosting::File file{semihosting::File::open(name.view(), semihosting::OpenMode::write)};
  g_file = &file;
  Text<96> line{};
  line.append("board ").append(board).append(" float ").append(kFloat ? "yes" : "no").append("\n");
  write_line(line);
  bool all_built = true;
  for (const fx::GoldenMove& g : fx::golden_moves()) {
    const core::Status st = measure_move(counter, g);
    line.clear();
    line.append("built ").append(g.name).append(" ").append(core::to_string(st)).append("\n");
    write_line(line);
    all_built = all_built && st == core::Status::ok;
  }
  line.clear();
  line.append("stack_high_water ").append_unsigned(stack_high_water()).append(" of ");
  line.append_unsigned(stack_size()).append("\n");
  write_line(line);
  if (!file.close()) fatal("evaluators: could not write the report\n", 2);
  return all_built ? 0 : 1;
}
