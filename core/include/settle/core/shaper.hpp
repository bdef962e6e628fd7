// SPDX-License-Identifier: Apache-2.0
#pragma once
// Input shapers as exact operators: a shaped profile is sum_i A_i p(t - t_i), evaluated directly
// (no delay line, no buffer). ZV, ZVD, ZVDD (closed forms), EI with damping (solved exactly),
// custom impulse lists, and composition (one shaper per mode; the "hybrid" of seed 001).
#include <array>
#include <cstddef>

#include "settle/core/design_params.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

inline constexpr std::size_t kMaxImpulses = 32;

// ei2, ei3: two- and three-hump EI (after custom, so that the older values keep their numbers).
enum class ShaperKind : unsigned char { none, zv, zvd, zvdd, ei, custom, ei2, ei3 };

template <typename T>
struct Shaper {
  std::array<T, kMaxImpulses> amp{T(1)};
  std::array<T, kMaxImpulses> time{};
  std::size_t count{1};

  Shaper() = default;
  template <typename U>
  explicit Shaper(const Shaper<U>& o) noexcept {
    convert_from(o);
  }
  // Becomes `o` converted to T in place: its `count` impulses are written, the entries past them
  // are not the shaper's and keep what they held.
  template <typename U>
  void convert_from(const Shaper<U>& o) noexcept {
    count = o.count;
    for (std::size_t i = 0; i < count; ++i) {
      amp[i] = static_cast<T>(o.amp[i]);
      time[i] = static_cast<T>(o.time[i]);
    }
  }
  [[nodiscard]] T duration() const noexcept { return time[count - 1]; }
  [[nodiscard]] bool is_identity() const noexcept { return count == 1 && time[0] == T(0); }
};

// Designs a shaper for the mode (omega, zeta). vtol is EI's vibration tolerance (0.05 is usual).
[[nodiscard]] Status design_shaper(ShaperKind kind, double omega, double zeta, double vtol,
                                   Shaper<double>& out) noexcept;
// The two- or three-hump EI shaper (humps 2 or 3: ShaperKind::ei2, ei3; Singhose, Seering &
// Singer): humps + 2 impulses, the residual at most vtol from its lowest zero to its highest, and
// exactly vtol at each hump. With `zeros` (room for humps + 1), also the frequencies where the
// residual vanishes, relative to omega, ascending. no_solution where the design's structure ends
// with heavy damping (vtol 0.05: two humps to about zeta 0.38, three to about 0.26).
[[nodiscard]] Status multi_hump_ei_shaper(std::size_t humps, double omega, double zeta, double vtol,
                                          Shaper<double>& out, double* zeros = nullptr) noexcept;
// The joint ZV shaper of n modes (1 <= n <= kMaxJointModes): n + 1 positive impulses whose
// residual is zero on every mode, designed for all modes at once (a simultaneous design, Hyde &
// Seering 1991; Singhose, Crain & Seering 1997 for two modes) rather than one ZV per mode
// convolved (2^n impulses). The shortest one Newton's method finds from a fixed set of starts;
// no_solution where it finds none with positive amplitudes (about 1 in 13 random sets of three
// modes; docs/fastest.md "Several modes"). With n = 1 it is ZV.
inline constexpr std::size_t kMaxJointModes = 4;
[[nodiscard]] Status joint_zv_shaper(const double* omega, const double* zeta, std::size_t n,
                                     Shaper<double>& out) noexcept;
// A user's own impulses: times >= 0, amplitudes summing to 1. Sorted by time on output.
[[nodiscard]] Status custom_shaper(const double* amp, const double* time, std::size_t n,
                                   Shaper<double>& out) noexcept;
// Convolution of two shapers (impulses at equal times merged).
[[nodiscard]] Status compose(const Shaper<double>& a, const Shaper<double>& b, Shaper<double>& out) noexcept;
// Residual vibration of a unit step shaped by s on the mode (omega, zeta), as a fraction of the
// unshaped step's residual (the classic V(omega, zeta) of the input-shaping literature).
[[nodiscard]] double shaper_residual(const Shaper<double>& s, double omega, double zeta) noexcept;

[[nodiscard]] const char* to_string(ShaperKind k) noexcept;

// What designing shaper k from a request uses (design_shaper): the mode (omega, zeta), and the EI
// shapers their tolerance (vtol). None for `none`, and for `custom` (its impulses are the user's).
[[nodiscard]] constexpr ParamSet shaper_params(ShaperKind k) noexcept {
  switch (k) {
    case ShaperKind::zv:
    case ShaperKind::zvd:
    case ShaperKind::zvdd: return {Param::omega, Param::zeta};
    case ShaperKind::ei:
    case ShaperKind::ei2:
    case ShaperKind::ei3: return {Param::omega, Param::zeta, Param::vtol};
    case ShaperKind::none:
    case ShaperKind::custom: break;
  }
  return {};
}

}  // namespace settle::core
