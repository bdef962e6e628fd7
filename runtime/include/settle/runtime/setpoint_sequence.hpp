// SPDX-License-Identifier: Apache-2.0
#pragma once
// The setpoints ServoLoop streams for one move and the online changes switched into it, stated
// once: SetpointStepper is the per-tick step that ServoLoop's tick and stream_setpoints (offline:
// the stream runner's replay, the tests) both drive, so that what is predicted is what is sent. The
// rule: a command (the move, or a blend) streams its setpoints 0, 1, 2, ... until its last; a change
// planned for switch index k replaces the command's setpoint k and everything after it with the
// blend's setpoints 0, 1, 2, ..., the blend's setpoint i at k + i on the clock of what it changes
// (the move's, or for a change of a running blend, that blend's), with the move's origin. A change
// whose index the command ends before (or has passed) is missed, and the command streams to its end.
// A halt whose best is to finish what runs (no blend) is met at its index and changes nothing.
// Freestanding: no allocation, no exceptions; the caller holds the prepared move and blends (a
// fixed-point one is a few KiB) and receives each setpoint through `sink`.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "settle/runtime/evaluation.hpp"

namespace settle::runtime {

// Where a change planned for setpoint `at` of the running command stands, before this tick's setpoint.
enum class SwitchPoint : std::uint8_t {
  ahead,   // the command has not reached `at` yet: wait
  due,     // this tick's setpoint is the command's `at`: switch now
  passed,  // the command is past `at`: the change is missed
};

// The next setpoint, tick by tick. start() begins a move; before each next(), offer() a pending
// change (its switch index on the running command's clock); when it is due, the blend's setpoint 0
// is the next one. Changes = false (a loop without online changes) keeps only the move's stream:
// next() is the evaluation's, nothing more.
template <typename Evaluation, bool Changes = true>
class SetpointStepper {
 public:
  // The move's setpoint 0 is the next; `origin`: the counts it (and every blend of it) starts from.
  void start(typename Evaluation::Stored& move, std::int32_t origin) noexcept {
    move_ = Evaluation::start(move, origin);
    if constexpr (Changes) {
      c_.origin = origin;
      c_.on_blend = false;
      c_.index.store(0, std::memory_order_relaxed);
    }
  }
  // The change planned for the running command's setpoint `at`: switched to `blend` when due (a null
  // blend, a halt that finishes what runs, switches nothing). Returns where it stood.
  SwitchPoint offer(std::int32_t at, typename Evaluation::BlendStored* blend) noexcept {
    static_assert(Changes, "a stepper without changes takes none");
    const std::int32_t k = c_.index.load(std::memory_order_relaxed);
    if (k != at) return k < at ? SwitchPoint::ahead : SwitchPoint::passed;
    if (blend != nullptr) {
      c_.blend = Evaluation::start(*blend, c_.origin);
      c_.on_blend = true;
      c_.index.store(0, std::memory_order_relaxed);
    }
    return SwitchPoint::due;
  }
  // The running command's next setpoint; `last`: it is the command's final one.
  [[nodiscard]] std::int32_t next(bool& last) noexcept {
    if constexpr (Changes) {
      c_.index.store(c_.index.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      if (c_.on_blend) return c_.blend.next(last);
    }
    return move_.next(last);
  }
  // The command is over (ended or abandoned): no blend runs until the next start().
  void end() noexcept {
    if constexpr (Changes) c_.on_blend = false;
  }
  // Whether a blend runs, and the setpoints the running command has produced (its clock). Read by
  // ServoLoop::service() between ticks.
  [[nodiscard]] bool on_blend() const noexcept {
    if constexpr (Changes) return c_.on_blend;
    return false;
  }
  [[nodiscard]] std::int32_t index() const noexcept {
    if constexpr (Changes) return c_.index.load(std::memory_order_acquire);
    return 0;
  }

 private:
  struct Change {
    typename Evaluation::BlendStream blend{};
    std::atomic<std::int32_t> index{0};
    std::int32_t origin{0};
    bool on_blend{false};
  };
  struct NoChange {};
  typename Evaluation::Stream move_{};
  [[no_unique_address]] std::conditional_t<Changes, Change, NoChange> c_{};
};

// One change: the blend prepared in the evaluation's scalar (Evaluation::prepare(blend, ...)), or
// null for a halt that finishes what runs, and the setpoint index of the running command at which
// the loop switches to it (ServoLoop: the index at service() plus the configuration's lead_ticks).
template <typename Evaluation>
struct SetpointSwitch {
  typename Evaluation::BlendStored* blend{nullptr};
  std::int32_t at{0};
};

struct SetpointSequence {
  std::size_t setpoints{0};  // given to the sink
  std::size_t switches{0};   // changes met at their index, in order; the rest were missed
  bool ended{false};         // the last command reached its end (false: cut at max_setpoints)
};

// Streams the prepared `move` from `origin` counts, offering switches[0..switch_count) in order
// (each `at` on the clock of the command it changes) to the stepper the loop's tick drives, and
// hands each setpoint to sink(std::int32_t), at most max_setpoints of them. Streams each prepared
// object once, as the loop does (a fixed-point one steps in place: prepare it again to stream it again).
template <typename Evaluation, typename Sink>
[[nodiscard]] SetpointSequence stream_setpoints(typename Evaluation::Stored& move, std::int32_t origin,
                                                const SetpointSwitch<Evaluation>* switches, std::size_t switch_count,
                                                std::size_t max_setpoints, Sink&& sink) noexcept {
  SetpointSequence out{};
  SetpointStepper<Evaluation> stepper{};
  stepper.start(move, origin);
  for (bool last = false; !last;) {
    if (out.setpoints == max_setpoints) return out;
    if (out.switches < switch_count &&
        stepper.offer(switches[out.switches].at, switches[out.switches].blend) == SwitchPoint::due) {
      ++out.switches;
    }
    sink(stepper.next(last));
    ++out.setpoints;
  }
  out.ended = true;
  return out;
}

}  // namespace settle::runtime
