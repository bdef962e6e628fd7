// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a user asks for: the distance, a move time or limits, the modes the move is designed for,
// and a shaper. Every profile's planner hook reads it (settle/core/profiles/), and plan() turns
// it into a Move (planner.hpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "settle/core/design_params.hpp"
#include "settle/core/limits.hpp"
#include "settle/core/mode.hpp"
#include "settle/core/pseudo_poly.hpp"
#include "settle/core/shaper.hpp"

namespace settle::core {

// One enumerator per line of the profile registry (settle/core/profiles/registry.hpp), which
// defines it; declared here so that the profiles' own headers can read a request.
enum class ProfileKind : std::uint8_t;

inline constexpr std::size_t kMaxModes = 4;  // the most a request designs for (profile `fastest`)

struct MoveRequest {
  ProfileKind profile{};  // the registry's first profile (scurve) unless set
  double distance{0.0};
  std::optional<double> time;  // move time of the unshaped profile
  OptionalLimits limits;  // each absent one does not limit
  std::array<double, kMaxGammas> gammas{};  // pseudopoly exponents
  std::size_t gamma_count{0};
  std::optional<std::array<double, 3>> y_fractions;  // ramp-versine: Y/L given instead of computed
  ShaperKind shaper{ShaperKind::none};
  double vtol{0.05};  // EI tolerance
  std::optional<double> robust;  // percent: residual <= 5 % over omega (1 +- robust/100) (`fastest`)
  // The modes the move is designed for, in the order given: a profile that designs for one mode
  // reads the first (omega(), zeta()); `fastest` reads every one.
  std::array<Mode, kMaxModes> modes{};
  std::size_t mode_count{0};

  [[nodiscard]] constexpr bool has_mode() const noexcept { return mode_count > 0; }
  // The first mode's natural frequency (rad/s) and damping ratio; 0 when there is no mode.
  [[nodiscard]] constexpr double omega() const noexcept { return mode_count > 0 ? modes[0].omega : 0.0; }
  [[nodiscard]] constexpr double zeta() const noexcept { return mode_count > 0 ? modes[0].zeta : 0.0; }
  [[nodiscard]] constexpr std::span<const Mode> mode_list() const noexcept { return {modes.data(), mode_count}; }
  // Designs for this one mode only.
  constexpr void set_mode(double omega_rad_s, double zeta_ratio = 0.0) noexcept {
    modes[0] = {omega_rad_s, zeta_ratio};
    mode_count = 1;
  }
  // Appends a mode; false (nothing changed) when the request holds kMaxModes already.
  constexpr bool add_mode(Mode m) noexcept {
    if (mode_count >= kMaxModes) return false;
    modes[mode_count++] = m;
    return true;
  }
};

}  // namespace settle::core
