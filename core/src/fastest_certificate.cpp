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
};

// Only what is written is read (a hold's entries, the first `cols` of a row): nothing is zeroed, the
// rows being 47 of 34 doubles each.
struct Dual {
  std::size_t cols{0};
  std::array<std::size_t, kMaxParts> slope;  // cruise/dwell: its mass's column
  std::array<Row, kMaxParts> c0;             // a hold's share at its start: a row over the unknowns
  std::array<double, kMaxParts> c0c;         // plus this constant
};

// The move is one of the problem's: at rest at D, within the limits, never backwards, every mode
// at rest (the amplitude it leaves, residual.hpp, within 1e-8 D).
bool one_of_the_problems(const FastestTable& t, double sgn, const Problem& pb, const MoveRequest& r) noexcept {
  constexpr double kLimit = 1e-9, kEnd = 1e-8;  // the table's sums round (a 24 s move ends 1.5e-9 D short)
  double a = 0.0, v = 0.0, p = 0.0;
  for (std::size_t k = 0; k < t.count; ++k) {
    const double d = t.durations[k], j = sgn * t.jerk[k];
    if (!(d >= 0.0) || !std::isfinite(j) || std::fabs(j) > pb.J * (1.0 + kLimit)) return false;
    const double v1 = v + a * d + j * d * d / 2.0, a1 = a + j * d;
    double v_lo = std::fmin(v, v1), v_hi = std::fmax(v, v1);
    if (j != 0.0 && -a / j > 0.0 && -a / j < d) {  // v turns inside the segment
      const double tau = -a / j, vt = v + a * tau + j * tau * tau / 2.0;
      v_lo = std::fmin(v_lo, vt);
      v_hi = std::fmax(v_hi, vt);
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

// psi's part without the holds' shares, its der-th derivative at s, as a row over the unknowns
// (returned) plus a constant (c).
Row p_row(const Problem& pb, double s, int der, double& c) noexcept {
  Row r{};
  const double u = pb.T - s;
  if (der == 0) {
    c = u * u / 2.0;
    r[0] = -1.0;
    r[1] = -u;
  } else if (der == 1) {
    c = -u;
    r[1] = 1.0;
  } else {
    c = 1.0;
  }
  for (std::size_t m = 0; m < pb.modes; ++m) {
    Cx e = cexp(u * pb.q[m]);
    for (int k = 0; k < der; ++k) e = e * Cx{-pb.q[m].re, -pb.q[m].im};
    r[2 + 2 * m] = -e.re;
    r[3 + 2 * m] = -e.im;
  }
  return r;
}

// psi^(der) at s as seen from piece i: every hold after i subtracts its share.
Row q_row(const Problem& pb, const Dual& du, std::size_t i, double s, int der, double& c) noexcept {
  Row r = p_row(pb, s, der, c);
  for (std::size_t h = i + 1; h < pb.pieces; ++h) {
    const Part& pc = pb.piece[h];
    if (pc.kind == Kind::ramp) continue;
    const bool line = pc.kind != Kind::limit;
    if (der == 0) {
      for (std::size_t k = 0; k < du.cols; ++k) r[k] -= du.c0[h][k];
      c -= du.c0c[h];
      if (line) r[du.slope[h]] -= s - pc.t0;
    } else if (der == 1 && line) {
      r[du.slope[h]] -= 1.0;
    }
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
    worst = std::fmax(worst, std::fabs(f) / scale);
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
  // psi^(der) at s_k = t0 + k h, k = 0 .. n, to f(k, s_k, value).
  template <class F>
  void walk(double t0, double h, std::size_t n, int der, F&& f) const noexcept {
    std::array<Cx, kMaxModes> w{}, e{}, step{};
    for (std::size_t m = 0; m < pb.modes; ++m) {
      const Cx q = pb.q[m];
      Cx z{1.0, 0.0};
      for (int d = 0; d < der; ++d) z = z * Cx{-q.re, -q.im};
      w[m] = z * Cx{x[2 + 2 * m], -x[3 + 2 * m]};  // x Re(E z) + y Im(E z) = Re(E w)
      step[m] = cexp(-h * q);
    }
    for (std::size_t k = 0; k <= n; ++k) {
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
  double value(double s, int der) const noexcept {
    double v = 0.0;
    walk(s, 0.0, 0, der, [&](std::size_t, double, double val) { v = val; });
    return v;
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
    pb.w_fast = std::fmax(pb.w_fast, r.modes[m].omega);
  }
  if (!(pb.T > 0.0) || !std::isfinite(pb.T) || !one_of_the_problems(t, sgn, pb, r)) {
    out.proof = FastestProof::not_the_problems;
    return out;
  }
  if (!lay_out(t, sgn, pb)) {
    out.proof = FastestProof::not_a_chain;
    return out;
  }
  // The unknowns, and each hold's share at its start from the holds after it (last first).
  Dual du;
  du.cols = 2 + 2 * pb.modes;
  for (std::size_t i = 0; i < pb.pieces; ++i) {
    if (pb.piece[i].kind == Kind::cruise || pb.piece[i].kind == Kind::dwell) du.slope[i] = du.cols++;
  }
  for (std::size_t i = pb.pieces; i-- > 0;) {
    if (pb.piece[i].kind == Kind::ramp) continue;
    du.c0[i] = q_row(pb, du, i, pb.piece[i].t0, 0, du.c0c[i]);
  }
  // The rows: psi = 0 at each turn and at each hold's end.
  std::array<Row, kMaxRows> a;  // [0, rows) only, each row whole (q_row)
  std::array<double, kMaxRows> b;
  std::size_t rows = 0;
  for (std::size_t i = 0; i < pb.pieces; ++i) {
    const Part& pc = pb.piece[i];
    const bool turn = pc.kind == Kind::ramp && i + 1 < pb.pieces && pb.piece[i + 1].kind == Kind::ramp;
    if (pc.kind == Kind::ramp && !turn) continue;
    double c = 0.0;
    a[rows] = q_row(pb, du, i, pc.t1, 0, c);
    b[rows++] = -c;
  }
  Row x{};
  if (rows == 0 || !solve(a, b, rows, du.cols, pb.T * pb.T, x)) {
    out.proof = FastestProof::no_dual;
    return out;
  }
  // Every sign, piece by piece, and the dual's value (jmax int|psi| + amax (limit masses) + vmax
  // (cruise masses)) for the gap. Along piece i the later holds' shares are one line A + B s.
  double worst = 0.0, value = 0.0;
  FastestProof why = FastestProof::proven;
  const auto note = [&](double v, FastestProof p, double at) {
    if (v < worst) {
      worst = v;
      why = p;
      out.at = at;
    }
  };
  const auto dot = [&](const Row& row) {
    double d = 0.0;
    for (std::size_t k = 0; k < du.cols; ++k) d += row[k] * x[k];
    return d;
  };
  const double T = pb.T, T2 = T * T;
  for (std::size_t i = 0; i < pb.pieces; ++i) {
    const Part& pc = pb.piece[i];
    Along al{pb, x};
    for (std::size_t h = i + 1; h < pb.pieces; ++h) {
      const Part& ph = pb.piece[h];
      if (ph.kind == Kind::ramp) continue;
      al.lin_a += dot(du.c0[h]) + du.c0c[h];
      if (ph.kind != Kind::limit) {
        al.lin_a -= x[du.slope[h]] * ph.t0;
        al.lin_b += x[du.slope[h]];
      }
    }
    const double len = pc.t1 - pc.t0;
    // An even number of intervals (Simpson's rule for the value), 64 at least and per period.
    const double per = pb.w_fast > 0.0 ? len * pb.w_fast / two_pi_v<double>() : 0.0;
    const double want = std::fmax(static_cast<double>(kSamples), std::ceil(kSamples * std::fmin(per, 1e6)));
    const auto n = static_cast<std::size_t>(2.0 * std::ceil(want / 2.0));
    const double h = len / static_cast<double>(n);
    if (pc.kind == Kind::ramp) {
      double integral = 0.0;
      al.walk(pc.t0, h, n, 0, [&](std::size_t k, double s, double v) {
        if (k > 0 && k < n) note(pc.side * v / T2, FastestProof::against_the_jerk, s);
        integral += (k == 0 || k == n ? 1.0 : k % 2 == 1 ? 4.0 : 2.0) * std::fabs(v);
      });
      value += pb.J * integral * h / 3.0;
      continue;
    }
    const bool limit = pc.kind == Kind::limit;
    al.walk(pc.t0, h, n, limit ? 1 : 2, [&](std::size_t k, double s, double v) {
      if (k > 0 && k < n) note(limit ? -pc.side * v / T : pc.side * v, FastestProof::negative_measure, s);
    });
    if (pc.kind == Kind::limit) {
      const double mass = dot(du.c0[i]) + du.c0c[i];
      note(pc.side * mass / T2, FastestProof::negative_measure, pc.t0);
      value += pb.A * pc.side * mass;
    } else {
      const double slope = x[du.slope[i]];
      note(-pc.side * al.value(pc.t1, 1) / T, FastestProof::negative_measure, pc.t1);  // the jump at its end
      note(pc.side * (al.value(pc.t0, 1) - slope) / T, FastestProof::negative_measure, pc.t0);  // at its start
      if (pc.kind == Kind::cruise) value -= pb.V * slope;
    }
  }
  out.gap = value / pb.D - 1.0;
  if (worst < -kTol) {
    out.proof = why;
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
