// SPDX-License-Identifier: Apache-2.0
// CiA 301 SYNC: the frame that marks each servo period. The producer (the servo loop) emits it
// with the optional 1..overflow counter; the consumer (a drive) notices counter gaps and loss.
#pragma once

#include <cstdint>
#include <optional>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/watchdog.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen {

inline constexpr std::uint8_t sync_counter_max = 240;  // 0x1019 may be 2..240 (0 = no counter)

struct SyncMessage {
  std::uint8_t counter{0};  // 0: the SYNC carried no counter
};

[[nodiscard]] CanFrame encode_sync(std::uint8_t counter = 0) noexcept;
// Accepts length 0 (no counter) or 1 with a counter in 1..240 on id 0x80.
[[nodiscard]] std::optional<SyncMessage> decode_sync(const CanFrame& frame) noexcept;

class SyncProducer {
 public:
  // counter_overflow: value of 0x1019; 0 or 1 send SYNC without a counter.
  explicit SyncProducer(std::uint32_t period_us, std::uint8_t counter_overflow = 0) noexcept;

  // The next SYNC frame, for a loop that owns the tick and sends one per period itself. The
  // producer keeps the frame and only steps its counter: nothing is built or copied per period.
  // The reference is valid until the next call.
  [[nodiscard]] const CanFrame& next() noexcept;

  // Time-driven use: sends when now has reached the next due time. A late call sends one
  // SYNC and skips the periods it missed, so a stalled caller never causes a burst.
  [[nodiscard]] bool poll(std::uint64_t now_us, FrameSink& out) noexcept;
  void start(std::uint64_t now_us) noexcept;

  [[nodiscard]] std::uint32_t period_us() const noexcept { return period_us_; }
  [[nodiscard]] std::uint64_t skipped() const noexcept { return skipped_; }

 private:
  std::uint32_t period_us_;
  std::uint8_t overflow_;
  std::uint8_t counter_{0};
  std::uint64_t next_due_us_{0};
  std::uint64_t skipped_{0};
  CanFrame frame_{encode_sync(0)};
};

enum class SyncEvent : std::uint8_t {
  in_order,  // first SYNC, or the counter followed on (or there is no counter)
  // The errors below mean this SYNC must not run a period (a second producer, a duplicated frame):
  unexpected_length,  // the SYNC's length does not match 0x1019: no counter while one is configured, or
                      // one while none is (CiA 301: EMCY 0x8240)
  out_of_range,       // a counter above 0x1019's overflow value: it does not match 0x1019 (EMCY 0x8240)
  out_of_sequence,    // a counter is configured and this one is not the successor of the previous one
  too_many,           // more SYNCs than one per period, beyond the tolerated burst (see SyncConsumer)
};

[[nodiscard]] constexpr bool is_sync_error(SyncEvent event) noexcept {
  return event == SyncEvent::unexpected_length || event == SyncEvent::out_of_range ||
         event == SyncEvent::out_of_sequence || event == SyncEvent::too_many;
}

class SyncConsumer {
 public:
  // SYNC loss is declared when more than loss_periods SYNCs in a row are missing: after
  // (loss_periods + 1.5) periods of silence, the half period absorbing the producer's
  // jitter. Period 0 disables it.
  //
  // The same loss_periods bound the other way: SYNCs arriving faster than one per period.
  // A consumer cannot tell a duplicated SYNC from one sent late and followed by one on time, so
  // it measures the rate, by the frames' receive times, with a token bucket: every SYNC costs one
  // period of credit, credit accrues at 9/8 of real time (so a producer whose clock runs up to
  // 12.5 % fast still passes) and is capped at loss_periods + 1 periods. A producer that is late and
  // then on time never runs short; a burst of more than loss_periods + 1 SYNCs at once, or a
  // sustained double rate (a duplicating bus, a second producer) does: too_many, after at most
  // about 1.15 x (loss_periods + 1) extra SYNCs. With a counter (set_counter_overflow) the first
  // duplicate is caught by its counter.
  SyncConsumer(std::uint32_t period_us, std::uint32_t loss_periods) noexcept;

  // now_us: the owner's clock, for the loss watchdog; received_us: when the frame arrived (its
  // receive timestamp), for the rate. The two-argument form uses now_us for both.
  [[nodiscard]] SyncEvent on_sync(const SyncMessage& sync, std::uint64_t now_us) noexcept {
    return on_sync(sync, now_us, now_us);
  }
  [[nodiscard]] SyncEvent on_sync(const SyncMessage& sync, std::uint64_t now_us, std::uint64_t received_us) noexcept;
  // True once when SYNCs stopped arriving (only after the first SYNC has been seen).
  [[nodiscard]] bool check_loss(std::uint64_t now_us) noexcept { return watchdog_.check(now_us); }
  void configure(std::uint32_t period_us, std::uint32_t loss_periods) noexcept;
  // 0x1019. 0: a SYNC carries no counter (one that does is an unexpected length); 2..240: every SYNC
  // must carry the successor of the previous counter (overflow, then 1). 1 is treated as 0.
  void set_counter_overflow(std::uint8_t overflow) noexcept;
  // Full credit again, as if the producer had been on time so far (a drive calls it when it
  // starts to follow, so that bursts while it was idle count for nothing).
  void rearm_rate_check() noexcept { credit_us_ = cap_us_; }

  [[nodiscard]] std::uint64_t received() const noexcept { return received_; }
  [[nodiscard]] std::uint8_t last_counter() const noexcept { return last_counter_; }

 private:
  [[nodiscard]] SyncEvent check_counter(std::uint8_t counter) noexcept;
  [[nodiscard]] bool take_credit(std::uint64_t received_us) noexcept;

  Watchdog watchdog_{};
  std::uint64_t timeout_us_;
  std::uint64_t period_us_;
  std::int64_t cap_us_;
  std::int64_t credit_us_;
  std::uint64_t last_received_us_{0};
  bool seen_{false};
  std::uint64_t received_{0};
  std::uint8_t last_counter_{0};
  std::uint8_t overflow_{0};
};

}  // namespace settle::hal::canopen
