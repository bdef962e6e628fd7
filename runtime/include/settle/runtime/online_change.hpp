// SPDX-License-Identifier: Apache-2.0
#pragma once
// Online changes in the servo loop: halt() and retarget() post a command into a
// per-axis single-producer mailbox from any context, lock-free; ServoLoop::service(), outside the
// tick, plans the blend (core/online.hpp) for a switch a few ticks ahead and hands it over with one
// atomic flag; the tick switches to it at exactly that setpoint index, so p, v, a are continuous.
// The blend is evaluated in the loop's scalar (evaluation.hpp: prepare(blend), start()), as every
// move is. Nothing here allocates or throws; the tick only loads a flag and compares an index.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "settle/core/online.hpp"

// Compile-time switch: 0 leaves online changes out of every ServoLoop (a loop that asks for them
// does not compile). Default 0 on M-profile cores without an FPU (the Cortex-M0: planning a blend
// takes ~10 KiB of stack in soft double, and the fixed-point blend slots 3.3 KiB per axis, more than
// the micro:bit's 16 KiB of RAM leave next to the loop), 1 everywhere else (docs/online.md).
#ifndef SETTLE_ONLINE_CHANGES
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && !defined(__ARM_FP)
#define SETTLE_ONLINE_CHANGES 0
#else
#define SETTLE_ONLINE_CHANGES 1
#endif
#endif

namespace settle::runtime {

inline constexpr bool kOnlineChangesAvailable = SETTLE_ONLINE_CHANGES != 0;

enum class OnlineKind : std::uint8_t { halt, retarget };

struct OnlineCommand {
  OnlineKind kind{OnlineKind::halt};
  double target{0.0};  // retarget: the new distance from the running move's start, move units
};

// Single producer (halt()/retarget()), single consumer (service()): a ring of Capacity commands
// indexed by two free-running counters, each written by one side only.
template <std::size_t Capacity = 4>
class OnlineMailbox {
  static_assert(Capacity > 0 && (Capacity & (Capacity - 1)) == 0, "a power of two");

 public:
  // Producer. False when full: the command is not taken (nothing is overwritten).
  [[nodiscard]] bool post(const OnlineCommand& c) noexcept {
    const std::uint32_t h = head_.load(std::memory_order_relaxed);
    if (h - tail_.load(std::memory_order_acquire) >= Capacity) return false;
    slots_[h % Capacity] = c;
    head_.store(h + 1, std::memory_order_release);
    return true;
  }
  // Consumer: the command take() would return, left in place. False when empty.
  [[nodiscard]] bool peek(OnlineCommand& out) const noexcept {
    const std::uint32_t t = tail_.load(std::memory_order_relaxed);
    if (t == head_.load(std::memory_order_acquire)) return false;
    out = slots_[t % Capacity];
    return true;
  }
  // Consumer. False when empty.
  [[nodiscard]] bool take(OnlineCommand& out) noexcept {
    const std::uint32_t t = tail_.load(std::memory_order_relaxed);
    if (t == head_.load(std::memory_order_acquire)) return false;
    out = slots_[t % Capacity];
    tail_.store(t + 1, std::memory_order_release);
    return true;
  }

 private:
  std::array<OnlineCommand, Capacity> slots_{};
  std::atomic<std::uint32_t> head_{0};
  std::atomic<std::uint32_t> tail_{0};
};

// Setpoint indices between the command's service() and the switch, by default: the blend is ready
// before the tick reaches its index as long as service() completes within this many periods of the
// last tick (a host plans a halt in ~20 us; a Cortex-M4F needs ~3.2 M instructions, docs/online.md).
inline constexpr std::int32_t kOnlineLeadTicks = 2;

// What an axis's blends respect: the modes to leave at rest and the limits (move units), and how
// many setpoints ahead of the running command service() plans the switch (at least 1).
struct OnlineConfig {
  std::array<core::Mode, core::kMaxOnlineModes> modes{};
  std::size_t mode_count{0};
  core::OnlineLimits limits{};
  std::int32_t lead_ticks{kOnlineLeadTicks};
  // The axis is one of a path's (multi-axis path sync: its move D_i s(t), its modes the path's, its
  // limits the path's times |D_i|): when every such axis's halt, or retarget on the line, waits
  // for the same setpoint, service() plans it once for all and scales it to each
  // (core::plan_path_online), so that they come to rest at the same instant on the line.
  bool path{false};
};

// A queued move as its changes need it: the move as planned (its state and mode memory at a
// switch) and each configured mode's memory at its end (core::end_memory: whether finishing it
// leaves the mode at rest), which no switch time changes: taken once, at submit, for the axis's
// online configuration `config` (OnlineSlot::config_serial; 0: none), and again by a change only
// if the axis was configured since.
struct OnlineQueued {
  core::Move<double> move{};
  core::EndMemory end{};
  std::uint32_t config{0};
};

// Per-axis state of online changes. `ready` hands the blend from service() (which writes its slot,
// switch_index, from_blend and blend_serial first) to the tick (which reads them only after seeing
// ready = 1, and sets it back to 0 when it has switched or discarded it). Two slots: a second
// change is planned while the first one's blend is streamed from the other.
template <typename Evaluation>
struct OnlineSlot {
  OnlineMailbox<4> mailbox{};
  OnlineConfig config{};
  bool configured{false};
  std::uint32_t config_serial{0};  // configure_online's calls: which configuration an end memory is for
  std::array<core::OnlineRequest, 2> request{};  // what each slot's blend was planned from (its start's memory)
  std::array<core::Blend, 2> blend{};            // as planned, in double (service()'s)
  std::array<typename Evaluation::BlendStored, 2> evaluated{};  // the same in the loop's scalar
  std::uint8_t slot{0};        // the slot of the blend handed over with ready
  // The halt is the running command itself (core::OnlineChoice::finish: no blend stops short of its
  // target and before its end): at switch_index the tick keeps streaming it and only marks it
  // halting; nothing queued behind it runs.
  bool finish{false};
  bool from_blend{false};      // switch_index counts the running blend's setpoints, not the move's
  std::int32_t switch_index{0};
  std::atomic<std::uint8_t> ready{0};
  std::atomic<std::uint32_t> move_serial{0};  // moves started (the tick's)
  // The move_serial (from_blend: the switches count) the blend was planned for (service()'s).
  std::uint32_t blend_serial{0};
  std::atomic<std::uint32_t> switches{0};   // blends the tick switched to (for the application)
  std::atomic<std::uint32_t> finishes{0};   // halts that finish the running command instead
  std::atomic<std::uint32_t> missed{0};     // blends discarded: the move ended or passed the index
  // The tick's own (the blend itself is streamed by ServoLoop's SetpointStepper, setpoint_sequence.hpp).
  bool halting{false};        // the running move or blend is a halt's finish: void the queue at its end
  std::uint8_t streaming{0};  // the running blend's slot
  double period_s{0.0};
};

struct NoOnline {};

}  // namespace settle::runtime
