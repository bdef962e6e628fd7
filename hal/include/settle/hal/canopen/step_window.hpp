// SPDX-License-Identifier: Apache-2.0
// The drive's motion bound over time: however its SYNCs arrive, the axis never moves more than
// the step limit (0x607F x period) within one period.
//
// The step limit alone bounds each SYNC's step. A bus that delivers two of the master's SYNC+RPDO
// pairs within one period (a delayed queue flushing, a replay catching up) would then move the
// axis two steps in one period, twice the drive's maximum velocity. The window remembers the last
// few setpoints applied and when, and bounds a new setpoint to within
// the limit of every setpoint applied less than `window_us` before it and of the one the axis
// held at that time (the latest applied at least `window_us` before). A setpoint beyond the bound
// is not refused (the master's own late periods are not an error): the axis moves as far towards
// it as the bound allows and catches up at the next SYNCs, as a drive's velocity limit does.
//
// Times are when the axis moves for each SYNC (DriveNodeConfig::axis_moves_one_period_per_sync
// says which clock that is).
// Allocation-free and small (36 bytes: it lives in the drive node on a Cortex-M0); positions
// wrap like the drive's 32-bit counter (differences the short way), times are kept as their low
// 32 bits of microseconds (ages compared modulo 2^32, so windows up to 35 minutes).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace settle::hal::canopen {

class StepWindow {
 public:
  // Setpoints remembered one by one. A burst of more SYNCs than this within one window folds
  // the oldest into a range (lowest and highest) that bounds like all of them together, so the
  // bound stays strict however long the burst; at worst it holds back more than it must.
  static constexpr std::size_t capacity = 4;

  // Forget everything: the axis is at `position` since `time_us` (enabling latches it).
  void reset(std::uint64_t time_us, std::int32_t position) noexcept {
    count_ = 0;
    spilled_ = false;
    push(time_us, position, 0);
  }

  // The setpoint nearest `target` that keeps the bound, for a SYNC whose period runs at `time_us`.
  // `limit` >= 0 counts. Without any history the target is returned unchanged; if the
  // remembered setpoints left no room (they cannot, but a hostile input is not trusted to
  // prove it), the last one, so the axis holds.
  [[nodiscard]] std::int32_t bound(std::uint64_t time_us, std::int32_t target, std::int64_t limit,
                                   std::uint32_t window_us) const noexcept {
    if (count_ == 0) return target;
    const std::int32_t last = at(0).position;
    // Offsets from the last applied setpoint, so the counter's wrap never matters.
    std::int64_t lo = -limit;
    std::int64_t hi = limit;
    const auto keep_within = [&](std::int32_t position) {
      const std::int64_t d = difference(position, last);
      if (d - limit > lo) lo = d - limit;
      if (d + limit < hi) hi = d + limit;
    };
    bool anchored = age(at(0), time_us) >= window_us;
    for (std::size_t i = 1; i < count_ && !anchored; ++i) {
      // Entry i-1 is inside the window, so entry i counts: inside too, or the one held then.
      keep_within(at(i).position);
      anchored = age(at(i), time_us) >= window_us;
    }
    if (!anchored && spilled_) {  // the held setpoint is among the folded ones
      keep_within(spill_low_);
      keep_within(spill_high_);
    }
    if (lo > hi) return last;
    std::int64_t want = difference(target, last);
    if (want < lo) want = lo;
    if (want > hi) want = hi;
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(last) +
                                     static_cast<std::uint32_t>(static_cast<std::int32_t>(want)));
  }

  // Records a setpoint applied for a SYNC whose period runs at `time_us` (window as for bound()).
  void push(std::uint64_t time_us, std::int32_t position, std::uint32_t window_us) noexcept {
    if (count_ == capacity) {
      // The oldest leaves. Once the next oldest is a window old, nothing older can ever count
      // again (windows only move forward); until then it joins the folded range.
      if (age(at(capacity - 2), time_us) >= window_us) {
        spilled_ = false;
      } else {
        fold(at(capacity - 1).position);
      }
    }
    head_ = static_cast<std::uint8_t>((head_ + 1U) % capacity);
    entries_[head_] = Entry{static_cast<std::uint32_t>(time_us), position};
    if (count_ < capacity) ++count_;
  }

  [[nodiscard]] std::size_t size() const noexcept { return count_; }

 private:
  struct Entry {
    std::uint32_t time_us{0};  // low 32 bits
    std::int32_t position{0};
  };
  [[nodiscard]] static std::uint64_t age(const Entry& e, std::uint64_t now_us) noexcept {
    return static_cast<std::uint32_t>(static_cast<std::uint32_t>(now_us) - e.time_us);
  }
  // 0 = the newest.
  [[nodiscard]] const Entry& at(std::size_t age) const noexcept {
    return entries_[(head_ + capacity - age) % capacity];
  }
  [[nodiscard]] static std::int64_t difference(std::int32_t a, std::int32_t b) noexcept {
    return std::int64_t{static_cast<std::int32_t>(static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b))};
  }
  void fold(std::int32_t position) noexcept {
    if (!spilled_) {
      spilled_ = true;
      spill_low_ = spill_high_ = position;
    } else if (difference(position, spill_low_) < 0) {
      spill_low_ = position;
    } else if (difference(position, spill_high_) > 0) {
      spill_high_ = position;
    }
  }

  std::array<Entry, capacity> entries_{};
  std::int32_t spill_low_{0};
  std::int32_t spill_high_{0};
  std::uint8_t head_{0};
  std::uint8_t count_{0};
  bool spilled_{false};
};

}  // namespace settle::hal::canopen
