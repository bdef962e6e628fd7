// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a user asks for: the distance, a move time or limits, the mode the move is designed for,
// and a shaper. Every profile's planner hook reads it (settle/core/profiles/), and plan() turns
// it into a Move (planner.hpp).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "settle/core/pseudo_poly.hpp"
#include "settle/core/shaper.hpp"

namespace settle::core {

// One enumerator per line of the profile registry (settle/core/profiles/registry.hpp), which
// defines it; declared here so that the profiles' own headers can read a request.
enum class ProfileKind : std::uint8_t;

// A further mode a request is designed for (profile `fastest` reads every one of them).
struct Mode {
  double omega{0.0};  // rad/s
  double zeta{0.0};
};
inline constexpr std::size_t kMaxExtraModes = 3;  // besides (omega, zeta): four modes at most

struct MoveRequest {
  ProfileKind profile{};  // the registry's first profile (scurve) unless set
  double distance{0.0};
  std::optional<double> time;  // move time of the unshaped profile
  std::optional<double> vmax, amax, jmax;
  std::optional<double> omega;  // the mode the move is designed for (rad/s)
  double zeta{0.0};
  std::array<double, kMaxGammas> gammas{};  // pseudopoly exponents
  std::size_t gamma_count{0};
  std::optional<std::array<double, 3>> y_fractions;  // ramp-versine: Y/L given instead of computed
  ShaperKind shaper{ShaperKind::none};
  double vtol{0.05};  // EI tolerance
  std::array<Mode, kMaxExtraModes> extra_modes{};  // modes after the first (profile `fastest`)
  std::size_t extra_mode_count{0};
  std::optional<double> robust;  // percent: residual <= 5 % over omega (1 +- robust/100) (`fastest`)
};

}  // namespace settle::core
