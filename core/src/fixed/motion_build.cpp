// SPDX-License-Identifier: Apache-2.0
// Planning time: a Move<double> becomes segments and tracks (motion.hpp). Every profile is first
// described as pieces in double (a polynomial in the piece's phase plus a phasor), then each
// piece is quantised with its bounds checked; only when every check passes is the output written.
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <type_traits>

#include "build.hpp"
#include "hermite.hpp"
#include "settle/core/fixed/motion.hpp"

namespace settle::core::fixed::detail {

namespace {

using build::Ctx;
using build::kTwoPi;

// Error budgets (counts for p; v and a relative to one output LSB plus a share of their bound).
constexpr double kRandomAccessBudget = 0.375;  // position error of at_tick before rounding
constexpr double kStepDriftBudget = 1.0 / 16;  // extra position error the stepper may add
// Pseudo-polynomial fit: counts for p (a one-tick piece may use up to the short tolerance); for v
// and a, half an output LSB or this fraction of the move's mean velocity D/T (mean
// "acceleration" D/T^2), whichever is larger.
constexpr double kFitPositionTolerance = 1.0 / 32;
constexpr double kFitVelocityTolerance = 0x1p-16;
constexpr double kFitAccelTolerance = 0x1p-12;
constexpr double kFitShortPositionTolerance = 0.25;
constexpr std::size_t kMaxFitPieces = 64;

// Every profile reaches the builder as pieces (settle/core/piece.hpp): the closed-form shapes give
// their own exact decomposition (piece_count(), piece(i)); a pseudo-polynomial is fitted below.
static_assert(kMaxPieceDegree == static_cast<std::size_t>(kMaxDegree), "a piece is what a segment holds");

template <typename S>
concept ClosedForm = requires(const S& s, int i) {
  { s.piece_count() } -> std::same_as<int>;
  { s.piece(i) } -> std::same_as<Piece>;
};

// The unit pseudo-polynomial phi(s) = 1 - sum C_i (1 - s)^g_i with phi' and phi''.
struct UnitShape {
  const PseudoPolyParams* p;
  void at(double s, double out[3]) const noexcept {
    const double w = 1.0 - s;
    double pp = 0.0, v = 0.0, a = 0.0;
    for (std::size_t i = 0; i < p->count; ++i) {
      const double g = p->gammas[i], c = p->coeffs[i];
      const double w2 = build::power(w, g - 2.0);  // g > 2 (pseudo_poly_design)
      pp += c * w2 * w * w;
      v += c * g * w2 * w;
      a += c * g * (g - 1.0) * w2;
    }
    out[0] = 1.0 - pp;
    out[1] = v;
    out[2] = -a;
  }
  // Quintic Hermite of phi on [sa, sb] in the local phase.
  [[nodiscard]] std::array<double, 6> hermite(double sa, double sb) const noexcept {
    const double h = sb - sa;
    double e0[3], e1[3];
    at(sa, e0);
    at(sb, e1);
    return hermite::quintic(e0[0], h * e0[1], h * h * e0[2], e1[0], h * e1[1], h * h * e1[2]);
  }
};

// The pieces of a profile or of a blend, produced on demand (so that no array of doubles sits on
// an M0 stack).
class Pieces {
 public:
  Status init(const Profile<double>& prof, const Ctx& ctx, std::size_t capacity) noexcept {
    prof_ = &prof;
    return prof.visit([&](const auto& p) { return init_one(p, ctx, capacity); });
  }
  Status init(const Blend& b) noexcept {
    blend_ = &b;
    return init_one(b, Ctx{}, 0);
  }
  [[nodiscard]] int count() const noexcept { return count_; }
  [[nodiscard]] Piece get(int i) const noexcept {
    if (blend_ != nullptr) return blend_->piece(i);
    return prof_->visit([&](const auto& p) { return get_one(p, i); });
  }

 private:
  template <ClosedForm S>
  Status init_one(const S& p, const Ctx&, std::size_t) noexcept {
    count_ = p.duration() > 0.0 ? p.piece_count() : 0;
    for (int i = 0; i < count_; ++i) {
      if (!(p.piece(i).length > 0.0)) return Status::bad_shape_parameter;
    }
    return Status::ok;
  }
  Status init_one(const PseudoPoly<double>& p, const Ctx& ctx, std::size_t capacity) noexcept;

  template <ClosedForm S>
  Piece get_one(const S& p, int i) const noexcept {
    return p.piece(i);
  }
  Piece get_one(const PseudoPoly<double>& p, int i) const noexcept {
    const auto& pp = p.params();
    const UnitShape u{&pp};
    const double sa = knots_[static_cast<std::size_t>(i)], sb = knots_[static_cast<std::size_t>(i + 1)];
    const auto h = u.hermite(sa, sb);
    Piece pc{};
    pc.start = sa * pp.duration;
    pc.length = (sb - sa) * pp.duration;
    for (std::size_t k = 0; k < 6; ++k) pc.c[k] = pp.distance * h[k];
    return pc;
  }

  const Profile<double>* prof_{nullptr};
  const Blend* blend_{nullptr};
  int count_{0};
  std::array<double, kMaxFitPieces + 1> knots_{};
};

// Pseudo-polynomial: quintic Hermite pieces matching p, v, a at their ends, each as long as the
// tolerances allow at seven interior points. Integer exponents up to 5 are one exact piece;
// (1 - s)^g with g not whole needs ever shorter pieces towards s = 1, where it is least smooth.
Status Pieces::init_one(const PseudoPoly<double>& p, const Ctx& ctx, std::size_t capacity) noexcept {
  const auto& pp = p.params();
  count_ = 0;
  if (!(pp.duration > 0.0) || pp.distance == 0.0) return Status::ok;
  const UnitShape u{&pp};
  const double ticks = pp.duration / ctx.dt;
  const double pscale = std::fabs(pp.distance) * ctx.cpu;  // counts per unit of phi
  const double vscale = pscale / ticks, ascale = vscale / ticks;
  const double tol_p = kFitPositionTolerance / pscale;
  const double tol_p_short = kFitShortPositionTolerance / pscale;
  const double tol_v = std::max(0.5 * ctx.v_lsb() / vscale, kFitVelocityTolerance);
  const double tol_a = std::max(0.5 * ctx.a_lsb() / ascale, kFitAccelTolerance);
  // Largest |Hermite - phi| of p, v, a at seven interior points of [sa, sb], in counts and LSB.
  auto misfit = [&](double sa, double sb, double tol_pos) {
    const double h = sb - sa;
    const auto c = u.hermite(sa, sb);
    int worst = 0;
    for (int k = 1; k < 8; ++k) {
      const double x = k / 8.0;
      double e[3];
      u.at(sa + h * x, e);
      const double hp = c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * (c[4] + x * c[5]))));
      const double hv = c[1] + x * (2.0 * c[2] + x * (3.0 * c[3] + x * (4.0 * c[4] + x * 5.0 * c[5])));
      const double ha = 2.0 * c[2] + x * (6.0 * c[3] + x * (12.0 * c[4] + x * 20.0 * c[5]));
      if (!(std::fabs(hp - e[0]) <= tol_pos)) return 2;  // position: the requirement
      if (!(std::fabs(hv / h - e[1]) <= tol_v && std::fabs(ha / (h * h) - e[2]) <= tol_a)) worst = 1;
    }
    return worst;
  };
  // Greedy: from each knot the longest piece that meets every tolerance, found by halving and then
  // bisecting between the last failure and the first success. Where (1 - s)^g is not smooth even
  // a one-tick piece may miss the v and a tolerances (reported, not refused) and may use more of
  // the count budget for p; a move whose one-tick piece still misses that is refused.
  const double one_tick = 1.0 / ticks;
  const std::size_t cap = std::min(capacity, kMaxFitPieces);
  std::size_t nk = 1;
  knots_[0] = 0.0;
  while (knots_[nk - 1] < 1.0) {
    if (nk > cap) return Status::table_too_small;
    const double sa = knots_[nk - 1], rem = 1.0 - sa;
    double ok = 0.0, bad = rem;
    for (double h = rem; ok == 0.0; h *= 0.5) {
      if (h < one_tick) {
        ok = std::min(rem, one_tick);
        if (misfit(sa, sa + ok, tol_p_short) == 2) return Status::precision_insufficient;
        bad = ok;
      } else if (misfit(sa, sa + h, tol_p) == 0) {
        ok = h;
      } else {
        bad = h;
      }
    }
    for (int it = 0; it < 4 && bad > ok; ++it) {
      const double mid = 0.5 * (ok + bad);
      if (misfit(sa, sa + mid, tol_p) == 0) {
        ok = mid;
      } else {
        bad = mid;
      }
    }
    knots_[nk++] = ok >= rem ? 1.0 : sa + ok;
  }
  count_ = static_cast<int>(nk - 1);
  return Status::ok;
}

// ---- Quantisation of one piece -----------------------------------------------------------------

// Magnitudes of a segment over s in [0, 1], for the range checks of the whole move.
struct Bounds {
  double p{0.0}, v{0.0}, a{0.0};
};

// Forward-difference scales and whether the drift they allow over the segment is within budget.
// `c` is the polynomial in counts per power of the phase, `ra` its sweep over one segment.
void plan_stepping(Segment& g, const std::array<double, 6>& c, const build::Sweep& ra, double absz, double eff,
                   const Ctx& ctx, const Bounds& bd) noexcept {
  const int d = g.degree;
  const double ds = 1.0 / eff;
  const double m_ticks = std::floor(eff) + 1.0;
  // |Delta^k Q| <= ds^k sup |P^(k)| with the sup over the phases the differences reach (up to
  // d + 1 ticks past the end); the anchor's Taylor coefficients b_k <= ds^k sup |T_k| over [0, 1].
  const build::Sweep fd = build::sweep(c, d, 1.0 + (d + 1) * ds);
  std::array<double, 6> bmax{}, bnd{};
  for (int k = 0; k <= d; ++k) {
    const auto u = static_cast<std::size_t>(k);
    bmax[u] = build::power(ds, k) * ra.t[u];
    bnd[u] = build::power(ds, k) * build::falling(k, k) * fd.t[u];
  }
  for (int r = 0; r <= 2; ++r) {  // the anchor's sums must fit too
    for (int i = 0; i + r <= d; ++i) {
      auto& b = bnd[static_cast<std::size_t>(i + r)];
      b = std::max(b, build::chain_sum_bound(bmax, d, r, i, [](int) { return 1.0; }));
    }
  }
  std::array<int, 6> f{32, 32, 32, 32, 32, 32};
  bool fits = true;
  for (int i = 1; i <= d; ++i) {
    const auto u = static_cast<std::size_t>(i);
    int fi = bnd[u] > 0.0 ? 60 - build::exponent(bnd[u]) : f[u - 1];
    fi = std::clamp(fi, f[u - 1], f[u - 1] + 62);
    f[u] = fi;
    g.sh[u] = static_cast<std::uint8_t>(fi - f[u - 1]);
    if (bnd[u] * std::ldexp(1.0, fi) >= 0x1p62) fits = false;
  }
  // Drift of each chain's head after the segment's last step: initial rounding propagated by the
  // binomials, plus one floor per step and order (poly.hpp's shifts).
  auto drift = [&](int r) {
    double e = std::ldexp(1.0, -32);
    for (int i = 0; i + r <= d; ++i) {
      double init = 2.0;
      for (int m = i; m + r <= d; ++m) init += build::kDiff[m][i] * build::falling(m + r, r);
      const double lsb = std::ldexp(1.0, -f[static_cast<std::size_t>(i + r)]);
      e += build::choose(m_ticks, i) * init * lsb;
      if (i + r < d) e += build::choose(m_ticks, i + 1) * lsb;
    }
    return e;
  };
  const double kv = build::value(g.kv), ka = build::value(g.ka);
  const double ew = g.trig ? m_ticks * 4.0 * 0x1p-32 +
                                 absz * m_ticks * (build::value(g.rot_u) + build::value(g.rot_sum)) * 0x1p-31
                           : 0.0;
  g.steppable = fits && (!g.trig || eff >= 4.0) && drift(0) + ew <= kStepDriftBudget &&
                drift(1) + kv * ew <= 0.25 * ctx.v_lsb() + bd.v * 0x1p-28 &&
                drift(2) + ka * ew <= 0.25 * ctx.a_lsb() + bd.a * 0x1p-28;
}

// Converts one piece. `bd` receives its magnitudes; nothing is written on failure.
Status make_segment(const Piece& pc, const Ctx& ctx, Segment& out, Bounds& bd) noexcept {
  const double tau = pc.length / ctx.dt;
  const double start = pc.start / ctx.dt;
  if (!(tau > 0.0) || !std::isfinite(tau) || !(start + tau < build::kTwo30)) return Status::duration_does_not_fit;
  if (pc.trig && tau < 1.0) return Status::transition_shorter_than_tick;
  // A polynomial piece shorter than a tick holds at most one tick: describe it over one tick.
  const double eff = tau < 1.0 ? 1.0 : tau;
  std::array<double, 6> c{};
  int degree = 0;
  for (int k = 0; k <= kMaxDegree; ++k) {
    const auto u = static_cast<std::size_t>(k);
    c[u] = pc.c[u] * ctx.cpu * build::power(eff / tau, k);
    if (c[u] != 0.0) degree = k;
  }
  const double zr = pc.zr * ctx.cpu, zi = pc.zi * ctx.cpu;
  const double absz = std::sqrt(zr * zr + zi * zi);
  // Ticks see phases below 1 (below tau when the piece was stretched to one tick).
  const build::Sweep ra = build::sweep(c, degree, std::min(tau, 1.0) + 0x1p-20);
  if (!std::isfinite(ra.inter + absz) || !(ra.inter < build::kTwo30) || !(ra.t[0] + absz < build::kTwo30)) {
    return Status::distance_does_not_fit;
  }
  const double ds = 1.0 / eff, w = kTwoPi * ds;
  bd.p = ra.t[0] + absz;
  bd.v = ds * ra.t[1] + w * absz;
  bd.a = 2.0 * ds * ds * ra.t[2] + w * w * absz;
  if (!(bd.v < build::kTwo30)) return Status::velocity_does_not_fit;
  if (!(bd.a < build::kTwo30)) return Status::acceleration_does_not_fit;
  // Random-access error before rounding: Horner's floors, the phasor's products, sin/cos (0.8 LSB
  // each) and the angle rounded to 2^-33 turn.
  const double err = (degree + 3) * 0x1p-32 + absz * (1.6 * 0x1p-30 + kTwoPi * 0x1p-33);
  if (!(err <= kRandomAccessBudget)) return Status::precision_insufficient;

  Segment g{};
  g.start = build::q32(start);
  g.ds = eff == 1.0 ? (std::uint64_t{1} << 63)
                    : static_cast<std::uint64_t>(std::nearbyint(std::ldexp(ds, 63)));
  for (std::size_t k = 0; k <= kMaxDegree; ++k) g.c[k] = build::q32(c[k]);
  g.zr = build::q32(zr);
  g.zi = build::q32(zi);
  double dsk = 1.0;
  for (std::size_t k = 0; k < kMaxDegree; ++k) {
    dsk *= ds;
    g.dsp[k] = build::factor(dsk);
  }
  g.trig = pc.trig && absz > 0.0;
  g.degree = static_cast<std::uint8_t>(degree);
  g.kv = build::factor(w);
  g.ka = build::factor(w * w);
  if (g.trig && eff >= 4.0) {  // a quarter turn per tick at most, so that s - u >= 0
    const double half = build::sin_turns(ds / 2.0);
    const double u = 2.0 * half * half, sn = build::sin_turns(ds);
    g.rot_u = build::factor(u);
    g.rot_sum = build::factor(sn + u);
    g.rot_diff = build::factor(sn - u);
  }
  plan_stepping(g, c, ra, absz, eff, ctx, bd);
  out = g;
  return Status::ok;
}

// ---- Tracks ------------------------------------------------------------------------------------

struct TrackSet {
  std::array<Track, kMaxImpulses> t{};
  std::size_t n{0};
  double weight_sum{0.0};  // sum |w|: scales every bound of the weighted sum
};

Status make_tracks(const Shaper<double>& s, const Ctx& ctx, TrackSet& out) noexcept {
  out.n = s.count;
  std::int64_t sum = 0;
  std::size_t largest = 0;
  for (std::size_t i = 0; i < s.count; ++i) {
    const double amp = s.amp[i], o = s.time[i] / ctx.dt;
    if (!std::isfinite(amp) || !(std::fabs(amp) < 2.0)) return Status::impulse_does_not_fit;
    if (!std::isfinite(o) || !(o >= 0.0 && o < build::kTwo30)) return Status::duration_does_not_fit;
    double whole = std::floor(o);
    double frac = std::nearbyint(std::ldexp(o - whole, 32));
    if (frac >= 4294967296.0) {
      whole += 1.0;
      frac = 0.0;
    }
    Track& t = out.t[i];
    t.delay = static_cast<std::int32_t>(whole);
    t.frac = static_cast<std::uint32_t>(frac);
    t.weight = static_cast<std::int32_t>(std::nearbyint(amp * build::kTwo30));
    sum += t.weight;
    if (std::abs(t.weight) > std::abs(out.t[largest].weight)) largest = i;
  }
  // The weights must sum to exactly 1 so that the move ends exactly on its target.
  const std::int64_t fixed = out.t[largest].weight + ((std::int64_t{1} << 30) - sum);
  if (fixed <= -(std::int64_t{1} << 31) || fixed >= (std::int64_t{1} << 31)) return Status::impulse_does_not_fit;
  out.t[largest].weight = static_cast<std::int32_t>(fixed);
  out.weight_sum = 0.0;
  for (std::size_t i = 0; i < out.n; ++i) out.weight_sum += std::fabs(std::ldexp(out.t[i].weight, -30));
  return Status::ok;
}

std::int64_t first_tick_at(const Track& t, std::int64_t edge) noexcept {
  return t.delay + ((edge + static_cast<std::int64_t>(t.frac) + 0xFFFFFFFFLL) >> 32);
}

// Whether a peak (counts per tick^k) fits an output of `frac` fraction bits, with slack for the
// evaluation error.
bool fits_output(double peak, int frac) noexcept {
  return std::ldexp(peak * (1.0 + 0x1p-20), frac) + 2.0 < 0x1p31;
}

// Where the command rests (units) and how long it lasts (s), within the formats' ranges.
Status check_extent(double distance, double duration, const Ctx& ctx) noexcept {
  const double dist = distance * ctx.cpu;
  if (!std::isfinite(dist) || !(std::fabs(dist) < build::kTwo30)) return Status::distance_does_not_fit;
  if (!(duration / ctx.dt < build::kTwo30)) return Status::duration_does_not_fit;
  return Status::ok;
}

// The pieces with the shaper's tracks (check_extent passed): every check first, then the same
// conversions written. `pk` are the command's peaks, `distance` where it rests (units).
Status build_from(const Pieces& pieces, const Shaper<double>& shaper, const Peaks<double>& pk, double distance,
                  const Ctx& ctx, const MotionStorage& out) noexcept {
  const double dist = distance * ctx.cpu;
  if (static_cast<std::size_t>(pieces.count()) > out.seg_capacity) return Status::table_too_small;
  TrackSet tracks{};
  if (shaper.count > out.trk_capacity) return Status::too_many_impulses;
  Status st = make_tracks(shaper, ctx, tracks);
  if (st != Status::ok) return st;

  // Pass 1: every check, nothing written.
  Bounds worst{};
  for (int i = 0; i < pieces.count(); ++i) {
    Segment g{};
    Bounds b{};
    st = make_segment(pieces.get(i), ctx, g, b);
    if (st != Status::ok) return st;
    worst.p = std::max(worst.p, b.p);
    worst.v = std::max(worst.v, b.v);
    worst.a = std::max(worst.a, b.a);
  }
  if (!(worst.p * tracks.weight_sum < build::kTwo30)) return Status::distance_does_not_fit;
  if (!(worst.v * tracks.weight_sum < build::kTwo30)) return Status::velocity_does_not_fit;
  if (!(worst.a * tracks.weight_sum < build::kTwo30)) return Status::acceleration_does_not_fit;
  const double vpk = std::isfinite(pk.v) ? pk.v * ctx.cpu * ctx.dt : worst.v * tracks.weight_sum;
  const double apk = std::isfinite(pk.a) ? pk.a * ctx.cpu * ctx.dt * ctx.dt : worst.a * tracks.weight_sum;
  if (!fits_output(vpk, ctx.vf)) return Status::velocity_does_not_fit;
  if (!fits_output(apk, ctx.af)) return Status::acceleration_does_not_fit;
  const Piece last = pieces.count() > 0 ? pieces.get(pieces.count() - 1) : Piece{};
  const std::int64_t end = pieces.count() > 0 ? build::q32((last.start + last.length) / ctx.dt) : 0;
  std::int64_t end_tick = 0;
  for (std::size_t i = 0; i < tracks.n; ++i) end_tick = std::max(end_tick, first_tick_at(tracks.t[i], end));
  if (end_tick >= (std::int64_t{1} << 30)) return Status::duration_does_not_fit;

  // Pass 2: the same conversions (deterministic), written.
  for (int i = 0; i < pieces.count(); ++i) {
    Bounds b{};
    (void)make_segment(pieces.get(i), ctx, out.seg[i], b);
  }
  for (std::size_t i = 0; i < tracks.n; ++i) out.trk[i] = tracks.t[i];
  MotionHeader& h = *out.hdr;
  h.end = end;
  h.final_p = build::q32(dist);
  h.target = static_cast<std::int32_t>(std::nearbyint(dist));
  h.end_tick = static_cast<std::int32_t>(end_tick);
  h.segments = static_cast<std::uint16_t>(pieces.count());
  h.tracks = static_cast<std::uint8_t>(tracks.n);
  h.v_frac = static_cast<std::uint8_t>(ctx.vf);
  h.a_frac = static_cast<std::uint8_t>(ctx.af);
  h.unit_weight = tracks.n == 1;
  return Status::ok;
}

}  // namespace

Status build_motion(const Move<double>& move, const Scale& scale, const MotionStorage& out) noexcept {
  Ctx ctx{};
  Status st = build::make_ctx(scale, ctx);
  if (st != Status::ok) return st;
  st = check_extent(move.distance(), move.duration(), ctx);
  if (st != Status::ok) return st;
  Pieces pieces{};
  st = pieces.init(move.profile(), ctx, out.seg_capacity);
  if (st != Status::ok) return st;
  return build_from(pieces, move.shaper(), move.peaks(), move.distance(), ctx, out);
}

Status build_blend_motion(const Blend& blend, const Scale& scale, const MotionStorage& out) noexcept {
  Ctx ctx{};
  Status st = build::make_ctx(scale, ctx);
  if (st != Status::ok) return st;
  st = check_extent(blend.end_position(), blend.duration(), ctx);
  if (st != Status::ok) return st;
  Pieces pieces{};
  st = pieces.init(blend);
  if (st != Status::ok) return st;
  // One track of weight 1: a blend is not shaped, it is the command itself from the switch on.
  return build_from(pieces, Shaper<double>{}, blend.peaks(), blend.end_position(), ctx, out);
}

}  // namespace settle::core::fixed::detail

namespace settle::core::fixed {

Status move_pieces(const Profile<double>& profile, const Scale& scale, Piece* out, std::size_t capacity,
                   std::size_t& count) noexcept {
  count = 0;
  build::Ctx ctx{};
  Status st = build::make_ctx(scale, ctx);
  if (st != Status::ok) return st;
  detail::Pieces pieces{};
  st = pieces.init(profile, ctx, capacity);
  if (st != Status::ok) return st;
  if (static_cast<std::size_t>(pieces.count()) > capacity) return Status::table_too_small;
  for (int i = 0; i < pieces.count(); ++i) out[i] = pieces.get(i);
  count = static_cast<std::size_t>(pieces.count());
  return Status::ok;
}

}  // namespace settle::core::fixed
