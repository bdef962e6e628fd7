// SPDX-License-Identifier: Apache-2.0
#pragma once
// Sine and cosine in fixed point for the evaluators' tick path. The angle is a 32-bit fraction of a
// turn, so a phase accumulator wraps onto it for free; results are Q2.30 (1.0 = 2^30). Two
// implementations were measured (docs/fixed-point.md): a 257-entry quarter-wave table with a short
// Taylor correction (used), and a pure polynomial (kept for the comparison and its tests).
#include <cstdint>

namespace settle::core::fixed {

inline constexpr int kTrigBits = 30;  // sin and cos are Q2.30

struct SinCos {
  std::int32_t sin{0};
  std::int32_t cos{0};
};

// Table + correction: |error| < 0.8 LSB (measured over all 2^32 angles), 8 products of 32 bits.
[[nodiscard]] SinCos sincos(std::uint32_t turn) noexcept;
// Odd/even Taylor polynomials on the nearest quarter turn: 14 products of 32 bits, no table.
[[nodiscard]] SinCos sincos_poly(std::uint32_t turn) noexcept;

}  // namespace settle::core::fixed
