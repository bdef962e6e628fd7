// SPDX-License-Identifier: Apache-2.0
#pragma once
// A `fastest` move scaled (core/src/fastest.cpp; used by axis_command, multi_axis.cpp, and by
// plan_fastest, which plans -D as the move of D mirrored: k = -1).
#include "settle/core/profiles/fastest.hpp"

namespace settle::core::detail {

// The same move scaled by k (distance k D, every position, velocity, acceleration and jerk times
// k; times, the family and the family times kept): the move planned for k D under the limits
// times |k|, exactly, where planning at that scale agrees only to about 1e-8 (the bang-bang
// chain's refinement decides on ulp-level differences) or finds another chain. A path's axes are
// one unit path scaled. Curve: distance and amplitude times k; table: distance, each segment's
// starting acceleration and jerk times k (durations kept, so every switch time is the unit move's
// bit for bit). Peaks scale by |k|; they are the caller's.
[[nodiscard]] FastestParams scaled_fastest(const FastestParams& p, double k) noexcept;

}  // namespace settle::core::detail
