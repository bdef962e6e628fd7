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
}  // namespace

SyncConsumer::SyncConsumer(std::uint32_t period_us, std::uint32_t loss_periods) noexcept
    : timeout_us_{sync_loss_timeout_us(period_us, loss_periods)} {}

void SyncConsumer::configure(std::uint32_t period_us, std::uint32_t loss_periods) noexcept {
  timeout_us_ = sync_loss_timeout_us(period_us, loss_periods);
  watchdog_.disarm();
}

SyncEvent SyncConsumer::on_sync(const SyncMessage& sync, std::uint64_t now_us) noexcept {
  ++received_;
  if (!watchdog_.armed() || watchdog_.timeout_us() != timeout_us_) {
    watchdog_.arm(timeout_us_, now_us);
  } else {
    watchdog_.feed(now_us);
  }
  SyncEvent event = SyncEvent::in_order;
  if (sync.counter != 0 && last_counter_ != 0) {
    // The counter restarts at 1 after the producer's overflow value, which the consumer
    // learns from the largest counter it has seen; any other step means lost SYNCs.
    const bool wrapped = sync.counter == 1 && last_counter_ >= max_counter_seen_;
    const unsigned expected = static_cast<unsigned>(last_counter_) + 1U;
    if (!wrapped && sync.counter != expected) {
      event = SyncEvent::gap;
      missed_ += sync.counter > last_counter_ ? static_cast<std::uint64_t>(sync.counter - last_counter_ - 1)
                                              : static_cast<std::uint64_t>(sync.counter - 1);
    }
  }
  if (sync.counter > max_counter_seen_) {
    max_counter_seen_ = sync.counter;
  }
  last_counter_ = sync.counter;
  return event;
}

}  // namespace settle::hal::canopen
