// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/candump_log.hpp"

namespace settle::hal {

namespace {

constexpr std::array<char, 16> hex_digits{'0', '1', '2', '3', '4', '5', '6', '7',
                                          '8', '9', 'A', 'B', 'C', 'D', 'E', 'F'};

// Appends to a fixed buffer and remembers whether anything did not fit.
class Writer {
 public:
  explicit Writer(std::span<char> out) noexcept : out_{out} {}
  void put(char c) noexcept {
    if (pos_ < out_.size()) {
      out_[pos_] = c;
    } else {
      overflow_ = true;
    }
    ++pos_;
  }
  void put_hex(std::uint64_t value, int digits) noexcept {
    for (int d = digits - 1; d >= 0; --d) {
      put(hex_digits[(value >> (4 * d)) & 0x0FU]);
    }
  }
  void put_decimal(std::uint64_t value, int min_digits) noexcept {
    std::array<char, 20> tmp{};
    int n = 0;
    do {
      tmp[static_cast<std::size_t>(n++)] = static_cast<char>('0' + value % 10U);
      value /= 10U;
    } while (value != 0 || n < min_digits);
    while (n > 0) {
      put(tmp[static_cast<std::size_t>(--n)]);
    }
  }
  [[nodiscard]] std::size_t finish() const noexcept { return overflow_ ? 0 : pos_; }

 private:
  std::span<char> out_;
  std::size_t pos_{0};
  bool overflow_{false};
};

[[nodiscard]] int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') {
    return c - '0';
  }
  if (c >= 'A' && c <= 'F') {
    return c - 'A' + 10;
  }
  if (c >= 'a' && c <= 'f') {
    return c - 'a' + 10;
  }
  return -1;
}

// A cursor over the line being parsed.
class Reader {
 public:
  explicit Reader(std::span<const char> in) noexcept : in_{in} {
    while (!in_.empty() && (in_.back() == '\n' || in_.back() == '\r')) {
      in_ = in_.first(in_.size() - 1);
    }
  }
  [[nodiscard]] bool at_end() const noexcept { return pos_ >= in_.size(); }
  [[nodiscard]] char peek() const noexcept { return at_end() ? '\0' : in_[pos_]; }
  [[nodiscard]] bool expect(char c) noexcept {
    if (peek() != c) {
      return false;
    }
    ++pos_;
    return true;
  }
  // Up to max_digits decimal digits, at least one.
  [[nodiscard]] std::optional<std::uint64_t> decimal(std::size_t max_digits, std::size_t& digits) noexcept {
    std::uint64_t v = 0;
    digits = 0;
    while (!at_end() && peek() >= '0' && peek() <= '9' && digits < max_digits) {
      v = v * 10U + static_cast<std::uint64_t>(in_[pos_++] - '0');
      ++digits;
    }
    return digits == 0 ? std::nullopt : std::optional<std::uint64_t>{v};
  }
  [[nodiscard]] std::size_t hex_run() const noexcept {
    std::size_t n = 0;
    while (pos_ + n < in_.size() && hex_value(in_[pos_ + n]) >= 0) {
      ++n;
    }
    return n;
  }
  [[nodiscard]] std::uint32_t take_hex(std::size_t n) noexcept {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < n; ++i) {
      v = (v << 4U) | static_cast<std::uint32_t>(hex_value(in_[pos_++]));
    }
    return v;
  }
  // A run of printable characters (an interface name); 0 when empty or too long.
  [[nodiscard]] std::size_t take_word(std::span<char> out) noexcept {
    std::size_t n = 0;
    while (!at_end() && peek() > ' ' && peek() < 0x7F) {
      if (n + 1 >= out.size()) {
        return 0;
      }
      out[n++] = in_[pos_++];
    }
    return n;
  }

 private:
  std::span<const char> in_;
  std::size_t pos_{0};
};

}  // namespace

std::size_t format_candump_line(const CanFrame& frame, const char* iface, std::span<char> out) noexcept {
  if (!is_valid(frame) || iface == nullptr) {
    return 0;
  }
  Writer w{out};
  w.put('(');
  w.put_decimal(frame.timestamp_us / 1'000'000U, 10);
  w.put('.');
  w.put_decimal(frame.timestamp_us % 1'000'000U, 6);
  w.put(')');
  w.put(' ');
  std::size_t name_len = 0;
  for (; iface[name_len] != '\0'; ++name_len) {
    if (name_len + 1 >= candump_iface_max) {
      return 0;
    }
    w.put(iface[name_len]);
  }
  if (name_len == 0) {
    return 0;
  }
  w.put(' ');
  w.put_hex(frame.id, frame.is_extended() ? 8 : 3);
  w.put('#');
  if (frame.is_fd()) {
    w.put('#');
    const unsigned fd_flags = ((frame.flags & can_flag::brs) != 0 ? 1U : 0U) | ((frame.flags & can_flag::esi) != 0 ? 2U : 0U);
    w.put(hex_digits[fd_flags]);
  } else if (frame.is_rtr()) {
    w.put('R');
    if (frame.len > 0) {
      w.put(hex_digits[frame.len & 0x0FU]);
    }
    return w.finish();
  }
  for (const std::uint8_t b : frame.payload()) {
    w.put_hex(b, 2);
  }
  return w.finish();
}

std::optional<CandumpRecord> parse_candump_line(std::span<const char> line) noexcept {
  Reader r{line};
  CandumpRecord rec{};
  std::size_t digits = 0;
  if (!r.expect('(')) {
    return std::nullopt;
  }
  const auto sec = r.decimal(12, digits);
  if (!sec || !r.expect('.')) {
    return std::nullopt;
  }
  const auto usec = r.decimal(6, digits);
  if (!usec || digits != 6 || !r.expect(')') || !r.expect(' ')) {
    return std::nullopt;
  }
  rec.frame.timestamp_us = *sec * 1'000'000U + *usec;
  if (r.take_word(rec.iface) == 0 || !r.expect(' ')) {
    return std::nullopt;
  }
  const std::size_t id_digits = r.hex_run();
  if (id_digits != 3 && id_digits != 8) {
    return std::nullopt;
  }
  rec.frame.id = r.take_hex(id_digits);
  if (id_digits == 8) {
    rec.frame.flags |= can_flag::extended;
  }
  if (!r.expect('#')) {
    return std::nullopt;
  }
  if (r.expect('#')) {
    rec.frame.flags |= can_flag::fd;
    if (r.hex_run() == 0) {
      return std::nullopt;
    }
    const std::uint32_t fd_flags = r.take_hex(1);
    if ((fd_flags & 0x1U) != 0) {
      rec.frame.flags |= can_flag::brs;
    }
    if ((fd_flags & 0x2U) != 0) {
      rec.frame.flags |= can_flag::esi;
    }
  } else if (r.expect('R')) {
    rec.frame.flags |= can_flag::rtr;
    if (r.hex_run() == 1) {
      rec.frame.len = static_cast<std::uint8_t>(r.take_hex(1));
    }
    if (!r.at_end() || !is_valid(rec.frame)) {
      return std::nullopt;
    }
    return rec;
  }
  const std::size_t data_digits = r.hex_run();
  if (data_digits % 2 != 0 || data_digits / 2 > can_fd_max_len) {
    return std::nullopt;
  }
  rec.frame.len = static_cast<std::uint8_t>(data_digits / 2);
  for (std::size_t i = 0; i < rec.frame.len; ++i) {
    rec.frame.data[i] = static_cast<std::uint8_t>(r.take_hex(2));
  }
  // Anything after the data (candump -L writes nothing) means this is not a frame line.
  if (!r.at_end() || !is_valid(rec.frame)) {
    return std::nullopt;
  }
  return rec;
}

}  // namespace settle::hal
