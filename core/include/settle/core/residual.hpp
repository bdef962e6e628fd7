// SPDX-License-Identifier: Apache-2.0
#pragma once
// The residual vibration a move leaves on a mode (omega, zeta): the one home of that quantity.
// The mode is  e'' + 2 zeta omega e' + omega^2 e = -x''(t),  driven by the command x from rest;
// once the command is at rest the mode rings freely, and its amplitude right after the move's end
// is what these functions give (in the move's units). Exact where the pieces allow (every
// profile's closed-form pieces, a constant-jerk table's segments); by Gauss-Legendre quadrature on
// panels short against the mode where they do not (the pseudo-polynomial), which is exact to
// rounding there too. The shaped step's classic V(omega, zeta) is shaper_residual (shaper.hpp).
// Freestanding: no heap, no exceptions.
#include <array>
#include <cmath>
#include <cstddef>

#include "settle/core/move.hpp"
#include "settle/core/move_request.hpp"  // Mode
#include "settle/core/piecewise_jerk.hpp"

namespace settle::core {

// At rest, relative to a move's distance |D|: every planned move leaves every design mode with a
// residual amplitude of at most kAtRestResidual |D| (docs/fastest.md, "What is guaranteed"; the
// tests check it by an integration of their own). A planner accepts its own designs tighter,
// kDesignResidual |D| (plus the rounding floor of its switch times), so that a move it returns
// clears the guarantee by a decade; whoever asks "does this command end at rest?" (the halt
// planner, the tests) asks it at kAtRestResidual, or a move the planner accepted could count as
// ringing (soak draw 726: planned to 1.03e-10 D, tests/core/test_halt.cpp).
inline constexpr double kAtRestResidual = 1e-9;
inline constexpr double kDesignResidual = 1e-10;

// The mode memory of a command x(t) that started at rest at t = 0, for the mode with poles
// lambda = -zeta omega +- i omega_d:  Q(t) = -int_0^t e^{lambda (t - s)} x'(s) ds  (complex).
// The command leaves the mode at rest at T (x'(T) = x''(T) = 0) exactly when Q(T) = 0, whatever
// the mode's input coupling (docs/online.md). A mode at rest with memory Q rings with amplitude
// |Q| / sqrt(1 - zeta^2).
struct ModeMemory {
  double re{0.0};
  double im{0.0};
};

// Q(t) of a planned move, from its exact piecewise closed form (piece.hpp) where the profile has
// one, by Gauss-Legendre quadrature otherwise (the pseudo-polynomial). t is on the move's clock.
// Zero for t <= 0 and for a mode Settle does not plan for (mode_status: finite, omega > 0, 0 <= zeta < 1).
[[nodiscard]] ModeMemory mode_memory(const Move<double>& m, double t, const Mode& mode) noexcept;

// The amplitude the move leaves on the mode at its end (move units). NaN for a mode Settle does
// not plan for (mode_status).
[[nodiscard]] double residual_amplitude(const Move<double>& m, const Mode& mode) noexcept;
// That amplitude relative to the one a step of the same distance leaves right after it,
// |D| omega / omega_d (a step has 1; undamped, the V(omega) of the input-shaping literature).
// 0 for a move of no distance; NaN for a mode outside the range above.
[[nodiscard]] double residual_ratio(const Move<double>& m, const Mode& mode) noexcept;

// The same for a constant-jerk table from rest (a = 0 at its start and end: the `fastest`
// profile's tables, the jerk-limited baselines), in closed form: |A(p)| / omega_d with A the
// Laplace transform of the acceleration at the pole p, referred to the table's end so that long
// moves on damped modes neither overflow nor cancel.
[[nodiscard]] double jerk_table_residual_amplitude(const double* durations, const double* jerk, std::size_t count,
                                                   const Mode& mode) noexcept;
template <std::size_t N>
[[nodiscard]] double residual_amplitude(const PiecewiseJerkTable<N>& p, const Mode& mode) noexcept {
  return jerk_table_residual_amplitude(p.durations.data(), p.jerk.data(), p.count, mode);
}
template <std::size_t N>
[[nodiscard]] double residual_ratio(const PiecewiseJerkTable<N>& p, const Mode& mode) noexcept {
  const double wd = mode.omega * std::sqrt(1.0 - mode.zeta * mode.zeta);
  if (p.distance == 0.0) return 0.0;
  return residual_amplitude(p, mode) * wd / (std::fabs(p.distance) * mode.omega);
}

}  // namespace settle::core
