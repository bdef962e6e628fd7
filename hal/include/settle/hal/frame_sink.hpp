// SPDX-License-Identifier: Apache-2.0
// Where I/O-free protocol code puts the frames it produces. A bus is a sink (frames go to the
// wire), a FrameBuffer is a sink (tests and callers that batch), so protocol objects never
// need to know which one they are talking to.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "settle/hal/can_frame.hpp"

namespace settle::hal {

class FrameSink {
 public:
  FrameSink() = default;
  FrameSink(const FrameSink&) = default;
  FrameSink& operator=(const FrameSink&) = default;
  virtual ~FrameSink() = default;

  // False when the frame was not taken (queue full, bus busy): the producer decides whether
  // that matters, the sink never blocks to make room.
  [[nodiscard]] virtual bool put(const CanFrame& frame) noexcept = 0;
};

// A fixed-capacity list of frames, in the order they were put; overflow is counted, not hidden.
template <std::size_t N>
class FrameBuffer final : public FrameSink {
 public:
  [[nodiscard]] bool put(const CanFrame& frame) noexcept override {
    if (count_ == N) {
      ++overflows_;
      return false;
    }
    frames_[count_++] = frame;
    return true;
  }

  [[nodiscard]] std::span<const CanFrame> frames() const noexcept { return {frames_.data(), count_}; }
  [[nodiscard]] std::size_t size() const noexcept { return count_; }
  [[nodiscard]] bool empty() const noexcept { return count_ == 0; }
  [[nodiscard]] const CanFrame& operator[](std::size_t i) const noexcept { return frames_[i]; }
  [[nodiscard]] std::uint32_t overflows() const noexcept { return overflows_; }
  void clear() noexcept {
    count_ = 0;
    overflows_ = 0;
  }

 private:
  std::array<CanFrame, N> frames_{};
  std::size_t count_{0};
  std::uint32_t overflows_{0};
};

}  // namespace settle::hal
