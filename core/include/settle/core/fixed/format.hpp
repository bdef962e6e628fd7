// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the fixed-point evaluators take and give: the scale from SI to drive units, the integer
// sample the servo loop streams, and the formats of its fields. This comment is the reference for
// every format in core/fixed (docs/fixed-point.md explains the choices and the error budget).
//
//   tick n          int32 ticks since the move started; a move lasts at most 2^30 ticks
//   Sample::p       int32 counts relative to the start of the move (|p| < 2^30); absolute() adds
//                   the start position modulo 2^32, as CiA 402 position objects wrap
//   Sample::v       int32 counts/tick   in Q(32-vf).vf, vf = Scale::velocity_frac_bits (16)
//   Sample::a       int32 counts/tick^2 in Q(32-af).af, af = Scale::accel_frac_bits (16)
//   internal p,v,a  int64 Q32.32 of the same units
//   segment phase   uint64 Q1.63 (0..1 across a segment); bits 31..62 are its angle in Q0.32 turns
//   sin, cos        int32 Q2.30
//   FD chains       int64, order i at 2^-F_i with F_0 = 32 and F_i chosen per segment (~60 bits)
//   rates           Factor: 32-bit mantissa and shift (ds^k, 2 pi ds, rotation by 2 pi ds)
//   shaper impulse  int32 whole-tick delay + uint32 Q0.32 fraction; weight int32 Q2.30, sum 2^30
//   cam knots       int32 p, v, a with per-table fraction bits (CamTable::formats())
#include <cstdint>

#include "settle/core/axis_scale.hpp"
#include "settle/core/fixed/qmath.hpp"

namespace settle::core::fixed {

// How SI maps to the drive (the axis's counts per unit and servo period, one tick per period) and
// how many fraction bits the velocity and acceleration outputs carry.
struct Scale {
  AxisScale axis{};
  int velocity_frac_bits{16};   // 0..30
  int accel_frac_bits{16};      // 0..30
};

struct Sample {
  std::int32_t p{0};  // counts from the start of the move
  std::int32_t v{0};  // counts/tick * 2^velocity_frac_bits
  std::int32_t a{0};  // counts/tick^2 * 2^accel_frac_bits
};

// Absolute drive position from the move's start and a relative position, wrapping modulo 2^32
// exactly as the drive's INTEGER32 position does (a move may cross the wrap).
[[nodiscard]] constexpr std::int32_t absolute(std::int32_t start, std::int32_t relative) noexcept {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(start) + static_cast<std::uint32_t>(relative));
}

// The wide accumulators of one evaluation: p, v, a in Q32.32 of counts, counts/tick, counts/tick^2.
struct Wide {
  std::int64_t p{0};
  std::int64_t v{0};
  std::int64_t a{0};
};

// The streamed sample: rounded to the output formats, saturated (never wrapped) should a value
// ever leave them, which the builders' range checks rule out.
[[nodiscard]] constexpr Sample to_sample(const Wide& w, unsigned v_frac, unsigned a_frac) noexcept {
  return {saturate_i32(round_shr(w.p, 32U)), saturate_i32(round_shr(w.v, 32U - v_frac)),
          saturate_i32(round_shr(w.a, 32U - a_frac))};
}

}  // namespace settle::core::fixed
