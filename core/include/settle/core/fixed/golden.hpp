#pragma once
// A deterministic fingerprint of the fixed-point evaluators, for comparing a target with the host:
// plans a fixed list of moves (chosen so that planning needs no libm approximation), builds them
// (motions and cam tables), runs every tick in both forms and folds every integer into 64-bit
// checksums. Equal numbers on x86-64 and on an ARM image mean equal setpoints, bit for bit.
#include <cstdint>

#include "settle/core/status.hpp"

namespace settle::core::fixed {

struct GoldenResult {
  std::uint64_t build{0};    // every field of every built object (segments, tracks, cam knots)
  std::uint64_t ticks{0};    // every p, v, a of at_tick() and of the steppers, every tick
  std::uint32_t moves{0};    // objects built
  std::uint32_t samples{0};  // samples folded into `ticks`
  Status status{Status::ok}; // the first failure (then the checksums cover what came before it)
};

// No heap; about 3.5 KiB of static storage (not reentrant) and 1.5 KiB of stack besides plan()'s
// own (4.6 KiB on a Cortex-M0). The host's values are pinned in tests/core_fixed/test_golden.cpp.
[[nodiscard]] GoldenResult golden_checksum() noexcept;

}  // namespace settle::core::fixed
