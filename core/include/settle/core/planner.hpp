#pragma once
// From a user's physical request (distance, a move time or limits, the mode, a shaper) to a ready
// Move, or a specific Status. Planning runs in double; convert the Move to float for evaluation.
// A failed plan leaves the output untouched.
#include <array>
#include <cstddef>
#include <optional>

#include "settle/core/move.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

struct MoveRequest {
  ProfileKind profile{ProfileKind::scurve};
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
};

[[nodiscard]] Status plan(const MoveRequest& req, Move<double>& out) noexcept;

// The shortest ramp-cycloid S-curve (undamped or damped variant per `damped`) that leaves the
// mode at rest and whose true peaks respect vmax, amax and jmax (jmax may be +infinity).
[[nodiscard]] Status plan_fastest_scurve(double distance, double vmax, double amax, double jmax, double omega,
                                         double zeta, bool damped, RampCycloidParams& out) noexcept;

// Peaks of a shaped move, computed from its evaluation (a dense scan refined around each
// maximum); equal to the profile's own peaks when the shaper is the identity.
[[nodiscard]] Peaks<double> shaped_peaks(const Profile<double>& p, const Shaper<double>& s,
                                         const Peaks<double>& unshaped) noexcept;

}  // namespace settle::core
