// SPDX-License-Identifier: Apache-2.0
// The tick path of PositionStepper: integer arithmetic only (no float, no division), so every
// target produces the same integers. A tick adds the forward differences, runs the sinusoid's
// recurrence (one product), and at the last tick of an interval copies the next interval's state
// instead of stepping, so that no tick does both.
#include <cstdint>

#include "settle/core/fixed/position.hpp"
#include "settle/core/fixed/qmath.hpp"

namespace settle::core::fixed::detail {

namespace {

void load(const PositionView& p, PositionState& s, std::int32_t index) noexcept {
  s.index = index;
  s.cur = p.iv[index];
  s.until = index + 1 < p.hdr->intervals ? p.iv[index + 1].first : p.hdr->end_tick;
}

// One tick of the differences, unrolled per degree (on a Cortex-M0 a loop costs twice as much).
void step_chain(std::int64_t* x, unsigned degree, const std::uint8_t* sh) noexcept {
  switch (degree) {
    case 5:
      x[0] += x[1] >> sh[0];
      x[1] += x[2] >> sh[1];
      x[2] += x[3] >> sh[2];
      x[3] += x[4] >> sh[3];
      x[4] += x[5] >> sh[4];
      break;
    case 4:
      x[0] += x[1] >> sh[0];
      x[1] += x[2] >> sh[1];
      x[2] += x[3] >> sh[2];
      x[3] += x[4] >> sh[3];
      break;
    case 3:
      x[0] += x[1] >> sh[0];
      x[1] += x[2] >> sh[1];
      x[2] += x[3] >> sh[2];
      break;
    case 2:
      x[0] += x[1] >> sh[0];
      x[1] += x[2] >> sh[1];
      break;
    case 1: x[0] += x[1] >> sh[0]; break;
    default: break;
  }
}

void advance(PositionInterval& c, const PositionHeader& h) noexcept {
  step_chain(c.x.data(), c.degree, c.sh.data());
  if ((c.flags & PositionInterval::kTrig) != 0U) {
    std::int64_t& y = c.x[4];
    std::int64_t& d = c.x[5];
    y += shift(d, c.dsh);
    const int sh = h.rot_exp - c.dsh;
    if ((c.flags & PositionInterval::kPrecise) != 0U) {
      d -= mul_shift(y, h.rot_hi, sh) + mul_shift(y, h.rot_lo, sh + 32);
    } else {
      d -= mul_shift(y, h.rot_near, sh);
    }
  }
}

}  // namespace

std::int32_t position_next(const PositionView& p, PositionState& s) noexcept {
  const std::int32_t n = s.n;
  if (n < INT32_MAX) s.n = n + 1;
  const PositionHeader& h = *p.hdr;
  if (n >= h.end_tick) return h.target;
  if (s.index < 0) {  // before the first interval: at rest on 0
    if (n + 1 >= s.until && h.intervals > 0) load(p, s, 0);
    return 0;
  }
  PositionInterval& c = s.cur;
  std::int64_t x = c.x[0];
  if ((c.flags & PositionInterval::kTrig) != 0U) x += c.x[4];
  if (n + 1 < s.until) {
    advance(c, h);
  } else if (s.index + 1 < h.intervals) {
    load(p, s, s.index + 1);
  }
  return saturate_i32(round_shr(x, 32U));
}

void position_restart(const PositionView& p, PositionState& s, std::int32_t n) noexcept {
  const PositionHeader& h = *p.hdr;
  s.n = n;
  s.index = -1;
  s.until = h.intervals > 0 ? p.iv[0].first : h.end_tick;
  if (h.intervals == 0 || n < p.iv[0].first || n >= h.end_tick) return;
  std::int32_t lo = 0, hi = h.intervals - 1;  // the last interval starting at or before n
  while (lo < hi) {
    const std::int32_t mid = (lo + hi + 1) >> 1;
    if (p.iv[mid].first <= n) {
      lo = mid;
    } else {
      hi = mid - 1;
    }
  }
  load(p, s, lo);
  for (std::int32_t k = s.cur.first; k < n; ++k) advance(s.cur, h);
}

}  // namespace settle::core::fixed::detail
