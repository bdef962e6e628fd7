// SPDX-License-Identifier: Apache-2.0
// A deadline on integer time: the one timeout rule behind heartbeat consumers, SYNC and RPDO
// loss, SDO client timeouts and following-error timeouts. Fires exactly once per loss, at the
// first check at or after the deadline, so virtual-clock tests can say when it must fire.
#pragma once

#include <cstdint>

namespace settle::hal::canopen {

class Watchdog {
 public:
  // A zero timeout disables the watchdog (CiA 301's meaning of 0 for every time object).
  void arm(std::uint64_t timeout_us, std::uint64_t now_us) noexcept {
    timeout_us_ = timeout_us;
    deadline_us_ = now_us + timeout_us;
    armed_ = timeout_us != 0;
    expired_ = false;
  }

  void disarm() noexcept {
    armed_ = false;
    expired_ = false;
  }

  // Proof of life: pushes the deadline out and clears an earlier expiry.
  void feed(std::uint64_t now_us) noexcept {
    if (timeout_us_ == 0) {
      return;
    }
    deadline_us_ = now_us + timeout_us_;
    armed_ = true;
    expired_ = false;
  }

  // True once, at the first call with now >= deadline; false again until fed and late again.
  [[nodiscard]] bool check(std::uint64_t now_us) noexcept {
    if (!armed_ || expired_ || now_us < deadline_us_) {
      return false;
    }
    expired_ = true;
    return true;
  }

  [[nodiscard]] bool armed() const noexcept { return armed_; }
  [[nodiscard]] bool expired() const noexcept { return expired_; }
  [[nodiscard]] std::uint64_t timeout_us() const noexcept { return timeout_us_; }
  [[nodiscard]] std::uint64_t deadline_us() const noexcept { return deadline_us_; }

 private:
  std::uint64_t timeout_us_{0};
  std::uint64_t deadline_us_{0};
  bool armed_{false};
  bool expired_{false};
};

}  // namespace settle::hal::canopen
