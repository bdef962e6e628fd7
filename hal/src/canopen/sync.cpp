// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/sync.hpp"

#include "settle/hal/canopen/cob_id.hpp"

namespace settle::hal::canopen {

CanFrame encode_sync(std::uint8_t counter) noexcept {
  CanFrame f{};
  f.id = cob::sync;
  if (counter != 0) {
    f.len = 1;
    f.data[0] = counter;
  }
  return f;
}

std::optional<SyncMessage> decode_sync(const CanFrame& frame) noexcept {
  if (!is_canopen_data_frame(frame) || frame.id != cob::sync) {
    return std::nullopt;
  }
  if (frame.len == 0) {
    return SyncMessage{0};
  }
  if (frame.len == 1 && frame.data[0] >= 1 && frame.data[0] <= sync_counter_max) {
    return SyncMessage{frame.data[0]};
  }
  return std::nullopt;
}

SyncProducer::SyncProducer(std::uint32_t period_us, std::uint8_t counter_overflow) noexcept
    : period_us_{period_us},
      overflow_{counter_overflow > sync_counter_max ? sync_counter_max : counter_overflow} {}

const CanFrame& SyncProducer::next() noexcept {
  if (overflow_ >= 2) {
    counter_ = counter_ >= overflow_ ? 1 : static_cast<std::uint8_t>(counter_ + 1);
    frame_.len = 1;
    frame_.data[0] = counter_;
  }
  return frame_;
}

void SyncProducer::start(std::uint64_t now_us) noexcept {
  next_due_us_ = now_us;
  counter_ = 0;
}

bool SyncProducer::poll(std::uint64_t now_us, FrameSink& out) noexcept {
  if (period_us_ == 0 || now_us < next_due_us_) {
    return false;
  }
  const std::uint64_t late_periods = (now_us - next_due_us_) / period_us_;
  skipped_ += late_periods;
  next_due_us_ += (late_periods + 1) * period_us_;
  return out.put(next());
}

namespace {
[[nodiscard]] std::uint64_t sync_loss_timeout_us(std::uint32_t period_us, std::uint32_t loss_periods) noexcept {
  return std::uint64_t{period_us} * (std::uint64_t{loss_periods} + 1U) + period_us / 2U;
}
// Credit cap: loss_periods + 1 periods (loss_periods is at most 2^32 - 1, the period too: the
// product fits 64 bits; it is capped far below the int64 range anyway).
[[nodiscard]] std::int64_t sync_rate_cap_us(std::uint32_t period_us, std::uint32_t loss_periods) noexcept {
  const std::uint64_t cap = std::uint64_t{period_us} * (std::uint64_t{loss_periods} + 1U);
  constexpr std::uint64_t limit = std::uint64_t{1} << 62U;
  return static_cast<std::int64_t>(cap < limit ? cap : limit);
}
}  // namespace

SyncConsumer::SyncConsumer(std::uint32_t period_us, std::uint32_t loss_periods) noexcept
    : timeout_us_{sync_loss_timeout_us(period_us, loss_periods)},
      period_us_{period_us},
      cap_us_{sync_rate_cap_us(period_us, loss_periods)},
      credit_us_{cap_us_} {}

void SyncConsumer::configure(std::uint32_t period_us, std::uint32_t loss_periods) noexcept {
  timeout_us_ = sync_loss_timeout_us(period_us, loss_periods);
  watchdog_.disarm();
  period_us_ = period_us;
  cap_us_ = sync_rate_cap_us(period_us, loss_periods);
  credit_us_ = cap_us_;
  seen_ = false;
}

void SyncConsumer::set_counter_overflow(std::uint8_t overflow) noexcept {
  overflow_ = overflow >= 2 ? (overflow > sync_counter_max ? sync_counter_max : overflow) : 0;
  last_counter_ = 0;
}

SyncEvent SyncConsumer::check_counter(std::uint8_t counter) noexcept {
  if (overflow_ != 0) {
    // CiA 301: with 0x1019 set, every SYNC carries a counter 1..overflow that steps by one and
    // restarts at 1 after the overflow value. Anything else is a SYNC this consumer must not
    // count as a period. The received counter becomes the reference either way, so that one lost
    // or one foreign SYNC is one error, not an error on every SYNC after it.
    if (counter == 0) {
      return SyncEvent::unexpected_length;
    }
    const std::uint8_t previous = last_counter_;
    last_counter_ = counter;
    if (counter > overflow_) {
      return SyncEvent::out_of_range;
    }
    if (previous != 0) {
      const std::uint8_t expected = previous >= overflow_ ? 1 : static_cast<std::uint8_t>(previous + 1U);
      if (counter != expected) {
        return SyncEvent::out_of_sequence;
      }
    }
    return SyncEvent::in_order;
  }
  // 0x1019 = 0: a SYNC carries no data (CiA 301). A counter byte is an unexpected length, as
  // CANopenNode reports it (EMCY 0x8240): the producer and this drive disagree on 0x1019.
  return counter == 0 ? SyncEvent::in_order : SyncEvent::unexpected_length;
}

bool SyncConsumer::take_credit(std::uint64_t received_us) noexcept {
  if (period_us_ == 0) {
    return true;  // no period configured (0x1006 = 0): nothing to measure against
  }
  if (!seen_ || received_us < last_received_us_) {
    // The first SYNC, or a receive clock that stepped back: start from full credit.
    credit_us_ = cap_us_;
  } else {
    const std::uint64_t elapsed = received_us - last_received_us_;
    const std::uint64_t room = static_cast<std::uint64_t>(cap_us_ - credit_us_);
    // elapsed x 9/8, computed only below the room left (so it cannot wrap).
    credit_us_ = elapsed >= room || elapsed + elapsed / 8U >= room
                     ? cap_us_
                     : credit_us_ + static_cast<std::int64_t>(elapsed + elapsed / 8U);
  }
  seen_ = true;
  last_received_us_ = received_us;
  const auto cost = static_cast<std::int64_t>(period_us_);
  if (credit_us_ < cost) {
    return false;  // refused SYNCs cost nothing: only the SYNCs run as periods are counted
  }
  credit_us_ -= cost;
  return true;
}

SyncEvent SyncConsumer::on_sync(const SyncMessage& sync, std::uint64_t now_us, std::uint64_t received_us) noexcept {
  ++received_;
  if (!watchdog_.armed() || watchdog_.timeout_us() != timeout_us_) {
    watchdog_.arm(timeout_us_, now_us);
  } else {
    watchdog_.feed(now_us);
  }
  const SyncEvent event = check_counter(sync.counter);
  if (is_sync_error(event)) {
    return event;
  }
  if (!take_credit(received_us)) {
    return SyncEvent::too_many;
  }
  return event;
}

}  // namespace settle::hal::canopen
