// SPDX-License-Identifier: Apache-2.0
#pragma once
// The excitation `settle identify` streams: one planned jerk-limited move, and before it a train
// of the same move back and forth. Each acceleration step of a move rings every mode once; a
// heavily damped mode rings for a few periods only, so its frequency and damping are learnt from
// those few samples after each step (docs/identification.md, the Cramér–Rao bound), and more
// steps are what lowers the bound. The train is one Move: the move convolved with impulses of
// alternating sign (+1, -1, +1, ..., +1: out, back, ..., out), so it is planned, checked against
// the limits, streamed, replayed and sampled like any shaped move. The copies never overlap, so
// its peaks are the move's; the gaps between them vary (a golden-ratio sequence, deterministic)
// so that no mode is rung in step with the train.
#include <cstddef>

#include "settle/core/limits.hpp"
#include "settle/core/move.hpp"
#include "settle/core/status.hpp"

namespace settle::commission {

// --train: round trips before the final move, 0..kMaxTrainRoundTrips (2 n + 1 copies of the move
// fill core::kMaxImpulses at most).
inline constexpr std::size_t kMaxTrainRoundTrips = 15;
// settle identify's default: the longest train a Move holds. Every acceleration step lowers the
// bound on a heavily damped mode, and a few more seconds of commissioning cost nothing against a
// mode measured wrong (docs/identification.md: 1 392 of 1 400 random plants identified against
// 1 375 with 8 round trips).
inline constexpr std::size_t kDefaultTrainRoundTrips = kMaxTrainRoundTrips;

struct IdentifyExcitation {
  double distance{0.01};  // m or rad, of the move and of each copy in the train
  core::Limits limits{.vmax = 0.1, .amax = 5.0, .jmax = 5000.0};  // of the move, each copy's too
  std::size_t round_trips{0};  // 0: the move alone
};

// The gap after copy k (k = 0, 1, ...), in units of the move's duration: from 0.25 to 0.75.
[[nodiscard]] double train_gap(std::size_t k) noexcept;

// The excitation as one Move (see above). Not ok when the move cannot be planned within the
// limits, or round_trips is beyond kMaxTrainRoundTrips (core::Status::too_many_impulses).
[[nodiscard]] core::Status plan_identify_excitation(const IdentifyExcitation& ex, core::Move<double>& out);
// The round trips of an excitation plan_identify_excitation made (from its impulses).
[[nodiscard]] std::size_t train_round_trips(const core::Move<double>& excitation) noexcept;

}  // namespace settle::commission
