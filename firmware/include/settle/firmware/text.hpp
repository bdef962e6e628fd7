// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fixed-capacity text building for images: numbers and strings into a stack buffer, without
// printf (newlib's stdio allocates, and the image links no heap).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace settle::firmware {

template <std::size_t Capacity>
class Text {
 public:
  // Appends as much as fits; overflowed() tells whether anything was cut.
  Text& append(std::string_view text) {
    for (const char c : text) {
      put(c);
    }
    return *this;
  }

  Text& append_unsigned(std::uint64_t value) {
    std::array<char, 20> digits{};
    std::size_t count{0};
    do {
      digits[count++] = static_cast<char>('0' + value % 10U);
      value /= 10U;
    } while (value != 0U);
    while (count > 0U) {
      put(digits[--count]);
    }
    return *this;
  }

  Text& append_signed(std::int64_t value) {
    if (value < 0) {
      put('-');
      // Negate in unsigned arithmetic so that INT64_MIN is printed correctly.
      return append_unsigned(0U - static_cast<std::uint64_t>(value));
    }
    return append_unsigned(static_cast<std::uint64_t>(value));
  }

  // value / 10^decimals with exactly `decimals` digits after the point (no float formatting).
  Text& append_scaled(std::int64_t value, unsigned decimals) {
    std::uint64_t scale{1};
    for (unsigned i{0}; i < decimals; ++i) {
      scale *= 10U;
    }
    if (value < 0) {
      put('-');
    }
    const std::uint64_t magnitude{value < 0 ? 0U - static_cast<std::uint64_t>(value)
                                            : static_cast<std::uint64_t>(value)};
    append_unsigned(magnitude / scale);
    if (decimals > 0U) {
      put('.');
      std::uint64_t fraction{magnitude % scale};
      for (unsigned i{0}; i < decimals; ++i) {
        scale /= 10U;
        put(static_cast<char>('0' + fraction / scale));
        fraction %= scale;
      }
    }
    return *this;
  }

  // Upper-case hex, zero-padded to `width` digits (candump writes ids and data this way).
  Text& append_hex(std::uint32_t value, unsigned width) {
    for (unsigned i{width}; i > 0U; --i) {
      const unsigned nibble{(value >> (4U * (i - 1U))) & 0xFU};
      put("0123456789ABCDEF"[nibble]);
    }
    return *this;
  }

  [[nodiscard]] std::string_view view() const { return {buffer_.data(), size_}; }
  [[nodiscard]] bool overflowed() const { return overflowed_; }
  void clear() {
    size_ = 0;
    overflowed_ = false;
  }

 private:
  void put(char c) {
    if (size_ < Capacity) {
      buffer_[size_++] = c;
    } else {
      overflowed_ = true;
    }
  }

  std::array<char, Capacity> buffer_{};
  std::size_t size_{0};
  bool overflowed_{false};
};

}  // namespace settle::firmware
