// SPDX-License-Identifier: Apache-2.0
#pragma once
// A queue that owns its fixed storage: hal's Ring over an array member. The servo loop keeps each
// axis's prepared moves in one (the next moves are planned and prepared outside the tick while
// the current one runs; the front is never overwritten while it is the active move, so a stepper
// may keep a pointer into it) and the feedback samples it has received in another.
#include <array>
#include <cstddef>

#include "settle/hal/ring.hpp"

namespace settle::runtime {

template <typename T, std::size_t Capacity>
class FixedQueue {
 public:
  static_assert(Capacity > 0);

  FixedQueue() = default;
  // The ring refers to this object's own array: it must stay where it was built.
  FixedQueue(const FixedQueue&) = delete;
  FixedQueue& operator=(const FixedQueue&) = delete;

  [[nodiscard]] bool push(const T& value) noexcept { return ring_.push(value); }
  [[nodiscard]] bool pop(T& out) noexcept { return ring_.pop(out); }
  // Build in place, then commit: see hal::Ring::back_slot. Only valid when !full().
  [[nodiscard]] T& back_slot() noexcept { return ring_.back_slot(); }
  void commit_back() noexcept { ring_.commit_back(); }
  [[nodiscard]] const T& front() const noexcept { return ring_.front(); }
  [[nodiscard]] T& front() noexcept { return ring_.front(); }
  void drop_front() noexcept { ring_.drop_front(); }
  void clear() noexcept { ring_.clear(); }
  [[nodiscard]] std::size_t size() const noexcept { return ring_.size(); }
  [[nodiscard]] bool empty() const noexcept { return ring_.empty(); }
  [[nodiscard]] bool full() const noexcept { return ring_.full(); }

 private:
  std::array<T, Capacity> storage_{};
  hal::Ring<T, Capacity> ring_{storage_};
};

}  // namespace settle::runtime
