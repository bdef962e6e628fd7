// SPDX-License-Identifier: Apache-2.0
#pragma once
// sin and cos of a profile's phase, which is always a few turns at most (a ramp-cycloid's
// 2*pi*u/tau within one segment, a ramp-versine's r*t within its duration, a stepper's rotation per
// tick). In double: std::sin and std::cos. In float: a Cody-Waite reduction by pi/2 in three parts
// and minimax polynomials on [-pi/4, pi/4] (Cephes's sinf/cosf coefficients), 1 to 2 float ulp
// for |x| <= kFloatTrigDomain (test_trig.cpp checks it against double).
//
// Why not std::sin(float): newlib's sinf/cosf link its Payne-Hanek reduction for arguments up to
// 2^128 (__kernel_rem_pio2f and its 2/pi table), 3.6 KiB of a Cortex-M4F servo image's 32 KiB of
// flash that no phase ever needs (firmware/README.md, "The budgets are checked").
#include <cmath>
#include <cstdint>
#include <type_traits>

namespace settle::core {

template <typename T>
struct SinCos {
  T sin;
  T cos;
};

// The float form's domain: 2^12 quadrants, where the reduction's products are exact; every phase
// Settle evaluates is within [0, 2*pi]. Outside it the float form is not an approximation: a finite
// x gives {0, 1} (bounded, so nothing downstream overflows), NaN and infinities give NaN as std::sin
// does. Reducing huge arguments properly is what costs newlib its 3.6 KiB.
inline constexpr float kFloatTrigDomain = 6400.0F;

namespace detail {

[[nodiscard]] inline SinCos<float> sin_cos_float(float x) noexcept {
  const bool in_domain = std::fabs(x) <= kFloatTrigDomain;
  // pi/2 = P1 + P2 + P3: P1 and P2 have 8 and 12 significant bits, so k*P1 and k*P2 are exact
  // for |k| < 2^12; P3 is the float nearest the rest.
  constexpr float kP1 = 1.5703125F;
  constexpr float kP2 = 4.837512969970703125e-4F;
  constexpr float kP3 = 7.549790126404332e-8F;
  constexpr float kTwoOverPi = 0.636619772367581343F;
  const float k = in_domain ? std::nearbyint(x * kTwoOverPi) : 0.0F;
  const float r = in_domain ? ((x - k * kP1) - k * kP2) - k * kP3 : x - x;  // x - x: 0, or NaN
  const float z = r * r;
  const float s = r + r * z * ((-1.9515295891e-4F * z + 8.3321608736e-3F) * z - 1.6666654611e-1F);
  const float c = 1.0F - 0.5F * z + z * z * ((2.443315711809948e-5F * z - 1.388731625493765e-3F) * z +
                                              4.166664568298827e-2F);
  // The quadrant: k mod 4 (two's complement keeps it right for negative k), |k| <= 2^12 + 1.
  const auto q = static_cast<std::uint32_t>(static_cast<std::int32_t>(k)) & 3U;
  switch (q) {
    case 1:
      return {c, -s};
    case 2:
      return {-s, -c};
    case 3:
      return {-c, s};
    default:
      return {s, c};
  }
}

}  // namespace detail

template <typename T>
[[nodiscard]] inline SinCos<T> sin_cos(T x) noexcept {
  if constexpr (std::is_same_v<T, float>) {
    return detail::sin_cos_float(x);
  } else {
    return {std::sin(x), std::cos(x)};
  }
}

}  // namespace settle::core
