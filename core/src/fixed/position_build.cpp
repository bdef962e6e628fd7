// SPDX-License-Identifier: Apache-2.0
// Planning time: a built motion becomes a position plan (position.hpp). The tracks' segment
// boundaries are merged into one timeline; at the first tick of each interval the weighted sum of
// the tracks is taken from the exact random-access integers (anchor.hpp) and turned into the
// stepping state. Doubles only bound magnitudes and drift and give the rotation's constants, with
// + - * / sqrt and the builders' libm-free sine (sources built -ffp-contract=off), so every target
// plans the same integers.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "anchor.hpp"
#include "build.hpp"
#include "settle/core/fixed/position.hpp"

namespace settle::core::fixed::detail {

namespace {

// Position drift the stepping may add to the random-access error within one interval (counts):
// the motion stepper's budget, so that stepped positions keep the at_tick() error bound + 1/16.
constexpr double kDriftBudget = 1.0 / 16;

// A non-negative real as (hi + lo 2^-32) 2^-exp with hi normalised: all 53 bits of the double.
struct Wide64 {
  std::uint32_t hi{0}, lo{0};
  int exp{0};
};
Wide64 split(double x) noexcept {
  if (!(x > 0.0)) return {};
  int e = 0;
  const double m = std::ldexp(std::frexp(x, &e), 32);  // [2^31, 2^32)
  const double hi = std::floor(m);
  return {static_cast<std::uint32_t>(hi), static_cast<std::uint32_t>(std::ldexp(m - hi, 32)), 32 - e};
}
double value(const Wide64& w) noexcept {
  return std::ldexp(static_cast<double>(w.hi) + std::ldexp(static_cast<double>(w.lo), -32), -w.exp);
}

// x f 2^extra for |f| as Wide64 (two floor products), negated when `negative`.
std::int64_t scale_by(std::int64_t x, const Wide64& f, int extra, bool negative) noexcept {
  if (f.hi == 0U) return 0;
  const std::int64_t r = mul_shift(x, f.hi, f.exp - extra) + mul_shift(x, f.lo, f.exp + 32 - extra);
  return negative ? -r : r;
}

// sin(2 pi x) for 0 <= x <= 1 (build::sin_turns covers half a turn).
double sin_full_turns(double x) noexcept { return x <= 0.5 ? build::sin_turns(x) : -build::sin_turns(1.0 - x); }

// What the tracks are doing over one interval, from the anchors at its first tick (bounds only).
struct Survey {
  int degree{0};
  int tracks{0};             // every track: each adds its floors to the sums
  bool trig{false};
  double ds_max{0.0};        // largest phase rate of the active segments (per tick)
  std::array<double, kMaxDegree + 1> b{};  // sum |w| |T_k| ds^k: Taylor coefficients in counts per tick^k
  double w{0.0};             // sum |w| |Z|: the sinusoid's amplitude bound (counts)
};

double weight_of(const Track& t) noexcept { return std::fabs(std::ldexp(static_cast<double>(t.weight), -30)); }

Status survey(const MotionView& m, std::int32_t n, Survey& s) noexcept {
  s = Survey{};
  s.tracks = m.hdr->tracks;
  for (unsigned i = 0; i < m.hdr->tracks; ++i) {
    const Track& t = m.trk[i];
    const TrackAnchor a = track_anchor(m, t, n);
    if (a.seg < 0 || a.seg >= m.hdr->segments) continue;
    const Segment& g = m.seg[a.seg];
    const double w = weight_of(t);
    const double ds = std::ldexp(static_cast<double>(g.ds), -63);
    s.degree = std::max<int>(s.degree, g.degree);
    s.ds_max = std::max(s.ds_max, ds);
    for (int k = 1; k <= g.degree; ++k) {
      const auto u = static_cast<std::size_t>(k);
      s.b[u] += w * std::fabs(std::ldexp(static_cast<double>(a.t[u]), -32)) * build::value(g.dsp[u - 1]);
    }
    if (g.trig) {
      s.trig = true;
      const double zr = std::ldexp(static_cast<double>(g.zr), -32), zi = std::ldexp(static_cast<double>(g.zi), -32);
      s.w += w * std::sqrt(zr * zr + zi * zi);
    }
  }
  if (s.trig && s.degree > 3) return Status::unsupported_request;  // x[4], x[5] hold the sinusoid
  return Status::ok;
}

// The rotation by d = 2 pi ds: c = 2 (1 - cos d) for the recurrence, s = sin d and u = 1 - cos d
// for the sinusoid's first difference; c's mantissa rounded (near) and to 53 bits (hi, lo).
struct Rotation {
  double c{0.0}, s{0.0}, u{0.0}, half_cos{0.0};
  std::uint32_t near{0};
  Wide64 wide{};
};
Rotation rotation(std::uint64_t ds_q63) noexcept {
  const double ds = std::ldexp(static_cast<double>(ds_q63), -63);
  const double h = build::sin_turns(ds / 2.0);  // sin(d/2)
  Rotation r{};
  r.u = 2.0 * h * h;
  r.c = 2.0 * r.u;
  r.s = sin_full_turns(ds);
  r.half_cos = std::sqrt(std::max(0.0, 1.0 - h * h));  // |cos(d/2)|
  r.wide = split(r.c);
  if (r.wide.hi != 0U) {  // the same exponent: the mantissa rounded, kept below 2^32
    const double m = std::nearbyint(std::ldexp(r.c, r.wide.exp));
    r.near = m >= 4294967296.0 ? 0xFFFFFFFFU : static_cast<std::uint32_t>(m);
  }
  return r;
}

// The phase rate every trigonometric segment shares (0: none); unsupported_request if they differ.
Status common_rate(const MotionView& m, std::uint64_t& ds) noexcept {
  ds = 0;
  for (unsigned k = 0; k < m.hdr->segments; ++k) {
    const Segment& g = m.seg[k];
    if (!g.trig) continue;
    if (ds != 0 && g.ds != ds) return Status::unsupported_request;
    ds = g.ds;
  }
  return Status::ok;
}

// How an interval of `len` ticks is stepped: the difference scales, the orders stepped, the
// sinusoid's format, and whether it all fits and stays within the drift budget.
struct Layout {
  std::array<int, kMaxDegree + 1> f{};  // F_i
  int steps{0};     // orders stepped: min(degree, len - 1), the only ones the interval's ticks see
  int terms{0};     // orders of the polynomial that enter them (all, or none for one tick)
  int dsh{0};
  bool precise{false};
  bool ok{false};
};

Layout layout(const Survey& s, const Rotation& r, double len, bool precise) noexcept {
  Layout out{};
  const int d = s.degree;
  // x[0] after j steps is sum_{i <= j} C(j, i) x_i(0): orders above len - 1 never reach an output,
  // so they are not stepped (the outputs are the same bits), which also keeps the chain from
  // extrapolating a sub-tick piece's polynomial (scaled to one tick) beyond the interval.
  const int e = std::min(d, static_cast<int>(std::min(len - 1.0, 8.0)));
  const int used = e == 0 ? 0 : d;  // x_0 alone is b_0; x_1.. take every b_m above them
  out.steps = e;
  out.terms = used;
  // |x_i(0)| = |Delta^i Q(0)| <= sum_m i! S(m, i) b_m (poly.cpp's sums), and a stepped order is
  // x_i(j) = sum_{k >= i} C(j, k - i) x_k(0), j <= len - 2 (before floors).
  std::array<double, kMaxDegree + 1> init{}, bound{};
  for (int i = 1; i <= used; ++i) {
    for (int m = i; m <= d; ++m) init[static_cast<std::size_t>(i)] += build::kDiff[m][i] * s.b[static_cast<std::size_t>(m)];
  }
  for (int i = 1; i <= used; ++i) {
    double b = init[static_cast<std::size_t>(i)];
    if (i <= e) {
      b = 0.0;
      for (int k = i; k <= e; ++k) b += build::choose(len - 1.0, k - i) * init[static_cast<std::size_t>(k)];
    }
    bound[static_cast<std::size_t>(i)] = b * (1.0 + 0x1p-20);
  }
  // Each order at the finest scale its bound allows (~60 significant bits). A step shifts right, so
  // the scales must not decrease: a lower order whose bound is smaller than a higher one's (a piece
  // starting at rest) takes the higher one's scale. Gaps stay within 62 bits.
  out.f[0] = 32;
  for (int i = 1; i <= kMaxDegree; ++i) {
    const auto u = static_cast<std::size_t>(i);
    out.f[u] = i <= used && bound[u] > 0.0 ? std::max(32, 60 - build::exponent(bound[u])) : INT32_MAX / 2;
  }
  for (int i = kMaxDegree - 1; i >= 1; --i) {
    const auto u = static_cast<std::size_t>(i);
    out.f[u] = std::min(out.f[u], out.f[u + 1]);
  }
  bool fits = true;
  for (int i = 1; i <= kMaxDegree; ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (i > used || !(bound[u] > 0.0)) {
      out.f[u] = out.f[u - 1];
      continue;
    }
    out.f[u] = std::clamp(out.f[u], out.f[u - 1], out.f[u - 1] + 62);
    if (bound[u] * std::ldexp(1.0, out.f[u]) >= 0x1p62) fits = false;
  }
  // Drift of x[0] after the interval: each order's initial rounding (the sums of the tracks' floored
  // terms) spread by the binomials, one floor per step and order, and the Q32.32 Taylor coefficients'
  // own floors carried over the interval's phases.
  const double k_tracks = s.tracks;
  double drift = 0.0;
  for (int i = 0; i <= e; ++i) {
    double sum = 2.0;
    for (int k = i; k <= d; ++k) sum += (k_tracks + 1.0) * build::kDiff[k][i];
    const double lsb = std::ldexp(1.0, -out.f[static_cast<std::size_t>(i)]);
    drift += build::choose(len, i) * sum * lsb;
    if (i < e) drift += build::choose(len, i + 1) * lsb;
  }
  double span = 0.0;
  for (int k = 0; k <= d; ++k) span += build::power(len * s.ds_max, k);
  drift += (k_tracks + 1.0) * (d + 2) * 0x1p-32 * span;
  if (s.trig) {
    // The recurrence e_{n+2} = (2 - c) e_{n+1} - e_n + injected error has the Green's function
    // sin(m d)/sin d, at most min(m, 1/|sin d|) (g below); the floors of y enter as differences,
    // each weighted at most 1/|cos(d/2)| (or 2m + 1).
    const double big = s.w * std::max(2.0 * std::sqrt(r.u / 2.0), r.c);  // |D|, |c y| (counts)
    out.dsh = std::clamp(29 - build::exponent(big + 0x1p-40), -30, 62);
    out.precise = precise;
    const double cq = precise ? value(r.wide) : std::ldexp(static_cast<double>(r.near), -r.wide.exp);
    const double dc = std::fabs(cq - r.c) + r.c * 0x1p-50;
    const double sd = std::fabs(r.s);
    const double g = sd * len > 1.0 ? 1.0 / sd : len;
    const double hc = r.half_cos * (2.0 * len + 1.0) > 1.0 ? 1.0 / r.half_cos : 2.0 * len + 1.0;
    const double ed = std::ldexp(precise ? 2.0 : 1.0, -(32 + out.dsh));
    const double e1 = std::ldexp(4.0, -(32 + out.dsh)) + s.w * (sd + r.c) * 0x1p-50;
    drift += dc * s.w * len * g + ed * len * g + 0x1p-32 * (len + 1.0) * hc + e1 * g;
    if (big * std::ldexp(1.0, 32 + out.dsh) >= 0x1p61) fits = false;
  }
  out.ok = fits && drift <= kDriftBudget;
  return out;
}

// The longest prefix of [n, end) that one interval can step, and its layout (len = 0: none, even
// one tick long).
std::int32_t choose_length(const Survey& s, const Rotation& r, std::int32_t n, std::int32_t end, Layout& out) noexcept {
  const std::int32_t full = end - n;
  out = layout(s, r, full, false);
  if (out.ok) return full;
  if (s.trig) {
    out = layout(s, r, full, true);
    if (out.ok) return full;
  }
  std::int32_t good = 0, bad = full;
  while (bad - good > 1) {
    const std::int32_t mid = good + (bad - good) / 2;
    if (layout(s, r, mid, s.trig).ok) {
      good = mid;
    } else {
      bad = mid;
    }
  }
  if (good > 0) out = layout(s, r, good, s.trig);
  return good;
}

// The exact state at tick n: weighted sums of the tracks' anchors, then differences.
void fill(const MotionView& m, std::int32_t n, const Survey& s, const Rotation& r, const Layout& lay,
          PositionInterval& out) noexcept {
  Coeffs b{};             // b[0]: Q32.32 counts; b[k]: counts per tick^k at 2^-F_k
  std::int64_t total = 0;  // sum of weighted (T_0 + Im W): what at_tick() rounds
  std::int64_t wr = 0, wi = 0;
  for (unsigned i = 0; i < m.hdr->tracks; ++i) {
    const Track& t = m.trk[i];
    const TrackAnchor a = track_anchor(m, t, n);
    if (a.seg < 0) continue;
    if (a.seg >= m.hdr->segments) {
      total += mul_shr(m.hdr->final_p, t.weight, 30U);
      continue;
    }
    const Segment& g = m.seg[a.seg];
    total += mul_shr(a.t[0] + a.wi, t.weight, 30U);
    for (int k = 1; k <= std::min<int>(g.degree, lay.terms); ++k) {
      const auto u = static_cast<std::size_t>(k);
      b[u] += apply(mul_shr(a.t[u], t.weight, 30U), g.dsp[u - 1], lay.f[u] - 32);
    }
    if (g.trig) {
      wr += mul_shr(a.wr, t.weight, 30U);
      wi += mul_shr(a.wi, t.weight, 30U);
    }
  }
  b[0] = total - wi;
  PositionInterval iv{};
  iv.first = n;
  iv.degree = static_cast<std::uint8_t>(lay.steps);
  for (int i = 0; i <= lay.steps; ++i) {  // Delta^i of sum_k b_k j^k at j = 0, at 2^-F_i
    std::int64_t acc = 0;
    for (int k = i; k <= lay.terms; ++k) {
      const auto u = static_cast<std::size_t>(k);
      acc += static_cast<std::int64_t>(build::kDiff[k][i]) * shift(b[u], lay.f[u] - lay.f[static_cast<std::size_t>(i)]);
    }
    iv.x[static_cast<std::size_t>(i)] = acc;
  }
  for (int i = 0; i < lay.steps; ++i) {
    const auto u = static_cast<std::size_t>(i);
    iv.sh[u] = static_cast<std::uint8_t>(lay.f[u + 1] - lay.f[u]);
  }
  if (s.trig) {
    iv.flags = PositionInterval::kTrig;
    iv.dsh = static_cast<std::int8_t>(lay.dsh);
    iv.x[4] = wi;
    // D_1 = Im(W (e^{i d} - 1)) = Re W sin d - Im W (1 - cos d), at 2^-(32 + dsh).
    iv.x[5] = scale_by(wr, split(std::fabs(r.s)), lay.dsh, r.s < 0.0) - scale_by(wi, split(r.u), lay.dsh, false);
    if (lay.precise) iv.flags |= PositionInterval::kPrecise;
  }
  out = iv;
}

// The first boundary after tick n: a tick at which some track enters a segment or ends.
std::int32_t next_boundary(const MotionView& m, std::int32_t n) noexcept {
  std::int32_t best = m.hdr->end_tick;
  for (unsigned i = 0; i < m.hdr->tracks; ++i) {
    const Track& t = m.trk[i];
    for (unsigned k = 0; k <= m.hdr->segments; ++k) {
      const std::int64_t edge = k < m.hdr->segments ? m.seg[k].start : m.hdr->end;
      const std::int32_t b = track_first_tick(t, edge);
      if (b > n && b < best) best = b;
    }
  }
  return best;
}

// Runs over every interval; writes them only when `out` is given. Returns the count in `count`.
Status plan_all(const MotionView& m, const Rotation& r, PositionInterval* out, std::size_t capacity,
                std::size_t& count) noexcept {
  count = 0;
  const std::int32_t end = m.hdr->end_tick;
  std::int32_t n = next_boundary(m, -1);
  while (n < end) {
    const std::int32_t natural = next_boundary(m, n);
    Survey s{};
    const Status st = survey(m, n, s);
    if (st != Status::ok) return st;
    Layout lay{};
    const std::int32_t len = choose_length(s, r, n, natural, lay);
    if (len <= 0) return Status::precision_insufficient;
    if (count >= capacity) return Status::table_too_small;
    if (out != nullptr) fill(m, n, s, r, lay, out[count]);
    ++count;
    n += len;
  }
  return Status::ok;
}

}  // namespace

Status build_position(const MotionView& m, PositionInterval* out, std::size_t capacity, PositionHeader* hdr) noexcept {
  std::uint64_t ds = 0;
  Status st = common_rate(m, ds);
  if (st != Status::ok) return st;
  const Rotation r = ds != 0 ? rotation(ds) : Rotation{};
  std::size_t count = 0;
  st = plan_all(m, r, nullptr, capacity, count);  // every check first: nothing written on failure
  if (st != Status::ok) return st;
  st = plan_all(m, r, out, capacity, count);
  if (st != Status::ok) return st;  // unreachable: the same deterministic pass succeeded
  hdr->end_tick = m.hdr->end_tick;
  hdr->target = m.hdr->target;
  hdr->rot_near = r.near;
  hdr->rot_hi = r.wide.hi;
  hdr->rot_lo = r.wide.lo;
  hdr->rot_exp = static_cast<std::int16_t>(r.wide.exp);
  hdr->intervals = static_cast<std::uint16_t>(count);
  return Status::ok;
}

}  // namespace settle::core::fixed::detail
