// SPDX-License-Identifier: Apache-2.0
#pragma once
// The values every profile evaluates to and the peaks it reports. Templated on the scalar so that
// double (planning, host) and float (Cortex-M4F) evaluation share one implementation.
#include <cmath>
#include <limits>

namespace settle::core {

template <typename T>
struct Sample {
  T p{};  // position relative to the start of the move
  T v{};
  T a{};
  T j{};
};

// True peak magnitudes over the whole move. A Dirac (a velocity step makes an acceleration
// impulse) is reported as +infinity with its flag set, never hidden.
template <typename T>
struct Peaks {
  T v{};
  T a{};
  T j{};
  bool velocity_step{false};      // the command jumps in velocity (seed 001 at start and end)
  bool acceleration_step{false};  // the command jumps in acceleration (trapezoid)
};

template <typename T>
inline constexpr T infinity_v = std::numeric_limits<T>::infinity();

template <typename T>
[[nodiscard]] inline constexpr T two_pi_v() noexcept {
  return static_cast<T>(6.283185307179586476925286766559);
}

}  // namespace settle::core
