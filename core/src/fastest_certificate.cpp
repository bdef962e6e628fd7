// SPDX-License-Identifier: Apache-2.0
// certify_fastest (profiles/fastest.hpp): a proof by linear-programming duality that a move is the
// shortest of its problem. docs/fastest.md, "A certificate of the shortest move", derives it;
// tools/fastest-certificate is the same check written apart (Python, from the printed plan).
//
// For the move's time T the problem is a linear program in the jerk u(t): maximise p(T) subject to
// a(T) = v(T) = 0, each mode's transform at its pole zero, |u| <= jmax, |a| <= amax, 0 <= v <= vmax.
// A dual of it is the switching function
//   psi(s) = (T-s)^2/2 - nu_a - nu_v (T-s) - sum_m (x_m Re + y_m Im) e^{q_m (T-s)} - (holds' share after s)
// where a hold at +-amax carries a measure of the a limit (its share before it: a constant, its
// mass) and a cruise or dwell one of the v limit (a line: mass and first moment). The move is
// optimal (and, the reach rising with T, the shortest) when psi has the jerk's sign on every ramp,
// vanishes on every hold, and every measure is nonnegative.
#include "settle/core/profiles/fastest.hpp"
#include "settle/core/profiles/registry.hpp"

#if SETTLE_CORE_FASTEST

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "settle/core/residual.hpp"
#include "numeric/complex.hpp"

namespace settle::core {

namespace {

using namespace numeric;

enum class Kind : std::uint8_t { ramp, limit, cruise, dwell };
struct Part {  // no initialisers: lay_out writes pieces [0, pieces) whole, the rest are not read
  Kind kind;
  double t0, t1;
  double side;  // ramp: the jerk's sign; limit: a's; cruise +1 (v <= vmax binds), dwell -1 (v >= 0)
};

// Holds and ramps alternate or ramps meet at a turn, so a table of kFastestSegments segments gives
// at most that many pieces, (kFastestSegments + 1) / 2 holds, and rows: one per turn, one per hold.
constexpr std::size_t kMaxParts = kFastestSegments;
constexpr std::size_t kMaxHolds = (kFastestSegments + 1) / 2;
// Unknowns: nu_a, nu_v, two per mode, and a cruise's or dwell's mass (its share's slope). Each
// hold's share at its start is not an unknown: psi = 0 there gives it from the unknowns after it.
constexpr std::size_t kMaxCols = 2 + 2 * kMaxModes + kMaxHolds;
constexpr std::size_t kMaxRows = kMaxParts;
constexpr double kTol = 1e-7;  // relative: the dual's fit and each sign condition
constexpr int kSamples = 64;   // per ramp or hold, and per period of the fastest mode
using Row = std::array<double, kMaxCols>;

struct Problem {
  double D{0.0}, V{0.0}, A{0.0}, J{0.0}, T{0.0};
  std::array<Cx, kMaxModes> q{};
  std::size_t modes{0};
  double w_fast{0.0};
  std::array<Part, kMaxParts> piece;  // [0, pieces) only
  std::size_t pieces{0};
  // e^{q_m (T - s)} at each piece's start and end, taken once: the rows, the dual's values at the
  // holds' ends and the bounds all read them there.
  std::array<std::array<Cx, kMaxModes>, kMaxParts> e0, e1;
};

// Only what is written is read (a hold's entries, the first `cols` of a row): nothing is zeroed, the
// rows being 47 of 34 doubles each.
struct Dual {
  std::size_t cols{0};
  std::array<std::size_t, kMaxParts> slope;  // cruise/dwell: its mass's column
  std::array<Row, kMaxParts> c0;             // a hold's share at its start: a row over the unknowns
  std::array<double, kMaxParts> c0c;         // plus this constant
};

// std::fmin and std::fmax where a is never NaN (b may be: a is kept, as they do), inline; up:
// std::ceil for 0 <= a < 2^52, inline.
inline double lesser(double a, double b) noexcept { return b < a ? b : a; }
inline double greater(double a, double b) noexcept { return b > a ? b : a; }
inline double up(double a) noexcept {
  const auto t = static_cast<double>(static_cast<std::int64_t>(a));
  return t < a ? t + 1.0 : t;
}

// The move is one of the problem's: at rest at D, within the limits, never backwards, every mode
// at rest (the amplitude it leaves, residual.hpp, within 1e-8 D).
bool one_of_the_problems(const FastestTable& t, double sgn, const Problem& pb, const MoveRequest& r) noexcept {
  constexpr double kLimit = 1e-9, kEnd = 1e-8;  // the table's sums round (a 24 s move ends 1.5e-9 D short)
  double a = 0.0, v = 0.0, p = 0.0;
  for (std::size_t k = 0; k < t.count; ++k) {
    const double d = t.durations[k], j = sgn * t.jerk[k];
    if (!(d >= 0.0) || !std::isfinite(j) || std::fabs(j) > pb.J * (1.0 + kLimit)) return false;
    const double v1 = v + a * d + j * d * d / 2.0, a1 = a + j * d;
    double v_lo = lesser(v, v1), v_hi = greater(v, v1);  // v is NaN only where v1 is
    if (j != 0.0 && -a / j > 0.0 && -a / j < d) {  // v turns inside the segment
      const double tau = -a / j, vt = v + a * tau + j * tau * tau / 2.0;
      v_lo = lesser(v_lo, vt);
      v_hi = greater(v_hi, vt);
    }
    if (std::fabs(a1) > pb.A * (1.0 + kLimit) || v_hi > pb.V * (1.0 + kLimit) || v_lo < -kLimit * pb.V) return false;
    p += v * d + a * d * d / 2.0 + j * d * d * d / 6.0;
    v = v1;
    a = a1;
  }
  if (!(std::fabs(a) <= kEnd * pb.A && std::fabs(v) <= kEnd * pb.V && std::fabs(p - pb.D) <= kEnd * pb.D)) return false;
  for (std::size_t m = 0; m < pb.modes; ++m) {
    if (!(residual_amplitude(t, r.modes[m]) <= kEnd * pb.D)) return false;  // the planner's own: 1e-9 D
  }
  return true;
}

// The pieces: ramps (one sign merged), holds at +-amax, at vmax, at v = 0; false for anything else.
bool lay_out(const FastestTable& t, double sgn, Problem& pb) noexcept {
  double tt = 0.0, a = 0.0, v = 0.0;
  for (std::size_t k = 0; k < t.count; ++k) {
    const double d = t.durations[k], j = sgn * t.jerk[k];
    if (d > 1e-15 * pb.T) {
      if (j != 0.0) {
        if (std::fabs(std::fabs(j) - pb.J) > 1e-9 * pb.J) return false;
        const double side = j > 0.0 ? 1.0 : -1.0;
        Part* last = pb.pieces > 0 ? &pb.piece[pb.pieces - 1] : nullptr;
        if (last && last->kind == Kind::ramp && last->side == side) {
          last->t1 = tt + d;  // one ramp
        } else {
          pb.piece[pb.pieces++] = {Kind::ramp, tt, tt + d, side};
        }
      } else if (std::fabs(std::fabs(a) - pb.A) <= 1e-6 * pb.A) {
        pb.piece[pb.pieces++] = {Kind::limit, tt, tt + d, a > 0.0 ? 1.0 : -1.0};
      } else if (std::fabs(a) <= 1e-6 * pb.A && std::fabs(v - pb.V) <= 1e-6 * pb.V) {
        pb.piece[pb.pieces++] = {Kind::cruise, tt, tt + d, 1.0};
      } else if (std::fabs(a) <= 1e-6 * pb.A && std::fabs(v) <= 1e-6 * pb.V) {
        pb.piece[pb.pieces++] = {Kind::dwell, tt, tt + d, -1.0};
      } else {
        return false;
      }
    }
    v += a * d + j * d * d / 2.0;
    a += j * d;
    tt += d;
  }
  return pb.pieces > 0;
}

void exps_at_ends(Problem& pb) noexcept {
  for (std::size_t i = 0; i < pb.pieces; ++i) {
    const Part& pc = pb.piece[i];
    for (std::size_t m = 0; m < pb.modes; ++m) {
      pb.e0[i][m] = i > 0 && pb.piece[i - 1].t1 == pc.t0 ? pb.e1[i - 1][m] : cexp((pb.T - pc.t0) * pb.q[m]);
      pb.e1[i][m] = cexp((pb.T - pc.t1) * pb.q[m]);
    }
  }
}

// psi's part without the holds' shares at s, as a row over the unknowns (returned) plus a constant
// (c); e: the modes' exponentials there.
Row p_row(const Problem& pb, std::size_t cols, double s, const std::array<Cx, kMaxModes>& e, double& c) noexcept {
  Row r;  // [0, cols) only
  std::fill_n(r.begin(), cols, 0.0);
  const double u = pb.T - s;
  c = u * u / 2.0;
  r[0] = -1.0;
  r[1] = -u;
  for (std::size_t m = 0; m < pb.modes; ++m) {
    r[2 + 2 * m] = -e[m].re;
    r[3 + 2 * m] = -e[m].im;
  }
  return r;
}

// Least squares by Householder reflections (columns scaled to unit norm first): x, and false where
// the rows are not met to kTol (relative to T^2, psi's scale). With fewer rows than unknowns the
// dual is not unique and this takes one of them (the unknowns past the rows 0): any dual that
// passes the sign tests proves the move, so another choice can only miss a proof, never make one.
bool solve(std::array<Row, kMaxRows>& a, std::array<double, kMaxRows>& b, std::size_t rows, std::size_t cols,
           double scale, Row& x) noexcept {
  std::array<Row, kMaxRows> a0;  // the system as given, for the fit's check: its rows x cols only
  std::array<double, kMaxRows> b0;
  for (std::size_t r = 0; r < rows; ++r) {
    std::copy_n(a[r].begin(), cols, a0[r].begin());
    b0[r] = b[r];
  }
  Row cs{};
  for (std::size_t k = 0; k < cols; ++k) {
    double n = 0.0;
    for (std::size_t r = 0; r < rows; ++r) n += a[r][k] * a[r][k];
    cs[k] = n > 0.0 ? 1.0 / std::sqrt(n) : 0.0;
    for (std::size_t r = 0; r < rows; ++r) a[r][k] *= cs[k];
  }
  const std::size_t steps = std::min(rows, cols);
  std::array<bool, kMaxCols> used{};
  for (std::size_t k = 0; k < steps; ++k) {
    double n = 0.0;
    for (std::size_t r = k; r < rows; ++r) n += a[r][k] * a[r][k];
    n = std::sqrt(n);
    if (!(n > 1e-12)) continue;  // a column dependent on those before: its unknown stays 0
    used[k] = true;
    const double alpha = a[k][k] > 0.0 ? -n : n;
    std::array<double, kMaxRows> w;  // [k, rows) only
    for (std::size_t r = k; r < rows; ++r) w[r] = a[r][k];
    w[k] -= alpha;
    double wn = 0.0;
    for (std::size_t r = k; r < rows; ++r) wn += w[r] * w[r];
    if (!(wn > 0.0)) continue;
    for (std::size_t c = k; c < cols; ++c) {
      double d = 0.0;
      for (std::size_t r = k; r < rows; ++r) d += w[r] * a[r][c];
      d = 2.0 * d / wn;
      for (std::size_t r = k; r < rows; ++r) a[r][c] -= d * w[r];
    }
    double d = 0.0;
    for (std::size_t r = k; r < rows; ++r) d += w[r] * b[r];
    d = 2.0 * d / wn;
    for (std::size_t r = k; r < rows; ++r) b[r] -= d * w[r];
  }
  x = Row{};
  for (std::size_t k = steps; k-- > 0;) {
    if (!used[k]) continue;
    double acc = b[k];
    for (std::size_t c = k + 1; c < cols; ++c) acc -= a[k][c] * x[c];
    x[k] = acc / a[k][k];
  }
  for (std::size_t k = 0; k < cols; ++k) x[k] *= cs[k];
  double worst = 0.0;
  for (std::size_t r = 0; r < rows; ++r) {
    double f = -b0[r];
    for (std::size_t k = 0; k < cols; ++k) f += a0[r][k] * x[k];
    worst = greater(worst, std::fabs(f) / scale);
  }
  for (std::size_t k = 0; k < cols; ++k) {
    if (!std::isfinite(x[k])) return false;
  }
  return worst < kTol;
}

// psi and its derivatives along piece i at the solution: the shares of the holds after it are
// one line, A + B s; each mode's exponential is stepped from sample to sample by one complex
// product (taken afresh every 64 samples: the steps' rounding stays below 1e-13).
struct Along {
  const Problem& pb;
  const Row& x;
  double lin_a{0.0}, lin_b{0.0};
  // psi^(der) at s_k = t0 + k h, k = k0 .. k1 (k0 a multiple of 64), to f(k, s_k, value).
  template <class F>
  void walk(double t0, double h, std::size_t k0, std::size_t k1, int der, F&& f) const noexcept {
    std::array<Cx, kMaxModes> w{}, e{}, step{};
    for (std::size_t m = 0; m < pb.modes; ++m) {
      const Cx q = pb.q[m];
      Cx z{1.0, 0.0};
      for (int d = 0; d < der; ++d) z = z * Cx{-q.re, -q.im};
      w[m] = z * Cx{x[2 + 2 * m], -x[3 + 2 * m]};  // x Re(E z) + y Im(E z) = Re(E w)
      step[m] = cexp(-h * q);
    }
    for (std::size_t k = k0; k <= k1; ++k) {
      const double s = t0 + h * static_cast<double>(k), u = pb.T - s;
      double v = der == 0 ? u * u / 2.0 - x[0] - x[1] * u - (lin_a + lin_b * s)
                 : der == 1 ? -u + x[1] - lin_b
                            : 1.0;
      for (std::size_t m = 0; m < pb.modes; ++m) {
        e[m] = k % 64 == 0 ? cexp(u * pb.q[m]) : e[m] * step[m];
        v -= e[m].re * w[m].re - e[m].im * w[m].im;
      }
      f(k, s, v);
    }
  }
  // psi' at s, e the modes' exponentials there: walk's first sample, without its exponentials.
  double slope_at(double s, const std::array<Cx, kMaxModes>& e) const noexcept {
    const double u = pb.T - s;
    double v = -u + x[1] - lin_b;
    for (std::size_t m = 0; m < pb.modes; ++m) {
      const Cx q = pb.q[m], w = Cx{1.0, 0.0} * Cx{-q.re, -q.im} * Cx{x[2 + 2 * m], -x[3 + 2 * m]};
      v -= e[m].re * w.re - e[m].im * w.im;
    }
    return v;
  }
};

// |a| from above, within a factor sqrt(2), without a square root.
inline double size(Cx a) noexcept { return std::fabs(a.re) + std::fabs(a.im); }
inline double modulus(Cx a) noexcept { return std::sqrt(a.re * a.re + a.im * a.im); }
// e^z - 1 as numeric::cexpm1, from one sine and cosine (of z.im / 2).
Cx exp_minus_1(Cx z) noexcept {
  const double sh = std::sin(0.5 * z.im), ch = std::cos(0.5 * z.im);
  const bool undamped = z.re == 0.0;
  const double em1 = undamped ? z.re : std::expm1(z.re), e = undamped ? 1.0 : std::exp(z.re);
  return {em1 * (1.0 - 2.0 * sh * sh) - 2.0 * sh * sh, e * 2.0 * sh * ch};
}

// The least of c(t) = f0 + f1 t + f2 t^2/2 - m3 t^3/6 over [tl, tr] (m3 >= 0): at an end or where
// c' = f1 + f2 t - m3 t^2/2 is 0 (its roots in the stable form: a root a little off can only raise it).
double cubic_min(double f0, double f1, double f2, double m3, double tl, double tr) noexcept {
  const auto c = [&](double t) { return f0 + t * (f1 + t * (f2 / 2.0 - m3 * t / 6.0)); };
  double low = lesser(c(tl), c(tr));
  const auto at = [&](double t) {
    if (t > tl && t < tr) low = lesser(low, c(t));
  };
  if (m3 > 0.0) {
    const double disc = f2 * f2 + 2.0 * m3 * f1;
    if (disc >= 0.0) {
      const double qq = 0.5 * (f2 + std::copysign(std::sqrt(disc), f2));  // (m3/2) t^2 - f2 t - f1 = 0
      at(qq / (0.5 * m3));
      if (qq != 0.0) at(-f1 / qq);
    }
  } else if (f2 != 0.0) {
    at(-f1 / f2);
  }
  return low;
}

// Simpson's sum over n intervals of h of e^{z k} (k = 0 .. n), z = -q h, over the integral of
// e^{-q tau} over [0, n h]: rho(z) = z (1 + 4 e^z + e^2z) / (3 (e^2z - 1)), even in z. With 64
// samples per period |z| <= 2 pi / 64: its series to z^12 (the next term below 1e-18 there);
// beyond, the closed form.
Cx simpson_ratio(Cx z) noexcept {
  const Cx w = z * z;
  if (size(w) <= 0.0104) {
    Cx r{21421.0 / 29719872000.0, 0.0};
    for (const double c : {-17.0 / 2395008.0, 1.0 / 14400.0, -1.0 / 1512.0, 1.0 / 180.0}) r = Cx{c, 0.0} + w * r;
    return Cx{1.0, 0.0} + w * w * r;
  }
  const Cx em = exp_minus_1(z);
  return z * (Cx{6.0, 0.0} + 6.0 * em + em * em) / (3.0 * em * (Cx{2.0, 0.0} + em));
}

// The sign tests of a piece without their samples, where a bound shows that none of them can
// fail. Along the piece f = sigma psi^(der), psi seen from it (the later holds' shares one line
// lin_a + lin_b s). From a point a where f, f' and f'' are known, f(a + t) >= f + f' t + f'' t^2/2
// - m3 t^3/6 for t >= 0 (Taylor), m3 bounding |f'''|: psi's polynomial part is of degree 2 in s, so
// f''' is the modes' part alone, each at most |W q^(der+3)| e^{Re(q) u}, largest at an end of the
// interval. An interval is bounded from each end over its half, and halved to a depth where that
// is not enough.
struct Bound {
  const Problem& pb;
  const Row& x;
  const std::array<std::array<Cx, kMaxModes>, 6>& wq;  // W (-q)^j, W = x_m - i y_m: Re(W e) = x Re e + y Im e
  const std::array<std::array<double, kMaxModes>, 6>& wsize;  // |W (-q)^j|
  double lin_a, lin_b, sigma;
  int der;
  double lo, hi;  // where the samples lie
  struct Node {
    double s;
    const Cx* e;               // e^{q (T - s)}, each mode
    std::array<double, 3> f;  // f, f', f''
  };
  void exps(double s, std::array<Cx, kMaxModes>& e) const noexcept {
    for (std::size_t m = 0; m < pb.modes; ++m) e[m] = cexp((pb.T - s) * pb.q[m]);
  }
  void eval(Node& n) const noexcept {
    const double u = pb.T - n.s;
    const double p0 = u * u / 2.0 - x[0] - x[1] * u - (lin_a + lin_b * n.s), p1 = -u + x[1] - lin_b;
    double g0 = der == 0 ? p0 : der == 1 ? p1 : 1.0, g1 = der == 0 ? p1 : der == 1 ? 1.0 : 0.0,
           g2 = der == 0 ? 1.0 : 0.0;
    const auto d = static_cast<std::size_t>(der);
    for (std::size_t m = 0; m < pb.modes; ++m) {
      const Cx e = n.e[m], w0 = wq[d][m], w1 = wq[d + 1][m], w2 = wq[d + 2][m];
      g0 -= w0.re * e.re - w0.im * e.im;
      g1 -= w1.re * e.re - w1.im * e.im;
      g2 -= w2.re * e.re - w2.im * e.im;
    }
    n.f = {sigma * g0, sigma * g1, sigma * g2};
  }
  // Whether f >= floor on [a, b] within [lo, hi] (false also where a point halving it is below).
  bool holds(const Node& a, const Node& b, int depth, double floor) const noexcept {
    const double l = greater(a.s, lo), r = lesser(b.s, hi);
    if (!(l <= r)) return true;
    const double mid = a.s + (b.s - a.s) / 2.0;
    double m3 = 0.0;
    const auto d3 = static_cast<std::size_t>(der) + 3;
    for (std::size_t m = 0; m < pb.modes; ++m) m3 += wsize[d3][m] * greater(modulus(a.e[m]), modulus(b.e[m]));
    m3 *= 1.0 + 1e-9;
    if (!std::isfinite(m3 + a.f[0] + a.f[1] + a.f[2] + b.f[0] + b.f[1] + b.f[2])) return false;
    double low = std::numeric_limits<double>::infinity();
    if (l <= mid) low = cubic_min(a.f[0], a.f[1], a.f[2], m3, l - a.s, lesser(r, mid) - a.s);
    if (r >= mid && low >= floor) low = lesser(low, cubic_min(b.f[0], -b.f[1], b.f[2], m3, b.s - r, b.s - greater(l, mid)));
    if (low >= floor) return true;
    if (depth == 0) return false;
    std::array<Cx, kMaxModes> ec;
    exps(mid, ec);
    Node c{mid, ec.data(), {}};
    eval(c);
    if (c.s >= lo && c.s <= hi && !(c.f[0] >= floor)) return false;
    return holds(a, c, depth - 1, floor) && holds(c, b, depth - 1, floor);
  }
};

// The worst sign condition so far: its value (scaled), which, and where.
struct Notes {
  double worst{0.0};
  FastestProof why{FastestProof::proven};
  double at{0.0};
  void operator()(double v, FastestProof p, double s) noexcept {
    if (v < worst) {
      worst = v;
      why = p;
      at = s;
    }
  }
};

// One piece's samples, s_k = t0 + k h, k = 0 .. n, in blocks of 64 (each walk takes its
// exponentials afresh at a block's start): a run of blocks where Bound shows every sample inside
// above `floor` is not walked, the others are, as before. What is walked notes what it did
// before, in the same order and to the bit; what is not cannot change the outcome:
//   - on a ramp floor is +margin, margin 1e-12 of the terms' size (psi's rounding is a few 1e-16 of
//     it, the exponentials' a few 1e-16 of 1 + |q| u) and at most kTol / 4 of the notes' scale:
//     every sample there is above 0, so none notes anything and |psi| = sigma psi at each: Simpson's
//     sum over the run is taken in closed form (below). (At -margin a ramp with psi within the
//     margin on the wrong side would be summed as sigma psi where the walk sums |psi|.)
//   - on a hold, where no integral is taken, floor is 2 margins above the worst so far or -kTol,
//     whichever is lower: a sample above it is never the worst where that fails the proof.
struct Sweep {
  const Problem& pb;
  const Along& al;
  const Bound& bd;
  const Part& pc;
  Notes& notes;
  std::size_t n;
  double h, norm;
  std::array<double, 3> poly;  // the size of the polynomial part's terms in f, f' and f''
  bool ramp;
  std::array<Cx, kMaxModes> rho{};  // ramp: Simpson's ratio to the integral for each mode's e^{-q tau}
  double integral{0.0};              // ramp: Simpson's sum of |psi| times h / 3
  Bound::Node node(std::size_t k, std::array<Cx, kMaxModes>& e) const noexcept {
    Bound::Node nd{k == n ? pc.t1 : pc.t0 + h * static_cast<double>(k), e.data(), {}};
    bd.exps(nd.s, e);
    bd.eval(nd);
    return nd;
  }
  // 1e-12 of the size of the bound's terms over [a, b] (its Taylor terms' t at most b - a): psi's
  // rounding is a few 1e-16 of it, that of e^{q u} (its phase q u) a few 1e-16 of 1 + |q| u.
  double margin(const Bound::Node& a, const Bound::Node& b) const noexcept {
    const double len = b.s - a.s, u = pb.T - a.s;
    std::array<double, 3> sc = poly;
    const auto d = static_cast<std::size_t>(bd.der);
    for (std::size_t m = 0; m < pb.modes; ++m) {
      const double big = greater(size(a.e[m]), size(b.e[m])) * (1.0 + size(pb.q[m]) * u);
      for (std::size_t j = 0; j < 3; ++j) sc[j] += bd.wsize[d + j][m] * big;
    }
    return 1e-12 * (sc[0] + sc[1] * len + sc[2] * len * len);
  }
  double floor(double margin) const noexcept {
    return ramp ? margin : lesser(notes.worst, -kTol) * norm + 2.0 * margin;
  }
  void walk(std::size_t k0, std::size_t k1) noexcept {
    if (ramp) {
      double sum = 0.0;
      al.walk(pc.t0, h, k0, k1, 0, [&](std::size_t k, double s, double v) {
        if (k > 0 && k < n) notes(pc.side * v / norm, FastestProof::against_the_jerk, s);
        sum += (k == k0 || k == k1 ? 1.0 : (k - k0) % 2 == 1 ? 4.0 : 2.0) * std::fabs(v);
      });
      integral += sum * h / 3.0;
      return;
    }
    al.walk(pc.t0, h, k0, k1, bd.der, [&](std::size_t k, double s, double v) {
      if (k > 0 && k < n) notes(bd.sigma * v / norm, FastestProof::negative_measure, s);
    });
  }
  // Simpson's sum of sigma psi over [a, b] in closed form: the polynomial part's integral (Simpson
  // is exact on it), each mode's e^{-q tau} summed as its integral times Simpson's ratio for z = -q h,
  // z (1 + 4 e^z + e^2z) / (3 (e^2z - 1)); at the two ends |psi| for sigma psi.
  void skip(const Bound::Node& a, const Bound::Node& b) noexcept {
    if (!ramp) return;
    const double T = pb.T, len = b.s - a.s, ua = T - a.s, ub = T - b.s;
    const Row& x = bd.x;
    double sum = len * (ua * ua + ua * ub + ub * ub) / 6.0 - (x[0] + bd.lin_a) * len - x[1] * len * (ua + ub) / 2.0 -
                 bd.lin_b * len * (a.s + b.s) / 2.0;
    for (std::size_t m = 0; m < pb.modes; ++m) {
      // e(a) int_0^len e^{-q tau} = (e(a) - e(b)) / q, by e^{-q len} - 1 where that is small
      const Cx q = pb.q[m];
      const Cx whole = size(q) * len >= 0.5 ? (a.e[m] - b.e[m]) / q
                                             : Cx{0.0, 0.0} - a.e[m] * exp_minus_1(Cx{-q.re * len, -q.im * len}) / q;
      const Cx part = whole * rho[m];
      sum -= bd.wq[0][m].re * part.re - bd.wq[0][m].im * part.im;
    }
    integral += pc.side * sum + (std::fabs(a.f[0]) - a.f[0] + std::fabs(b.f[0]) - b.f[0]) * h / 3.0;
  }
  // Samples k0 .. k1 (block starts, or n), a and b the nodes there.
  void cover(const Bound::Node& a, const Bound::Node& b, std::size_t k0, std::size_t k1) noexcept {
    const bool one = k1 - k0 <= 64;
    const double margin = this->margin(a, b);
    if (4.0 * margin < kTol * norm && bd.holds(a, b, one ? 2 : 0, floor(margin))) {
      skip(a, b);
      return;
    }
    if (one) {
      walk(k0, k1);
      return;
    }
    const std::size_t km = k0 + 64 * ((k1 - k0 + 63) / 64 / 2);
    std::array<Cx, kMaxModes> ec;
    const Bound::Node c = node(km, ec);
    cover(a, c, k0, km);
    cover(c, b, km, k1);
  }
};

}  // namespace

const char* to_string(FastestProof p) noexcept {
  switch (p) {
    case FastestProof::proven: return "proven the shortest";
    case FastestProof::not_the_problems: return "not one of the problem's moves";
    case FastestProof::not_a_chain: return "not a chain of ramps at jmax and holds at a limit or at rest";
    case FastestProof::no_dual: return "no dual fits its turns and holds";
    case FastestProof::against_the_jerk: return "the switching function against the jerk on a ramp";
    case FastestProof::negative_measure: return "a limit's measure negative where it binds";
    case FastestProof::robust: return "a --robust move: the proof is for exact rest only";
  }
  return "?";
}

FastestCertificate certify_fastest(const FastestTable& t, const MoveRequest& r) noexcept {
  FastestCertificate out{};
  if (!r.limits.vmax || !r.limits.amax || !r.limits.jmax || t.count == 0 || t.count > kFastestSegments ||
      r.mode_count > kMaxModes || !std::isfinite(r.distance) || r.distance == 0.0) {
    out.proof = FastestProof::not_the_problems;
    return out;
  }
  if (r.robust) {
    out.proof = FastestProof::robust;
    return out;
  }
  Problem pb;
  const double sgn = r.distance < 0.0 ? -1.0 : 1.0;  // the move of -D is that of D mirrored
  pb.D = std::fabs(r.distance);
  pb.V = *r.limits.vmax;
  pb.A = *r.limits.amax;
  pb.J = *r.limits.jmax;
  for (std::size_t k = 0; k < t.count; ++k) pb.T += t.durations[k];
  pb.modes = r.mode_count;
  for (std::size_t m = 0; m < pb.modes; ++m) {
    pb.q[m] = pole(r.modes[m].omega, r.modes[m].zeta);
    pb.w_fast = greater(pb.w_fast, r.modes[m].omega);
  }
  if (!(pb.T > 0.0) || !std::isfinite(pb.T) || !one_of_the_problems(t, sgn, pb, r)) {
    out.proof = FastestProof::not_the_problems;
    return out;
  }
  if (!lay_out(t, sgn, pb)) {
    out.proof = FastestProof::not_a_chain;
    return out;
  }
  exps_at_ends(pb);
  // The unknowns.
  Dual du;
  du.cols = 2 + 2 * pb.modes;
  for (std::size_t i = 0; i < pb.pieces; ++i) {
    if (pb.piece[i].kind == Kind::cruise || pb.piece[i].kind == Kind::dwell) du.slope[i] = du.cols++;
  }
  // The rows: psi = 0 at each turn and at each hold's end, psi seen from the piece (every hold
  // after it subtracts its share). Built last first, the later holds' shares summed as they come
  // (sum, sumc; a cruise's or dwell's line in its own column, lines).
  std::array<Row, kMaxRows> a;  // [0, rows) only, [0, cols) of each
  std::array<double, kMaxRows> b;
  const auto turn = [&](std::size_t i) {
    return pb.piece[i].kind == Kind::ramp && i + 1 < pb.pieces && pb.piece[i + 1].kind == Kind::ramp;
  };
  std::size_t rows = 0;
  for (std::size_t i = 0; i < pb.pieces; ++i) rows += pb.piece[i].kind != Kind::ramp || turn(i) ? 1u : 0u;
  {
    Row sum;
    std::fill_n(sum.begin(), du.cols, 0.0);
    double sumc = 0.0;
    std::array<std::size_t, kMaxHolds> lines;
    std::size_t nlines = 0;
    const auto seen = [&](double at, const std::array<Cx, kMaxModes>& e, double& c) {
      Row row = p_row(pb, du.cols, at, e, c);
      for (std::size_t k = 0; k < du.cols; ++k) row[k] -= sum[k];
      c -= sumc;
      for (std::size_t l = 0; l < nlines; ++l) row[du.slope[lines[l]]] -= at - pb.piece[lines[l]].t0;
      return row;
    };
    std::size_t row = rows;
    for (std::size_t i = pb.pieces; i-- > 0;) {
      const Part& pc = pb.piece[i];
      if (pc.kind != Kind::ramp || turn(i)) {
        double c = 0.0;
        a[--row] = seen(pc.t1, pb.e1[i], c);
        b[row] = -c;
      }
      if (pc.kind == Kind::ramp) continue;
      du.c0[i] = seen(pc.t0, pb.e0[i], du.c0c[i]);  // its share at its start
      for (std::size_t k = 0; k < du.cols; ++k) sum[k] += du.c0[i][k];
      sumc += du.c0c[i];
      if (pc.kind != Kind::limit) lines[nlines++] = i;
    }
  }
  Row x{};
  if (rows == 0 || !solve(a, b, rows, du.cols, pb.T * pb.T, x)) {
    out.proof = FastestProof::no_dual;
    return out;
  }
  // Every sign, piece by piece, and the dual's value (jmax int|psi| + amax (limit masses) + vmax
  // (cruise masses)) for the gap. Along piece i the later holds' shares are one line A + B s.
  double value = 0.0;
  const auto dot = [&](const Row& row) {
    double d = 0.0;
    for (std::size_t k = 0; k < du.cols; ++k) d += row[k] * x[k];
    return d;
  };
  const double T = pb.T, T2 = T * T;
  std::array<double, kMaxParts> share;  // a hold's share at its start, at the solution
  for (std::size_t h = 0; h < pb.pieces; ++h) {
    if (pb.piece[h].kind != Kind::ramp) share[h] = dot(du.c0[h]) + du.c0c[h];
  }
  std::array<std::array<Cx, kMaxModes>, 6> wq;  // W (-q)^j, j = 0 .. 5 (psi's derivatives to the fifth)
  for (std::size_t m = 0; m < pb.modes; ++m) {
    const Cx mq{-pb.q[m].re, -pb.q[m].im};
    wq[0][m] = Cx{x[2 + 2 * m], -x[3 + 2 * m]};
    for (std::size_t j = 1; j < 6; ++j) wq[j][m] = wq[j - 1][m] * mq;
  }
  std::array<std::array<double, kMaxModes>, 6> wsize;
  for (std::size_t j = 0; j < 6; ++j) {
    for (std::size_t m = 0; m < pb.modes; ++m) wsize[j][m] = modulus(wq[j][m]);
  }
  // Along piece i the shares of the holds after it are one line, lin_a + lin_b s: summed from the end.
  std::array<double, kMaxParts> lin_a, lin_b;
  {
    double la = 0.0, lb = 0.0;
    for (std::size_t h = pb.pieces; h-- > 0;) {
      lin_a[h] = la;
      lin_b[h] = lb;
      const Part& ph = pb.piece[h];
      if (ph.kind == Kind::ramp) continue;
      la += share[h];
      if (ph.kind != Kind::limit) {
        la -= x[du.slope[h]] * ph.t0;
        lb += x[du.slope[h]];
      }
    }
  }
  Notes notes;
  for (std::size_t i = 0; i < pb.pieces; ++i) {
    const Part& pc = pb.piece[i];
    const Along al{pb, x, lin_a[i], lin_b[i]};
    const double len = pc.t1 - pc.t0;
    // An even number of intervals (Simpson's rule for the value), 64 at least and per period.
    const double per = pb.w_fast > 0.0 ? len * pb.w_fast / two_pi_v<double>() : 0.0;
    const double want = greater(static_cast<double>(kSamples), up(kSamples * lesser(1e6, per)));
    const auto n = static_cast<std::size_t>(2.0 * up(want / 2.0));
    const double h = len / static_cast<double>(n);
    const bool ramp = pc.kind == Kind::ramp, limit = pc.kind == Kind::limit;
    const Bound bd{pb, x, wq, wsize, al.lin_a, al.lin_b, limit ? -pc.side : pc.side, ramp ? 0 : limit ? 1 : 2,
                   pc.t0 + 0.99 * h, pc.t1 - 0.99 * h};
    Sweep sw{pb, al, bd, pc, notes, n, h, ramp ? T2 : limit ? T : 1.0, {}, ramp};
    Bound::Node n0{pc.t0, pb.e0[i].data(), {}}, n1{pc.t1, pb.e1[i].data(), {}};
    bd.eval(n0);
    bd.eval(n1);
    const double u0 = T - pc.t0;
    const double p1 = u0 + std::fabs(x[1]) + std::fabs(al.lin_b);
    sw.poly = ramp ? std::array<double, 3>{u0 * u0 / 2.0 + std::fabs(x[0]) + std::fabs(x[1]) * u0 + std::fabs(al.lin_a) +
                                               std::fabs(al.lin_b) * std::fabs(pc.t1),
                                           p1, 1.0}
                   : limit ? std::array<double, 3>{p1, 1.0, 0.0} : std::array<double, 3>{1.0, 0.0, 0.0};
    if (h > 1e-9 * T) {
      for (std::size_t m = 0; ramp && m < pb.modes; ++m) sw.rho[m] = simpson_ratio(Cx{-pb.q[m].re * h, -pb.q[m].im * h});
      sw.cover(n0, n1, 0, n);
    } else {
      sw.walk(0, n);
    }
    if (ramp) {
      value += pb.J * sw.integral;
      continue;
    }
    if (limit) {
      const double mass = share[i];
      notes(pc.side * mass / T2, FastestProof::negative_measure, pc.t0);
      value += pb.A * pc.side * mass;
    } else {
      const double slope = x[du.slope[i]];
      notes(-pc.side * al.slope_at(pc.t1, pb.e1[i]) / T, FastestProof::negative_measure, pc.t1);  // the jump at its end
      notes(pc.side * (al.slope_at(pc.t0, pb.e0[i]) - slope) / T, FastestProof::negative_measure, pc.t0);  // at its start
      if (pc.kind == Kind::cruise) value -= pb.V * slope;
    }
  }
  out.at = notes.at;
  out.gap = value / pb.D - 1.0;
  if (notes.worst < -kTol) {
    out.proof = notes.why;
  } else if (!(std::fabs(out.gap) < 1e-6)) {  // the dual's value is D where the two are each other's optimum
    out.proof = FastestProof::no_dual;
  } else {
    out.proof = FastestProof::proven;
    out.at = 0.0;
  }
  return out;
}

}  // namespace settle::core

#endif  // SETTLE_CORE_FASTEST
