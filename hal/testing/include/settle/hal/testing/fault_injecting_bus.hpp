// SPDX-License-Identifier: Apache-2.0
// A test double for any CanBus: forwards to a real backend (usually a loopback port) and, on
// request, makes sends report busy or error, loses frames in either direction, or holds them
// back until the test's virtual time has advanced. Scripted (the next n frames) or random
// (seeded rates), and optionally only for frames matching a filter (e.g. only SYNC). It also plays
// the controller's error reports, which no virtual interface can produce: error-warning,
// error-passive and bus-off (as the error frames a real controller sends), and the answer to a
// restart request. While bus-off, every send fails with error and whatever reaches the
// controller is lost, as on a controller that is off the bus.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "settle/hal/can_bus.hpp"
#include "settle/hal/ring.hpp"

namespace settle::hal::testing {

// Probabilities in parts per million, drawn per frame from a seeded generator.
struct FaultRates {
  std::uint32_t tx_busy_ppm{0};
  std::uint32_t tx_error_ppm{0};
  std::uint32_t tx_drop_ppm{0};
  std::uint32_t rx_drop_ppm{0};
};

struct FaultStats {
  std::uint64_t tx_busy{0};     // sends answered busy by the double
  std::uint64_t tx_errors{0};   // sends answered error by the double
  std::uint64_t tx_dropped{0};  // reported sent, never forwarded
  std::uint64_t rx_dropped{0};  // taken from the backend and discarded
  std::uint64_t delayed{0};     // frames that waited in a hold queue
  std::uint64_t bus_off_rx_lost{0};  // frames that arrived while the controller was off the bus
};

class FaultInjectingBus final : public CanBus {
 public:
  static constexpr std::size_t hold_capacity = 64;

  explicit FaultInjectingBus(CanBus& inner) noexcept;

  // Scripted faults for the next `count` frames the target filter matches.
  void fail_sends(std::uint32_t count, SendStatus status) noexcept;
  void drop_sends(std::uint32_t count) noexcept;
  void drop_receives(std::uint32_t count) noexcept;
  // Frames wait this long (virtual time) before they go out / become receivable.
  void delay_sends_us(std::uint64_t delay_us) noexcept { tx_delay_us_ = delay_us; }
  void delay_receives_us(std::uint64_t delay_us) noexcept { rx_delay_us_ = delay_us; }
  void set_random(std::uint32_t seed, const FaultRates& rates) noexcept;
  // Faults touch only frames this filter matches; nullopt (the default) means every frame.
  void set_target(std::optional<CanFilter> target) noexcept { target_ = target; }
  void clear_faults() noexcept;

  // The controller reports a new error state (what an error frame tells SocketCanBus).
  void inject_bus_state(BusState state) noexcept {
    count_error_frame();
    set_bus_state(state);
  }
  // How the next restart requests are answered. ok: the controller is back (error_active) at once
  // unless restart_completes is false (then inject the state when the test wants it back).
  void set_restart_answer(BusStatus answer, bool restart_completes = true) noexcept {
    restart_answer_ = answer;
    restart_completes_ = restart_completes;
  }

  // Advances virtual time and forwards delayed sends that are due.
  void set_time_us(std::uint64_t now_us) noexcept;

  [[nodiscard]] const FaultStats& stats() const noexcept { return stats_; }
  [[nodiscard]] std::size_t held_sends() const noexcept { return tx_hold_.size(); }
  [[nodiscard]] std::size_t held_receives() const noexcept { return rx_hold_.size(); }

 private:
  struct Held {
    CanFrame frame{};
    std::uint64_t due_us{0};
  };
  // Frames waiting for their due time; full means the frame is lost (and counted).
  class HoldQueue {
   public:
    HoldQueue() noexcept : ring_{storage_} {}
    HoldQueue(const HoldQueue&) = delete;
    HoldQueue& operator=(const HoldQueue&) = delete;
    [[nodiscard]] bool push(const CanFrame& f, std::uint64_t due_us) noexcept { return ring_.push(Held{f, due_us}); }
    [[nodiscard]] bool pop_due(std::uint64_t now_us, CanFrame& out) noexcept;
    [[nodiscard]] std::size_t size() const noexcept { return ring_.size(); }
    void clear() noexcept { ring_.clear(); }

   private:
    std::array<Held, hold_capacity> storage_{};
    Ring<Held> ring_;
  };

  [[nodiscard]] SendStatus do_send(const CanFrame& frame) noexcept override;
  [[nodiscard]] ReceiveStatus do_receive(CanFrame& frame, std::uint32_t timeout_us) noexcept override;
  [[nodiscard]] BusStatus do_set_filters(std::span<const CanFilter> filters) noexcept override;
  [[nodiscard]] BusStatus do_restart() noexcept override;

  [[nodiscard]] bool targeted(const CanFrame& frame) const noexcept;
  [[nodiscard]] bool chance(std::uint32_t ppm) noexcept;

  CanBus& inner_;
  std::optional<CanFilter> target_{};
  std::uint32_t fail_count_{0};
  SendStatus fail_status_{SendStatus::busy};
  std::uint32_t drop_tx_count_{0};
  std::uint32_t drop_rx_count_{0};
  std::uint64_t tx_delay_us_{0};
  std::uint64_t rx_delay_us_{0};
  FaultRates rates_{};
  std::uint32_t rng_{0};
  std::uint64_t now_us_{0};
  HoldQueue tx_hold_{};
  HoldQueue rx_hold_{};
  FaultStats stats_{};
  BusStatus restart_answer_{BusStatus::not_supported};
  bool restart_completes_{true};
};

}  // namespace settle::hal::testing
