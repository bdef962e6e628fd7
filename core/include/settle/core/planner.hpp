// SPDX-License-Identifier: Apache-2.0
#pragma once
// From a user's physical request (distance, a move time or limits, the mode, a shaper) to a ready
// Move, or a specific Status. Planning runs in double; convert the Move to float for evaluation.
// A failed plan leaves the output untouched. Each profile's own planning is its hook in the
// registry (profiles/registry.hpp); what every plan shares (validation, shaping, limits) is here.
#include "settle/core/move.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

[[nodiscard]] Status plan(const MoveRequest& req, Move<double>& out) noexcept;
// The same, convolved with `extra` too (after the request's own shaper): a coordinated path shaped
// for further modes (multi_axis.hpp). Peaks and limits are the result's.
[[nodiscard]] Status plan(const MoveRequest& req, const Shaper<double>& extra, Move<double>& out) noexcept;

// The parameters planning `req` reads beyond its distance (design_params.hpp): its profile's (less
// what the profile's override drops, e.g. ramp-versine's mode given its fractions) and its shaper's.
// A parameter the request carries outside this set is ignored by plan(): callers refuse it.
[[nodiscard]] ParamSet used_params(const MoveRequest& req) noexcept;
// Whether planning `req` uses the mode (used_params holds omega): a shaper does, and so does a
// profile whose hook designs for it. plan() then requires a positive omega.
[[nodiscard]] bool needs_mode(const MoveRequest& req) noexcept;

// Peaks of a shaped move, computed from its evaluation (a dense scan refined around each
// maximum); equal to the profile's own peaks when the shaper is the identity.
[[nodiscard]] Peaks<double> shaped_peaks(const Profile<double>& p, const Shaper<double>& s,
                                         const Peaks<double>& unshaped) noexcept;

}  // namespace settle::core
