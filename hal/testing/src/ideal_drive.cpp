// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/testing/ideal_drive.hpp"

#include <limits>

namespace settle::hal::testing {

std::int32_t ideal_velocity(std::int32_t from, std::int32_t to, std::uint32_t periods_per_second) noexcept {
  // The step the short way round the wrap (as DriveNode's position_difference), then the rate,
  // both in 64 bits: |step| <= 2^31 and the rate < 2^32, so the product fits.
  const std::int64_t step =
      static_cast<std::int32_t>(static_cast<std::uint32_t>(to) - static_cast<std::uint32_t>(from));
  const std::int64_t v = step * std::int64_t{periods_per_second};
  constexpr std::int64_t lo = std::numeric_limits<std::int32_t>::min();
  constexpr std::int64_t hi = std::numeric_limits<std::int32_t>::max();
  return static_cast<std::int32_t>(v < lo ? lo : (v > hi ? hi : v));
}

IdealAxis::IdealAxis(const canopen::DriveNodeConfig& config) noexcept
    : node_{config},
      periods_per_second_{config.sync_period_us == 0 ? 0U : 1'000'000U / config.sync_period_us} {}

void IdealAxis::start(std::uint64_t now_us, FrameSink& out) noexcept { node_.start(now_us, out); }

canopen::DriveEvent IdealAxis::on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept {
  const canopen::DriveEvent e = node_.on_frame(frame, now_us, out);
  if (e != canopen::DriveEvent::sync) return e;
  const bool following = node_.following();
  const std::int32_t sp = following ? node_.setpoint() : position_;
  if (following) {
    if (applied_count_ < record_.size()) record_[static_cast<std::size_t>(applied_count_)] = sp;
    ++applied_count_;
  }
  velocity_ = ideal_velocity(position_, sp, periods_per_second_);
  position_ = sp;
  if (node_.stopping()) node_.stop_complete();
  // Counts wrap modulo 2^32, as a drive's position counter does.
  const auto reported = static_cast<std::int32_t>(static_cast<std::uint32_t>(position_) - lag_);
  node_.publish({reported, velocity_, reported}, now_us, out);
  return e;
}

void IdealAxis::record_applied(std::span<std::int32_t> buffer) noexcept {
  record_ = buffer;
  applied_count_ = 0;
}

std::span<const std::int32_t> IdealAxis::applied() const noexcept {
  const std::size_t n = applied_count_ < record_.size() ? static_cast<std::size_t>(applied_count_) : record_.size();
  return record_.first(n);
}

}  // namespace settle::hal::testing
