// SPDX-License-Identifier: Apache-2.0
#pragma once
// The setpoints ServoLoop streams for one move and the online changes switched into it, offline:
// the loop's switch-to-blend rule (next_setpoint() in servo_loop.hpp) stated once for everything
// that must predict what the loop sends (the stream runner's replay, the tests). The rule: a
// command (the move, or a blend) streams its setpoints 0, 1, 2, ... until its last; a change
// planned for switch index k replaces the command's setpoint k and everything after it with the
// blend's setpoints 0, 1, 2, ..., the blend's setpoint i at k + i on the clock of what it changes
// (the move's, or for a change of a running blend, that blend's), with the move's origin. A change
// whose index the command ends before (or has passed) is missed, and the command streams to its end.
// Freestanding: no allocation, no exceptions; the caller holds the prepared move and blends (a
// fixed-point one is a few KiB) and receives each setpoint through `sink`.
#include <cstddef>
#include <cstdint>

#include "settle/runtime/evaluation.hpp"

namespace settle::runtime {

// One change: the blend prepared in the evaluation's scalar (Evaluation::prepare(blend, ...)), and
// the setpoint index of the running command at which the loop switches to it (ServoLoop: the
// index at service() plus the configuration's lead_ticks).
template <typename Evaluation>
struct SetpointSwitch {
  typename Evaluation::BlendStored* blend{nullptr};
  std::int32_t at{0};
};

struct SetpointSequence {
  std::size_t setpoints{0};  // given to the sink
  std::size_t switches{0};   // changes switched in, in order; the rest were missed
  bool ended{false};         // the last command reached its end (false: cut at max_setpoints)
};

// Streams the prepared `move` from `origin` counts, switching to switches[0..switch_count) in
// order (each `at` on the clock of the command it changes), and hands each setpoint to
// sink(std::int32_t), at most max_setpoints of them. Streams each prepared object once, as the
// loop does (a fixed-point one steps in place: prepare it again to stream it again).
template <typename Evaluation, typename Sink>
[[nodiscard]] SetpointSequence stream_setpoints(typename Evaluation::Stored& move, std::int32_t origin,
                                                const SetpointSwitch<Evaluation>* switches, std::size_t switch_count,
                                                std::size_t max_setpoints, Sink&& sink) noexcept {
  SetpointSequence out{};
  typename Evaluation::Stream m = Evaluation::start(move, origin);
  typename Evaluation::BlendStream b{};
  bool on_blend = false;
  std::int32_t index = 0;  // setpoints the running command has produced
  for (bool last = false; !last;) {
    if (out.setpoints == max_setpoints) return out;
    if (out.switches < switch_count && index == switches[out.switches].at) {
      b = Evaluation::start(*switches[out.switches].blend, origin);
      on_blend = true;
      index = 0;
      ++out.switches;
    }
    sink(on_blend ? b.next(last) : m.next(last));
    ++out.setpoints;
    ++index;
  }
  out.ended = true;
  return out;
}

}  // namespace settle::runtime
