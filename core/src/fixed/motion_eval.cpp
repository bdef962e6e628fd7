// SPDX-License-Identifier: Apache-2.0
// The tick path of BasicMotion: integer arithmetic only (no float, no division), so every target
// produces the same integers. Random access and stepping share locate(), the anchor evaluation
// and finish(); stepping differs only inside a segment, where it adds differences and rotates.
#include <cstdint>

#include "anchor.hpp"
#include "settle/core/fixed/motion.hpp"
#include "settle/core/fixed/poly.hpp"
#include "settle/core/fixed/qmath.hpp"
#include "settle/core/fixed/trig.hpp"

namespace settle::core::fixed::detail {

namespace {

enum class Mode : std::uint8_t { unset, before, step, random, after };

// Where track t is at tick n: -1 before its start, hdr.segments after its end, else the segment,
// with u = ticks into that segment (Q32.32).
struct Where {
  int seg;
  std::int64_t u;
};

Where locate(const MotionView& m, const Track& t, std::int32_t n) noexcept {
  const std::int64_t x =
      static_cast<std::int64_t>(static_cast<std::uint64_t>(static_cast<std::int64_t>(n) - t.delay) << 32) - t.frac;
  if (x < 0) return {-1, 0};
  const int count = m.hdr->segments;
  if (x >= m.hdr->end) return {count, 0};
  int lo = 0, hi = count - 1;  // largest k with start <= x; start[0] = 0
  while (lo < hi) {
    const int mid = (lo + hi + 1) >> 1;
    if (m.seg[mid].start <= x) {
      lo = mid;
    } else {
      hi = mid - 1;
    }
  }
  return {lo, x - m.seg[lo].start};
}

// The first tick at which track t's local time reaches `edge` (Q32.32 ticks), i.e.
// delay + ceil((edge + frac) / 2^32).
std::int32_t first_tick_at(const Track& t, std::int64_t edge) noexcept {
  const std::int64_t x = edge + static_cast<std::int64_t>(t.frac);
  return static_cast<std::int32_t>(t.delay + ((x + 0xFFFFFFFFLL) >> 32));
}

// Phase after u ticks (Q32.32): whole ticks times ds modulo 2^64 plus the fraction's share, the
// same integers the stepper accumulates (so both forms see the same phase).
std::uint64_t phase_at(const Segment& g, std::int64_t u) noexcept {
  const auto m = static_cast<std::uint32_t>(static_cast<std::uint64_t>(u) >> 32);
  const auto f = static_cast<std::uint32_t>(u);
  const auto dh = static_cast<std::uint32_t>(g.ds >> 32);
  const auto dl = static_cast<std::uint32_t>(g.ds);
  const std::uint64_t whole = umul_wide(m, dl) + (static_cast<std::uint64_t>(m * dh) << 32);
  const std::uint64_t part = umul_wide(f, dh) + (umul_wide(f, dl) >> 32);
  return whole + part;
}

// Z e^{2 pi i s}, the angle rounded to Q0.32 turns.
void phasor(const Segment& g, std::uint64_t phase, std::int64_t& wr, std::int64_t& wi) noexcept {
  const SinCos sc = sincos(static_cast<std::uint32_t>((phase + (std::uint64_t{1} << 30)) >> 31));
  wr = mul_shr(g.zr, sc.cos, kTrigBits) - mul_shr(g.zi, sc.sin, kTrigBits);
  wi = mul_shr(g.zr, sc.sin, kTrigBits) + mul_shr(g.zi, sc.cos, kTrigBits);
}

// The trigonometric term's p, v, a from the phasor: Im W, 2 pi ds Re W, -(2 pi ds)^2 Im W.
void add_phasor(const Segment& g, std::int64_t wr, std::int64_t wi, Wide& w) noexcept {
  w.p += wi;
  w.v += apply(wr, g.kv);
  w.a -= apply(wi, g.ka);
}

// Random access needs T_0..T_2 (p, v, a): three passes of the shift.
constexpr int ra_passes(int degree) noexcept { return degree < 3 ? degree : 3; }

// Taylor coefficients of the polynomial part at the phase, to `passes` orders. T_0..T_2 are then
// refined for the phase bits below Q1.31 (T_k with T_{k+1}, so T_2 only when T_3 is final after
// three passes) by the same rule whatever `passes`, so the stepper's anchor equals random access.
Coeffs taylor_at(const Segment& g, std::uint64_t phase, int passes) noexcept {
  Coeffs t = g.c;
  taylor_shift(t, g.degree, static_cast<std::uint32_t>(phase >> 32), passes);
  const int ra = ra_passes(g.degree);
  taylor_refine(t, g.degree, static_cast<std::uint32_t>(phase), ra == g.degree ? ra : ra - 1);
  return t;
}

// Random access inside a segment: p = P(s), v = ds P'(s), a = ds^2 P''(s), plus the phasor.
Wide eval_segment(const Segment& g, std::uint64_t phase) noexcept {
  const Coeffs t = taylor_at(g, phase, ra_passes(g.degree));
  Wide w{t[0], 0, 0};
  if (g.degree >= 1) w.v = apply(t[1], g.dsp[0]);
  if (g.degree >= 2) w.a = apply(t[2], g.dsp[1], 1);
  if (g.trig) {
    std::int64_t wr = 0, wi = 0;
    phasor(g, phase, wr, wi);
    add_phasor(g, wr, wi, w);
  }
  return w;
}

Wide eval_track(const MotionView& m, const Track& t, std::int32_t n) noexcept {
  const Where w = locate(m, t, n);
  if (w.seg < 0) return {};
  if (w.seg >= m.hdr->segments) return {m.hdr->final_p, 0, 0};
  const Segment& g = m.seg[w.seg];
  return eval_segment(g, phase_at(g, w.u));
}

void accumulate(Wide& total, const Wide& x, std::int32_t weight) noexcept {
  total.p += mul_shr(x.p, weight, 30U);
  total.v += mul_shr(x.v, weight, 30U);
  total.a += mul_shr(x.a, weight, 30U);
}

Sample finish(const MotionHeader& h, const Wide& w) noexcept { return to_sample(w, h.v_frac, h.a_frac); }

Sample at_rest(const MotionHeader& h) noexcept { return {h.target, 0, 0}; }

// Stepping: anchor on segment g at the track's tick (exact Taylor coefficients scaled to tick
// units, then differences), or fall back to random access where the builder found drift too large.
void anchor(const Segment& g, std::int64_t u, TrackState& s) noexcept {
  const std::uint64_t phase = phase_at(g, u);
  if (!g.steppable) {
    s.mode = static_cast<std::uint8_t>(Mode::random);
    return;
  }
  Coeffs b = taylor_at(g, phase, g.degree);
  int f = 0;  // F_i - 32
  for (int i = 1; i <= g.degree; ++i) {
    f += g.sh[static_cast<unsigned>(i)];
    b[static_cast<unsigned>(i)] = apply(b[static_cast<unsigned>(i)], g.dsp[static_cast<unsigned>(i - 1)], f);
  }
  chains_init(b, g.degree, g.sh, s.fd);
  s.wr = 0;
  s.wi = 0;
  if (g.trig) phasor(g, phase, s.wr, s.wi);
  s.mode = static_cast<std::uint8_t>(Mode::step);
}

void advance(const Segment& g, TrackState& s) noexcept {
  chains_step(s.fd, g.degree, g.sh);
  if (g.trig) {
    const std::int64_t k1 = apply(s.wr + s.wi, g.rot_u);
    const std::int64_t k2 = apply(s.wr, g.rot_sum);
    const std::int64_t k3 = apply(s.wi, g.rot_diff);
    s.wr -= k1 + k3;
    s.wi += k2 - k1;
  }
}

Wide step_track(const MotionView& m, const Track& t, TrackState& s, std::int32_t n) noexcept {
  const MotionHeader& h = *m.hdr;
  if (s.mode == static_cast<std::uint8_t>(Mode::unset) || n >= s.until) {
    const Where w = locate(m, t, n);
    s.seg = w.seg;
    if (w.seg < 0) {
      s.mode = static_cast<std::uint8_t>(Mode::before);
      s.until = first_tick_at(t, 0);
    } else if (w.seg >= h.segments) {
      s.mode = static_cast<std::uint8_t>(Mode::after);
      s.until = INT32_MAX;
    } else {
      s.until = first_tick_at(t, w.seg + 1 < h.segments ? m.seg[w.seg + 1].start : h.end);
      anchor(m.seg[w.seg], w.u, s);
    }
  }
  switch (static_cast<Mode>(s.mode)) {
    case Mode::before: return {};
    case Mode::after: return {h.final_p, 0, 0};
    case Mode::random: return eval_track(m, t, n);
    default: break;
  }
  const Segment& g = m.seg[s.seg];
  Wide w = chains_value(s.fd, g.degree, g.sh);
  if (g.trig) add_phasor(g, s.wr, s.wi, w);
  if (n + 1 < s.until) advance(g, s);
  return w;
}

}  // namespace

Sample motion_at(const MotionView& m, std::int32_t n) noexcept {
  const MotionHeader& h = *m.hdr;
  if (n >= h.end_tick) return at_rest(h);
  if (h.unit_weight) return finish(h, eval_track(m, m.trk[0], n));
  Wide total{};
  for (unsigned i = 0; i < h.tracks; ++i) accumulate(total, eval_track(m, m.trk[i], n), m.trk[i].weight);
  return finish(h, total);
}

Sample motion_next(const MotionView& m, TrackState* st, std::int32_t n) noexcept {
  const MotionHeader& h = *m.hdr;
  if (n >= h.end_tick) return at_rest(h);
  if (h.unit_weight) return finish(h, step_track(m, m.trk[0], st[0], n));
  Wide total{};
  for (unsigned i = 0; i < h.tracks; ++i) accumulate(total, step_track(m, m.trk[i], st[i], n), m.trk[i].weight);
  return finish(h, total);
}

TrackAnchor track_anchor(const MotionView& m, const Track& t, std::int32_t n) noexcept {
  const Where w = locate(m, t, n);
  TrackAnchor a{};
  a.seg = w.seg;
  if (w.seg < 0 || w.seg >= m.hdr->segments) return a;
  const Segment& g = m.seg[w.seg];
  const std::uint64_t phase = phase_at(g, w.u);
  a.t = taylor_at(g, phase, g.degree);
  if (g.trig) phasor(g, phase, a.wr, a.wi);
  return a;
}

std::int32_t track_first_tick(const Track& t, std::int64_t edge) noexcept { return first_tick_at(t, edge); }

void motion_restart(TrackState* st, std::size_t count) noexcept {
  for (std::size_t i = 0; i < count; ++i) st[i].mode = static_cast<std::uint8_t>(Mode::unset);
}

}  // namespace settle::core::fixed::detail
