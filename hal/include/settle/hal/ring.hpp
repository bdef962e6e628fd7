// SPDX-License-Identifier: Apache-2.0
// Fixed-capacity FIFO over storage the owner provides, so queues in the HAL never allocate
// and a bare-metal target decides where (and how large) each queue lives.
#pragma once

#include <cstddef>
#include <span>

namespace settle::hal {

// Extent: the capacity when the owner fixes it at compile time (a controller's mailboxes, a
// queue over its own array), so that wrapping and fullness compare with a constant; or
// std::dynamic_extent for storage sized at run time.
template <typename T, std::size_t Extent = std::dynamic_extent>
class Ring {
 public:
  Ring() = default;
  explicit Ring(std::span<T, Extent> storage) noexcept : storage_{storage} {}

  [[nodiscard]] bool push(const T& value) noexcept {
    if (full()) {
      return false;
    }
    back_slot() = value;
    commit_back();
    return true;
  }

  // The free slot after the newest element, to build an element in place (no copy, no second
  // buffer); it joins the ring only with commit_back(). Only valid when !full().
  [[nodiscard]] T& back_slot() noexcept {
    std::size_t tail = head_ + size_;
    if (tail >= storage_.size()) {
      tail -= storage_.size();
    }
    return storage_[tail];
  }
  void commit_back() noexcept {
    if (size_ < storage_.size()) {
      ++size_;
    }
  }

  [[nodiscard]] bool pop(T& out) noexcept {
    if (size_ == 0) {
      return false;
    }
    out = storage_[head_];
    drop_front();
    return true;
  }

  // The oldest element; only valid when !empty().
  [[nodiscard]] const T& front() const noexcept { return storage_[head_]; }
  // The i-th oldest element (at(0) is front()); only valid when i < size().
  [[nodiscard]] const T& at(std::size_t i) const noexcept {
    std::size_t index = head_ + i;
    if (index >= storage_.size()) {
      index -= storage_.size();
    }
    return storage_[index];
  }
  [[nodiscard]] T& front() noexcept { return storage_[head_]; }

  void drop_front() noexcept {
    if (size_ == 0) {
      return;
    }
    ++head_;
    if (head_ == storage_.size()) {
      head_ = 0;
    }
    --size_;
  }
  // Drops the n oldest elements (all of them when n > size()).
  void drop_front(std::size_t n) noexcept {
    if (n > size_) {
      n = size_;
    }
    head_ += n;
    if (head_ >= storage_.size()) {
      head_ -= storage_.size();
    }
    size_ -= n;
  }

  void clear() noexcept {
    head_ = 0;
    size_ = 0;
  }

  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return storage_.size(); }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] bool full() const noexcept { return size_ == storage_.size(); }

 private:
  std::span<T, Extent> storage_{};
  std::size_t head_{0};
  std::size_t size_{0};
};

}  // namespace settle::hal
