#pragma once
// Online changes in the servo loop (issue 17): halt() and retarget() post a command into a
// per-axis single-producer mailbox from any context, lock-free; ServoLoop::service(), outside the
// tick, plans the blend (core/online.hpp) for a switch a few ticks ahead and hands it over with one
// atomic flag; the tick switches to it at exactly that setpoint index, so p, v, a are continuous.
// Nothing here allocates or throws; the tick only loads a flag and compares an index.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "settle/core/online.hpp"

namespace settle::firmware {

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

// What an axis's blends respect: the modes to leave at rest and the limits (move units).
struct OnlineConfig {
  std::array<core::Mode, core::kMaxOnlineModes> modes{};
  std::size_t mode_count{0};
  core::OnlineLimits limits{};
};

// Setpoint indices between the command's service() and the switch: the blend is ready before the
// tick reaches its index as long as service() runs within this many periods of the last tick.
inline constexpr std::int32_t kOnlineLeadTicks = 2;

// Per-axis state of online changes. `ready` hands the blend from service() (which writes blend and
// switch_index first) to the tick (which reads them only after seeing ready = 1, and sets it back
// to 0 when it has switched or discarded it).
struct OnlineSlot {
  OnlineMailbox<4> mailbox{};
  OnlineConfig config{};
  bool configured{false};
  core::Blend blend{};
  std::int32_t switch_index{0};
  std::atomic<std::uint8_t> ready{0};
  std::atomic<std::int32_t> move_index{0};  // setpoints the active move has produced (the tick's)
  std::atomic<std::uint32_t> move_serial{0};  // moves started (the tick's)
  std::uint32_t blend_serial{0};  // the move_serial the blend was planned for (service()'s)
  std::atomic<std::uint32_t> switches{0};   // blends the tick switched to (for the application)
  std::atomic<std::uint32_t> missed{0};     // blends discarded: the move ended or passed the index
  // The tick's own: the blend being streamed.
  bool running{false};
  std::int32_t index{0};  // setpoints of the blend produced so far
  std::int32_t origin{0};  // counts at the active move's start
  double counts_per_unit{1.0};
  double period_s{0.0};
};

struct NoOnline {};

}  // namespace settle::firmware
