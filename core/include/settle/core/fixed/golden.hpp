// SPDX-License-Identifier: Apache-2.0
#pragma once
// A deterministic fingerprint of the fixed-point evaluators, for comparing a target with the host:
// plans a fixed list of moves (chosen so that planning needs no libm approximation), builds them
// (motions, their position plans, cam tables), runs every tick in every form and folds every
// integer into 64-bit checksums. Equal numbers on x86-64 and on an ARM image mean equal setpoints, bit for bit.
#include <cstdint>
#include <span>

#include "settle/core/fixed/format.hpp"
#include "settle/core/move.hpp"
#include "settle/core/status.hpp"

namespace settle::core::fixed {

// One move of the golden list: every evaluator kind once, planned libm-free (timed requests, whole
// exponents, zeta = 0 for the shaped moves), so any target plans the same move. The firmware's
// per-evaluator cost image measures the same list.
struct GoldenMove {
  const char* name;  // scurve, scurve_damped, ramp_versine, poly345, pseudopoly, trapezoid, scurve_zv, ...
  ProfileKind kind;
  double distance, time, omega, zeta;
  AxisScale scale;    // every period a whole number of microseconds
  ShaperKind shaper;  // ZV and ZVD designed with zeta = 0: impulses at fractional ticks, libm-free
};
[[nodiscard]] std::span<const GoldenMove> golden_moves() noexcept;
[[nodiscard]] Status plan_golden(const GoldenMove& g, Move<double>& out) noexcept;
[[nodiscard]] constexpr Scale golden_scale(const GoldenMove& g) noexcept { return Scale{g.scale, 16, 16}; }

struct GoldenResult {
  std::uint64_t build{0};    // every field of every built object (segments, tracks, cam knots)
  std::uint64_t ticks{0};    // every p, v, a of at_tick() and of the steppers, every tick
  std::uint64_t plan{0};     // every field of every motion's position plan
  std::uint64_t positions{0};  // every position of the position stepper, every tick
  std::uint32_t moves{0};    // objects built (motions and cam tables)
  std::uint32_t samples{0};  // samples folded into `ticks`
  std::uint32_t position_samples{0};  // positions folded into `positions`
  Status status{Status::ok}; // the first failure (then the checksums cover what came before it)
};

// No heap; about 5 KiB of static storage (not reentrant) and 1.5 KiB of stack besides plan()'s
// own (4.6 KiB on a Cortex-M0). The host's values are pinned in tests/core_fixed/test_golden.cpp.
[[nodiscard]] GoldenResult golden_checksum() noexcept;

}  // namespace settle::core::fixed
