#pragma once
// A bounded FIFO of prepared moves per axis (core Moves, or their fixed-point form): the next
// moves are planned and prepared outside the tick while the current one runs. Fixed capacity, no heap; the front slot is never overwritten while it is
// the active move, so a stepper may keep a pointer into it.
#include <array>
#include <cstddef>


namespace settle::firmware {

template <typename Element, std::size_t Capacity>
class MoveQueue {
 public:
  static_assert(Capacity > 0);

  // The free slot at the back, for preparing an element in place (no copy, no extra storage);
  // it joins the queue only with commit_back(). Requires !full().
  [[nodiscard]] Element& back_slot() noexcept { return slots_[(head_ + size_) % Capacity]; }
  void commit_back() noexcept {
    if (size_ < Capacity) ++size_;
  }
  [[nodiscard]] const Element& front() const noexcept { return slots_[head_]; }
  void pop() noexcept {
    if (size_ == 0) return;
    head_ = (head_ + 1) % Capacity;
    --size_;
  }
  void clear() noexcept {
    head_ = 0;
    size_ = 0;
  }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] bool full() const noexcept { return size_ == Capacity; }

 private:
  std::array<Element, Capacity> slots_{};
  std::size_t head_{0};
  std::size_t size_{0};
};

}  // namespace settle::firmware
