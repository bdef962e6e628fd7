// SPDX-License-Identifier: Apache-2.0
// Profile `fastest` (profiles/fastest.hpp): plans every family and keeps the shortest feasible
// move. docs/fastest.md describes the method.
#include "settle/core/profiles/fastest.hpp"
// SETTLE_CORE_FASTEST: whether the registry holds `fastest` (0 on M-profile cores unless defined).
#include "settle/core/profiles/registry.hpp"

// Where the registry leaves `fastest` out (Cortex-M by default: its moves do not fit the images'
// stacks), nothing can call the planner, and it is not built: it was a quarter of the library on
// the Cortex-M0 (the link check that forces every symbol into a 256 KiB image stood at 99 %).
#if SETTLE_CORE_FASTEST

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>

#include "settle/core/golden_section.hpp"
#include "settle/core/limits.hpp"
#include "settle/core/piecewise_jerk.hpp"
#include "settle/core/residual.hpp"
#include "settle/core/shaper.hpp"
#include "settle/core/small_solve.hpp"
#include "fastest_scale.hpp"
#include "numeric/complex.hpp"
#include "numeric/levenberg_marquardt.hpp"

namespace settle::core {

namespace {

using namespace numeric;

struct ModeSet {
  std::array<Mode, kMaxModes> m{};
  std::size_t n{0};
};

// ----- jerk tables ---------------------------------------------------------------------------

// Appends a segment (merged with the last when its jerk is the same); false when the table is
// full (the caller then drops the whole table). accel0 follows from the segments before.
[[nodiscard]] bool push_segment(FastestTable& p, double d, double j) noexcept {
  if (!(d > 0.0)) return true;
  if (p.count > 0 && p.jerk[p.count - 1] == j) {
    p.durations[p.count - 1] += d;
    return true;
  }
  if (p.count >= kFastestSegments) return false;
  p.accel0[p.count] = p.count == 0 ? 0.0 : p.accel0[p.count - 1] + p.jerk[p.count - 1] * p.durations[p.count - 1];
  p.durations[p.count] = d;
  p.jerk[p.count] = j;
  ++p.count;
  return true;
}

double table_duration(const FastestTable& p) noexcept {
  double t = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) t += p.durations[i];
  return t;
}

// ----- family: the time-optimal move convolved with shapers -----------------------------------

// The time-optimal move shaped by s, flattened into one constant-jerk table. False when the
// breakpoints do not fit the table.
bool flatten_shaped(const PiecewiseJerkParams& base, const Shaper<double>& s, FastestTable& out) noexcept {
  std::array<double, kMaxJerkSegments + 1> bt{};
  std::size_t nb = 0;
  double t = 0.0;
  bt[nb++] = 0.0;
  for (std::size_t i = 0; i < base.count; ++i) bt[nb++] = (t += base.durations[i]);
  const double total = t + s.duration();
  std::array<double, (kMaxJerkSegments + 1) * kMaxImpulses> br{};
  std::size_t n = 0;
  for (std::size_t k = 0; k < s.count; ++k) {
    for (std::size_t i = 0; i < nb; ++i) br[n++] = bt[i] + s.time[k];
  }
  std::sort(br.begin(), br.begin() + static_cast<std::ptrdiff_t>(n));
  const auto jerk_at = [&](double tm) {
    double j = 0.0;
    for (std::size_t k = 0; k < s.count; ++k) {
      const double u = tm - s.time[k];
      if (!(u > 0.0) || u >= t) continue;
      double acc = 0.0;
      for (std::size_t i = 0; i < base.count; ++i) {
        if (u < acc + base.durations[i]) {
          j += s.amp[k] * base.jerk[i];
          break;
        }
        acc += base.durations[i];
      }
    }
    return j;
  };
  FastestTable p{};
  p.distance = base.distance;
  const double merge = 1e-13 * total;
  double last = 0.0, a = 0.0;
  for (std::size_t i = 1; i < n; ++i) {
    if (br[i] - last <= merge) continue;
    if (p.count >= kFastestSegments) return false;
    const double d = br[i] - last;
    const double j = jerk_at(last + 0.5 * d);
    p.durations[p.count] = d;
    p.accel0[p.count] = a;
    p.jerk[p.count] = j;
    ++p.count;
    a += j * d;
    last = br[i];
  }
  out = p;
  return true;
}

// ----- family: bang-coast switch times ---------------------------------------------------------
//
// Both forms describe the move (or its acceleration pulse) as one alternating pattern: h
// ramp/coast pairs, ramps alternately at +J and -J, and a closing ramp back to a = 0, so the jerk
// stays in {+J, 0, -J} by construction. The durations are t0 y^2 (never negative); the
// inequalities are equalities with squared slacks. For a move time T the equalities are solved
// by Levenberg-Marquardt (minimum-norm steps); T is then lowered to the shortest that still
// solves (descend()).
//
// - mirrored pulse: a(t) = g(t) - g(t - tau), the pattern g, a cruise, and the pattern mirrored,
//   with D = v_c tau (v_c the pulse's area). Its transform is G(s) (1 - e^{-s tau}), so the move
//   leaves a mode at rest when G vanishes at the mode's pole (and robustly when G's derivatives
//   vanish too). Slacks: the coast levels within amax, v_c <= vmax, and a non-negative cruise.
// - whole move: the pattern is the move. Equalities: v = 0 and p = D at the end, the end at T,
//   the zero conditions referred to T; slacks: the coast levels within amax and |v| <= vmax at
//   each coast's end (the velocity may still peak inside a ramp: the result is checked). This
//   form also holds moves whose acceleration and deceleration overlap (short moves on slow
//   modes), which the mirrored form cannot.
//
// Unknowns: y[0..2h) the ramp and coast durations (ramp i at 2i, coast i at 2i + 1), then the
// level slacks y[2h..3h), then the form's own slacks.

constexpr std::size_t kMaxPairs = 7;       // mirrored: 4h + 3 segments <= kFastestSegments
constexpr std::size_t kMaxFullPairs = 15;  // whole: 2h + 1 segments <= kFastestSegments
constexpr std::size_t kMaxConds = 6;       // complex conditions
// Sized for the larger form (the whole move: durations 2h, level and velocity slacks h each).
constexpr std::size_t kMaxVars = 4 * kMaxFullPairs;
constexpr std::size_t kMaxEqs = 3 + 2 * kMaxConds + 2 * kMaxFullPairs;
constexpr std::size_t kMaxSwitches = 2 * kMaxFullPairs + 2;

struct Condition {
  Cx p;       // the pole
  double w;   // omega, to scale t
  int order;  // derivative order q: sum dj (-w t)^q e^{-p t} = 0
};

struct Problem {
  bool mirrored{true};
  double D{0.0}, J{0.0}, amax{0.0}, vmax{0.0}, t0{1.0};
  double t_ref{0.0};  // mirrored: conditions referred to this time (about the pulse's end)
  std::size_t h{2};
  std::array<Condition, kMaxConds> cond{};
  std::size_t nc{0};
  [[nodiscard]] std::size_t max_pairs() const noexcept { return mirrored ? kMaxPairs : kMaxFullPairs; }
  [[nodiscard]] std::size_t nvar() const noexcept { return mirrored ? 3 * h + 2 : 4 * h; }
  [[nodiscard]] std::size_t neq() const noexcept { return mirrored ? 1 + 2 * nc + h + 2 : 3 + 2 * nc + 2 * h; }
  [[nodiscard]] bool fits() const noexcept { return h <= max_pairs() && neq() <= kMaxEqs && nvar() <= kMaxVars; }
};

using Vec = std::array<double, kMaxVars>;
using EqVec = std::array<double, kMaxEqs>;
// The Jacobian, as it is structured: dense over the durations (columns 0 .. 2h), and each slack
// column (from 2h on) holding one entry, on its own row.
using Jac = numeric::SlackJacobian<kMaxEqs, 2 * kMaxFullPairs, kMaxVars>;

// The pattern's segment durations, jerks (units of J) and switch times from the unknowns.
struct Pattern {
  std::size_t h{0}, nseg{0};
  std::array<double, 2 * kMaxFullPairs + 1> d{}, j{};
  std::array<double, kMaxSwitches> t{}, dj{};  // switch times and jerk jumps (units of J)
  std::array<double, kMaxFullPairs> level{};   // acceleration on each coast (units of J s)
  double close_sign{0.0};                      // the closing ramp's duration is close_sign * level[h-1]
  double end{0.0};                             // the pattern's length
  std::array<double, 2 * kMaxFullPairs> g{};   // d(duration)/dy = 2 t0 y
};

Pattern make_pattern(const Problem& b, const Vec& y) noexcept {
  Pattern q{};
  q.h = b.h;
  double lv = 0.0;
  for (std::size_t i = 0; i < b.h; ++i) {
    const double sg = (i % 2 == 0) ? 1.0 : -1.0;
    const double r = b.t0 * y[2 * i] * y[2 * i];
    lv += sg * r;
    q.level[i] = lv;
    q.d[2 * i] = r;
    q.j[2 * i] = sg;
    q.d[2 * i + 1] = b.t0 * y[2 * i + 1] * y[2 * i + 1];
    q.j[2 * i + 1] = 0.0;
    q.g[2 * i] = 2.0 * b.t0 * y[2 * i];
    q.g[2 * i + 1] = 2.0 * b.t0 * y[2 * i + 1];
  }
  q.close_sign = lv >= 0.0 ? 1.0 : -1.0;
  q.d[2 * b.h] = std::fabs(lv);
  q.j[2 * b.h] = -q.close_sign;
  q.nseg = 2 * b.h + 1;
  double t = 0.0, prev = 0.0;
  for (std::size_t k = 0; k < q.nseg; ++k) {
    q.t[k] = t;
    q.dj[k] = q.j[k] - prev;
    prev = q.j[k];
    t += q.d[k];
  }
  q.t[q.nseg] = t;
  q.dj[q.nseg] = -prev;
  q.end = t;
  return q;
}

// The chain rule through the switch times: out[v] = sum_{k <= K} x[k] d t_k / d y_v. Switch k
// follows every earlier segment (d t_k / d y_v = 2 t0 y_v for v < k) and the last switch also
// the closing ramp (whose duration is +-(sum of signed ramps)), so the sum is a suffix sum: no
// matrix of derivatives is formed.
template <typename X>
void chain(const Pattern& q, const X* x, std::size_t K, X* out) noexcept {
  const std::size_t nv = 2 * q.h;
  X s{};
  for (std::size_t k = nv + 1; k <= K; ++k) s = s + x[k];
  const bool closing = K == q.nseg;
  for (std::size_t v = nv; v-- > 0;) {
    if (v + 1 <= K) s = s + x[v + 1];
    X o = q.g[v] * s;
    if (closing && v % 2 == 0) o = o + (q.close_sign * ((v / 2) % 2 == 0 ? 1.0 : -1.0) * q.g[v]) * x[q.nseg];
    out[v] = o;
  }
}
// d t_k / d y_v for one switch.
double switch_derivative(const Pattern& q, std::size_t k, std::size_t v) noexcept {
  double d = v < k ? q.g[v] : 0.0;
  if (k == q.nseg && v % 2 == 0) d += q.close_sign * ((v / 2) % 2 == 0 ? 1.0 : -1.0) * q.g[v];
  return d;
}

// The rows both forms share, from row e on: the zero-residual conditions referred to t_ref, and
// the coast levels within amax (1 - (J L / amax)^2 - s^2 = 0). Returns the next row.
std::size_t shared_rows(const Problem& b, const Pattern& q, const Vec& y, double t_ref, EqVec& f, Jac* jac,
                        std::size_t e) noexcept {
  const std::size_t ns = q.nseg + 1, nv = 2 * b.h;
  for (std::size_t c = 0; c < b.nc; ++c) {
    const Condition& cd = b.cond[c];
    Cx sum{};
    std::array<Cx, kMaxSwitches> dk{}, ex{};
    std::array<bool, kMaxSwitches> have_ex{};
    const auto ex_at = [&](std::size_t k) {  // e^{-p (t_k - t_ref)}, once per switch
      if (!have_ex[k]) {
        ex[k] = cexp_neg(cd.p, q.t[k] - t_ref);
        have_ex[k] = true;
      }
      return ex[k];
    };
    // The jump form: the sum itself for derivative orders above 0, the Jacobian for all.
    if (jac || cd.order != 0) {
      for (std::size_t k = 0; k < ns; ++k) {
        if (q.dj[k] == 0.0) continue;
        const Cx x = ex_at(k);
        const double u = -cd.w * (q.t[k] - t_ref);
        const double uq = cd.order == 0 ? 1.0 : std::pow(u, cd.order);
        sum = sum + (q.dj[k] * uq) * x;
        if (jac) {
          // d/dt [u^q e^{-pt}] = (q u^{q-1} (-w) - p u^q) e^{-pt}
          const double uq1 =
              cd.order == 0 ? 0.0 : cd.order * (cd.order == 1 ? 1.0 : std::pow(u, cd.order - 1)) * -cd.w;
          dk[k] = q.dj[k] * (Cx{uq1 - cd.p.re * uq, -cd.p.im * uq} * x);
        }
      }
    }
    if (cd.order == 0) {
      // The same sum segment by segment, sum_m j_m e^{-p (t_{m+1} - t_ref)} (e^{p d_m} - 1):
      // accurate to the terms' own size, where the jump form cancels (short segments, low omega).
      sum = Cx{};
      for (std::size_t m = 0; m < q.nseg; ++m) {
        if (q.j[m] != 0.0) sum = sum + q.j[m] * (ex_at(m + 1) * cexpm1(q.d[m] * cd.p));
      }
    }
    f[e] = sum.re;
    f[e + 1] = sum.im;
    if (jac) {
      std::array<Cx, 2 * kMaxFullPairs> grad{};
      chain(q, dk.data(), q.nseg, grad.data());
      for (std::size_t v = 0; v < nv; ++v) {
        jac->d[e][v] = grad[v].re;
        jac->d[e + 1][v] = grad[v].im;
      }
    }
    e += 2;
  }
  for (std::size_t i = 0; i < b.h; ++i) {
    const double x = b.J * q.level[i] / b.amax;
    const std::size_t sv = 2 * b.h + i;
    f[e] = 1.0 - x * x - y[sv] * y[sv];
    if (jac) {
      for (std::size_t l = 0; l <= i; ++l) {
        const double sg = (l % 2 == 0) ? 1.0 : -1.0;
        jac->d[e][2 * l] = -2.0 * x * (b.J / b.amax) * sg * q.g[2 * l];
      }
      jac->set_slack(e, sv, -2.0 * y[sv]);
    }
    ++e;
  }
  return e;
}

// Mirrored pulse: distance, shared rows, v_c <= vmax, cruise >= 0.
void mirrored_residuals(const Problem& b, const Pattern& q, double T, const Vec& y, EqVec& f, Jac* jac) noexcept {
  const std::size_t ns = q.nseg + 1, nv = 2 * b.h;
  // Area (velocity gain) v_c = J/2 sum dj t^2; tau = T - tg; D = v_c tau.
  double vc = 0.0;
  std::array<double, kMaxSwitches> x{};
  for (std::size_t k = 0; k < ns; ++k) {
    vc += 0.5 * b.J * q.dj[k] * q.t[k] * q.t[k];
    x[k] = b.J * q.dj[k] * q.t[k];
  }
  std::array<double, 2 * kMaxFullPairs> dvc{};
  if (jac) chain(q, x.data(), q.nseg, dvc.data());
  const double tau = T - q.end;
  std::size_t e = 0;
  f[e] = vc * tau / b.D - 1.0;
  if (jac) {
    for (std::size_t v = 0; v < nv; ++v) jac->d[e][v] = (dvc[v] * tau - vc * switch_derivative(q, q.nseg, v)) / b.D;
  }
  ++e;
  e = shared_rows(b, q, y, b.t_ref, f, jac, e);
  // vmax: 1 - v_c / vmax - s^2 = 0.
  {
    const std::size_t sv = 3 * b.h;
    f[e] = 1.0 - vc / b.vmax - y[sv] * y[sv];
    if (jac) {
      for (std::size_t v = 0; v < nv; ++v) jac->d[e][v] = -dvc[v] / b.vmax;
      jac->set_slack(e, sv, -2.0 * y[sv]);
    }
    ++e;
  }
  // Cruise >= 0: (T - 2 tg) / t0 - s^2 = 0.
  {
    const std::size_t sv = 3 * b.h + 1;
    f[e] = (tau - q.end) / b.t0 - y[sv] * y[sv];
    if (jac) {
      for (std::size_t v = 0; v < nv; ++v) jac->d[e][v] = -2.0 * switch_derivative(q, q.nseg, v) / b.t0;
      jac->set_slack(e, sv, -2.0 * y[sv]);
    }
  }
}

// Whole move: rest and distance at the end, the end at T, shared rows, |v| <= vmax at each
// coast's end.
void whole_residuals(const Problem& b, const Pattern& q, double T, const Vec& y, EqVec& f, Jac* jac) noexcept {
  const std::size_t ns = q.nseg + 1, nv = 2 * b.h;
  // With sum dj = 0 and sum dj t = 0 (a = 0 at the end): v_end = J/2 sum dj t^2 and, once
  // v_end = 0, p_end = -J/6 sum dj t^3 (times taken from the end to keep the sums small). Only
  // their derivatives are used: the values come from integrating segment by segment (the sums
  // cancel to the last digits of J T^2).
  const double vs = b.D / T;
  double pe = 0.0, ve = 0.0, ae = 0.0;
  for (std::size_t m = 0; m < q.nseg; ++m) {
    const double d = q.d[m], jm = b.J * q.j[m];
    pe += d * (ve + d * (ae / 2.0 + jm * d / 6.0));
    ve += d * (ae + jm * d / 2.0);
    ae += jm * d;
  }
  f[0] = ve / vs;
  f[1] = pe / b.D - 1.0;
  f[2] = (q.end - T) / b.t0;
  if (jac) {
    std::array<double, kMaxSwitches> xv{}, xp{};
    for (std::size_t k = 0; k < ns; ++k) {
      const double u = q.t[k] - q.end;
      xv[k] = b.J * q.dj[k] * u / vs;
      xp[k] = -0.5 * b.J * q.dj[k] * u * u / b.D;
    }
    // p(t_end) also moves with t_end at the rate v_end.
    xp[q.nseg] += ve / b.D;
    std::array<double, 2 * kMaxFullPairs> gv{}, gp{};
    chain(q, xv.data(), q.nseg, gv.data());
    chain(q, xp.data(), q.nseg, gp.data());
    for (std::size_t w = 0; w < nv; ++w) {
      jac->d[0][w] = gv[w];
      jac->d[1][w] = gp[w];
      jac->d[2][w] = switch_derivative(q, q.nseg, w) / b.t0;
    }
  }
  std::size_t e = shared_rows(b, q, y, T, f, jac, 3);
  // |v| <= vmax at the end of each coast: 1 - (v / vmax)^2 - s^2 = 0, v from the integration,
  // dv/dt_k = -J dj_k (t_e - t_k) and dv/dt_e = a(t_e) = J level.
  double vc = 0.0, ac = 0.0;  // velocity and acceleration at each coast's end
  for (std::size_t i = 0; i < b.h; ++i) {
    for (std::size_t m = 2 * i; m < 2 * i + 2; ++m) {
      const double d = q.d[m], jm = b.J * q.j[m];
      vc += d * (ac + jm * d / 2.0);
      ac += jm * d;
    }
    const std::size_t ke = 2 * i + 2;  // the switch at the coast's end
    const double x = vc / b.vmax;
    const std::size_t sv = 3 * b.h + i;
    f[e] = 1.0 - x * x - y[sv] * y[sv];
    if (jac) {
      std::array<double, kMaxSwitches> xs{};
      for (std::size_t k = 0; k < ke; ++k) xs[k] = -b.J * q.dj[k] * (q.t[ke] - q.t[k]);
      xs[ke] = b.J * q.level[i];
      std::array<double, 2 * kMaxFullPairs> dv{};
      chain(q, xs.data(), ke, dv.data());
      for (std::size_t w = 0; w < nv; ++w) jac->d[e][w] = -2.0 * x * dv[w] / b.vmax;
      jac->set_slack(e, sv, -2.0 * y[sv]);
    }
    ++e;
  }
}

// F(y) and its Jacobian for move time T.
void residuals(const Problem& b, double T, const Vec& y, EqVec& f, Jac* jac) noexcept {
  const Pattern q = make_pattern(b, y);
  if (jac) {
    jac->clear(b.neq(), 2 * b.h);
  }
  if (b.mirrored) {
    mirrored_residuals(b, q, T, y, f, jac);
  } else {
    whole_residuals(b, q, T, y, f, jac);
  }
}

// The equations are dimensionless (relative distance and velocity, residual sums of order 1);
// the move that comes out is checked on its own (limits, residual), so this only stops the solve.
constexpr double kSolveTol = 1e-11;
// Iterations from a seed, and from the previous move time's solution (descent steps); the
// descent stops at this relative width of the bracket.
constexpr int kFirstIterations = 40;
constexpr int kWarmIterations = 12;
constexpr double kBisectTol = 1e-6;

// The switch times for move time T from y (numeric/levenberg_marquardt.hpp).
bool lm_solve(const Problem& b, double T, Vec& y, int max_iter) noexcept {
  const auto f = [&](const Vec& yy, EqVec& out, Jac* jac) { residuals(b, T, yy, out, jac); };
  return numeric::levenberg_marquardt<kMaxEqs, 2 * kMaxFullPairs, kMaxVars>(
      f, numeric::LmSize{b.nvar(), b.neq(), 2 * b.h, kSolveTol}, y, max_iter);
}

// The move as a table: mirrored, the pulse, the cruise and the pulse mirrored; whole, the
// pattern. D > 0 in the pattern; the sign of `distance` is applied here.
FastestTable pattern_table(const Problem& b, double T, const Vec& y, double distance) noexcept {
  const Pattern q = make_pattern(b, y);
  const double sg = distance < 0.0 ? -1.0 : 1.0;
  FastestTable p{};
  p.distance = distance;
  bool ok = true;
  for (std::size_t k = 0; k < q.nseg; ++k) ok = push_segment(p, q.d[k], sg * b.J * q.j[k]) && ok;
  if (b.mirrored) {
    const double cruise = T - 2.0 * q.end;
    if (cruise > 1e-12 * T) ok = push_segment(p, cruise, 0.0) && ok;
    for (std::size_t k = 0; k < q.nseg; ++k) ok = push_segment(p, q.d[k], -sg * b.J * q.j[k]) && ok;
  }
  if (!ok) p.count = 0;  // does not fit: refused by the caller
  return p;
}

// The slack variables that make the inequalities hold with equality at y's pattern (or nearly).
void fit_slacks(const Problem& b, double T, Vec& y) noexcept {
  const Pattern q = make_pattern(b, y);
  for (std::size_t i = 0; i < b.h; ++i) {
    const double x = b.J * q.level[i] / b.amax;
    y[2 * b.h + i] = std::sqrt(std::fmax(1.0 - x * x, 1e-8));
  }
  if (b.mirrored) {
    double vc = 0.0;
    for (std::size_t k = 0; k <= q.nseg; ++k) vc += 0.5 * b.J * q.dj[k] * q.t[k] * q.t[k];
    y[3 * b.h] = std::sqrt(std::fmax(1.0 - vc / b.vmax, 1e-8));
    y[3 * b.h + 1] = std::sqrt(std::fmax((T - 2.0 * q.end) / b.t0, 1e-8));
    return;
  }
  double ve = 0.0, ae = 0.0;
  for (std::size_t i = 0; i < b.h; ++i) {
    for (std::size_t m = 2 * i; m < 2 * i + 2; ++m) {
      ve += q.d[m] * (ae + b.J * q.j[m] * q.d[m] / 2.0);
      ae += b.J * q.j[m] * q.d[m];
    }
    const double xv = ve / b.vmax;
    y[3 * b.h + i] = std::sqrt(std::fmax(1.0 - xv * xv, 1e-8));
  }
}

// Seeds for the mirrored form: the pulse as a staircase up then down, its total length a
// fraction of T / 2.
void staircase(const Problem& b, double T, double frac, int style, Vec& y) noexcept {
  y.fill(0.0);
  const double tg = frac * T / 2.0;
  const double each = tg / static_cast<double>(2 * b.h + 1);
  for (std::size_t i = 0; i < b.h; ++i) {
    double r = each;
    if (style == 1) r = (i % 2 == 0) ? each : 0.3 * each;
    if (style == 2) r = (i == 0) ? std::fmin(b.amax / b.J, tg / 3.0) : 0.2 * each;
    y[2 * i] = std::sqrt(r / b.t0);
    y[2 * i + 1] = std::sqrt(each / b.t0);
  }
}

}  // namespace

namespace {

// One walk over a table's segments: its exact peaks (jerk and acceleration at breakpoints,
// velocity also where the acceleration crosses zero inside a segment), and what the
// never-backwards rule reads: the lowest velocity in the move's direction and the peak |v| at the
// breakpoints.
struct TableWalk {
  Peaks<double> pk{};
  double lowest{0.0};    // min of sign(D) v
  double end_peak{0.0};  // max |v| at the breakpoints
};

TableWalk walk_table(const FastestTable& p) noexcept {
  TableWalk w{};
  const double sg = p.distance < 0.0 ? -1.0 : 1.0;
  double v = 0.0, a = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) {
    const double d = p.durations[i], j = p.jerk[i];
    w.pk.j = std::fmax(w.pk.j, std::fabs(j));
    // v(u) = v + a u + j u^2 / 2 is extremal where a + j u = 0 inside the segment.
    if (j != 0.0) {
      const double u = -a / j;
      if (u > 0.0 && u < d) {
        const double ve = v + a * u + j * u * u / 2.0;
        w.pk.v = std::fmax(w.pk.v, std::fabs(ve));
        w.lowest = std::fmin(w.lowest, sg * ve);
      }
    }
    v += d * (a + j * d / 2.0);
    a += j * d;
    w.pk.v = std::fmax(w.pk.v, std::fabs(v));
    w.pk.a = std::fmax(w.pk.a, std::fabs(a));
    w.lowest = std::fmin(w.lowest, sg * v);
    w.end_peak = std::fmax(w.end_peak, std::fabs(v));
  }
  return w;
}

}  // namespace

Peaks<double> jerk_table_peaks(const FastestTable& p) noexcept { return walk_table(p).pk; }

FastestParams detail::scaled_fastest(const FastestParams& p, double k) noexcept {
  FastestParams out = p;
  out.curve.distance = k * p.curve.distance;
  out.curve.amplitude = k * p.curve.amplitude;
  out.table.distance = k * p.table.distance;
  const std::size_t n = std::min(p.table.count, kFastestSegments);
  for (std::size_t i = 0; i < n; ++i) {
    out.table.accel0[i] = k * p.table.accel0[i];
    out.table.jerk[i] = k * p.table.jerk[i];
  }
  return out;
}

namespace {

// --robust: the residual ratio must stay <= 5 % over the band. It is sampled at 129 frequencies
// per mode and each local maximum is refined by golden-section search, so the bound holds between
// the samples too.
constexpr double kRobustLimit = 0.05;

double worst_over_band(const FastestTable& p, const ModeSet& ms, double band) noexcept {
  double worst = 0.0;
  constexpr int kSamples = 128;
  for (std::size_t i = 0; i < ms.n; ++i) {
    const double w0 = ms.m[i].omega, z = ms.m[i].zeta;
    const auto at = [&](int k) { return w0 * (1.0 - band + 2.0 * band * k / kSamples); };
    const auto ratio = [&](double w) { return residual_ratio(p, Mode{w, z}); };
    double prev2 = -1.0, prev = ratio(at(0));
    worst = std::fmax(worst, prev);
    for (int k = 1; k <= kSamples; ++k) {
      const double cur = ratio(at(k));
      worst = std::fmax(worst, cur);
      if (k >= 2 && prev >= prev2 && prev >= cur) {  // a local maximum around sample k - 1
        const double tol = 1e-12 * w0;
        const GoldenProbes g = golden_section_max(ratio, at(k - 2), at(k), 40,
                                                  [tol](double a, double b) { return !(b - a > tol); });
        worst = std::fmax(worst, std::fmax(g.fc, g.fd));
      }
      prev2 = prev;
      prev = cur;
    }
  }
  return worst;
}

// A point-to-point move never runs backwards: v has the sign of D throughout (so the position
// stays between start and target). Without this rule the shortest moves on slow modes swing the
// axis back by more than it moves forward (docs/fastest.md, "Never backwards"). For a jerk table
// walk_table finds the lowest velocity exactly (table_ok below reads it).
constexpr double kBackwardsTol = 1e-9;  // of the peak |v|: rounding, not motion
// The ramp-cycloid's velocity is a polynomial plus one period of a sinusoid on each piece:
// sampled, 32 points a piece (the S-curves run backwards only where a damped transition's
// acceleration overshoots far, e.g. D 0.03 on a 2 rad/s mode).
bool runs_backwards(const RampCycloidParams& c) noexcept {
  const RampCycloid<double> m{c};
  const double sg = m.distance() < 0.0 ? -1.0 : 1.0;
  constexpr int kSamples = 32;
  double lowest = 0.0, peak = 0.0;
  for (int i = 0; i < m.piece_count(); ++i) {
    const Piece pc = m.piece(i);
    for (int k = 0; k <= kSamples; ++k) {
      const double v = piece_at(pc, pc.start + pc.length * k / kSamples).v;
      lowest = std::fmin(lowest, sg * v);
      peak = std::fmax(peak, std::fabs(v));
    }
  }
  return lowest < -kBackwardsTol * peak;
}

struct Best {
  FastestParams p{};
  Peaks<double> pk{};
  double time{HUGE_VAL};
};

// Exact: every mode's residual amplitude within kDesignResidual |D| (residual.hpp), or within what the table's
// double-precision switch times allow: each is off by about eps T, which moves the velocity by
// about |j| eps T per switch and leaves about that over omega. Only tiny moves on slow modes
// (1 um on 2 rad/s) reach that floor; without it nothing, not even the time-optimal move * ZV,
// passes for them.
bool design_ok(const FastestTable& p, const ModeSet& ms, double band) noexcept {
  if (band > 0.0) return worst_over_band(p, ms, band) <= kRobustLimit;
  double T = 0.0, jpk = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) {
    T += p.durations[i];
    jpk = std::fmax(jpk, std::fabs(p.jerk[i]));
  }
  constexpr double kEps = 2.220446049250313e-16;
  const double time_floor = 16.0 * static_cast<double>(p.count) * jpk * kEps * T;
  for (std::size_t i = 0; i < ms.n; ++i) {
    const double amp = residual_amplitude(p, ms.m[i]);
    if (!(amp <= kDesignResidual * std::fabs(p.distance) + time_floor / ms.m[i].omega)) return false;
  }
  return true;
}

// A jerk-table candidate of any family: its exact peaks within the limits, never backwards, and
// its design held (exact zeros, or the band). pk gets its peaks.
bool table_ok(const FastestTable& t, const Limits& lim, const ModeSet& ms, double band, Peaks<double>& pk) noexcept {
  const TableWalk w = walk_table(t);
  pk = w.pk;
  return within_limits(pk, lim) && !(w.lowest < -kBackwardsTol * w.end_peak) &&
         design_ok(t, ms, band);
}

// A candidate replaces the best only when shorter by more than rounding (1e-9 of it): a later
// family that reproduces an earlier one's move (bang-coast seeded with the bang-bang move) does
// not take its name.
void consider(Best& best, const FastestParams& p, const Peaks<double>& pk, double time) noexcept {
  if (time < best.time * (1.0 - 1e-9)) {
    best.p = p;
    best.pk = pk;
    best.time = time;
  }
}

// Lays a move whose jerk takes any value in [-J, J] (the time-optimal move or pulse convolved
// with a shaper) onto the alternating pattern: each maximal run of segments whose jerk has one
// sign (zero-jerk segments inside it included) becomes one ramp at that sign with the run's
// change of acceleration, followed by a coast for the rest of the run; a coast at zero
// acceleration (a cruise, or rest between two parts) ends a run and stays a coast when
// `break_at_rest` (two seeds: the other merges it into the run). Where two
// ramps of one sign follow each other (and before a negative first one) a tiny opposite ramp
// keeps the pattern alternating. Returns the number of ramps (0 when more than `cap`).
std::size_t alternate_runs(const FastestTable& g, double J, double tiny, bool break_at_rest, double* ramp,
                           double* coast, std::size_t cap) noexcept {
  std::size_t n = 0;
  double last_sign = -1.0;  // the pattern starts with a positive ramp
  double run_sign = 0.0, run_da = 0.0, run_len = 0.0, a = 0.0, a_peak = 0.0;
  const auto flush = [&]() {
    if (run_sign == 0.0) return true;
    if (run_sign == last_sign) {  // two ramps of one sign: a tiny opposite one between them
      if (n >= cap) return false;
      ramp[n] = tiny;
      coast[n] = 0.0;
      ++n;
    }
    if (n >= cap) return false;
    ramp[n] = std::fmin(std::fabs(run_da) / J, run_len);
    coast[n] = run_len - ramp[n];
    ++n;
    last_sign = run_sign;
    run_sign = 0.0;
    return true;
  };
  for (std::size_t k = 0; k < g.count; ++k) {
    const double f = g.jerk[k] / J, d = g.durations[k];
    if (std::fabs(f) < 1e-12) {
      // A coast at zero acceleration (cruise, or rest between two parts of the move) ends the run.
      if (break_at_rest && std::fabs(a) <= 1e-9 * a_peak && run_sign != 0.0) {
        if (!flush()) return 0;
      }
      if (n > 0 && run_sign == 0.0) coast[n - 1] += d;
      else if (run_sign != 0.0) run_len += d;
      continue;
    }
    const double sg = f > 0.0 ? 1.0 : -1.0;
    if (sg != run_sign) {
      if (!flush()) return 0;
      run_sign = sg;
      run_da = 0.0;
      run_len = 0.0;
    }
    run_da += f * J * d;
    run_len += d;
    a += f * J * d;
    a_peak = std::fmax(a_peak, std::fabs(a));
  }
  if (!flush()) return 0;
  return n;
}

// A seed from a move (whole form) or pulse (mirrored) whose jerk may take any value in [-J, J]
// (alternate_runs); the last ramp is the pattern's closing ramp. Sets b.h; false when the seed
// needs more pairs than the form holds. The slacks are left to fit_slacks.
bool seed_pattern(Problem& b, const FastestTable& g, bool break_at_rest, Vec& y) noexcept {
  constexpr double kTiny = 1e-6;
  const std::size_t cap = b.max_pairs();
  std::array<double, 2 * kMaxFullPairs + 2> ramp{}, coast{};
  const std::size_t n = alternate_runs(g, b.J, kTiny * b.t0, break_at_rest, ramp.data(), coast.data(), 2 * cap + 2);
  if (n < 2 || n - 1 > cap) return false;
  const std::size_t pairs = n - 1;  // the last ramp closes the pattern
  b.h = std::max(pairs, std::min(cap, b.nc + (b.mirrored ? 1 : 2)));
  y.fill(0.0);
  for (std::size_t i = 0; i < b.h; ++i) {
    const double rr = i < pairs ? ramp[i] : kTiny * b.t0;
    const double c = i < pairs ? coast[i] : kTiny * b.t0;
    y[2 * i] = std::sqrt(std::fmax(rr, kTiny * b.t0) / b.t0);
    y[2 * i + 1] = std::sqrt(std::fmax(c, kTiny * b.t0) / b.t0);
  }
  return true;
}

// A seed move (or pulse) with the move time it comes from.
struct Seed {
  FastestTable g{};
  double time{0.0};
};

// True when an earlier seed is the same move with the same time (the shortest move so far is
// often the time-optimal move * ZV, which is also a seed of its own).
bool same_as_earlier_seed(const Seed* seeds, std::size_t k) noexcept {
  const FastestTable& g = seeds[k].g;
  for (std::size_t i = 0; i < k; ++i) {
    const FastestTable& o = seeds[i].g;
    if (seeds[i].time != seeds[k].time || o.count != g.count || o.distance != g.distance) continue;
    bool same = true;
    for (std::size_t s = 0; s < g.count && same; ++s) same = o.durations[s] == g.durations[s] && o.jerk[s] == g.jerk[s];
    if (same) return true;
  }
  return false;
}

// Shortest bang-coast move of one form for the conditions, no longer than t_cap; false when none
// was found. From each seed that solves (at its own move time), the move time is lowered with
// warm starts down to the shortest that still solves and passes the checks (exact peaks within
// the limits, residual); the shortest over the seeds wins.
bool plan_pattern(const MoveRequest& r, const ModeSet& ms, bool mirrored, const std::array<Condition, kMaxConds>& cond,
                  std::size_t nc, const Seed* seeds, std::size_t nseeds, double t_lo, double t_cap, double band,
                  FastestTable& out, Peaks<double>& out_pk) noexcept {
  Problem b{};
  b.mirrored = mirrored;
  b.D = std::fabs(r.distance);
  b.J = *r.limits.jmax;
  b.amax = *r.limits.amax;
  b.vmax = *r.limits.vmax;
  b.t0 = t_cap;
  b.cond = cond;
  b.nc = nc;
  const auto accept = [&](const Problem& bb, double T, const Vec& yy, FastestTable& p, Peaks<double>& pk) {
    p = pattern_table(bb, T, yy, r.distance);
    return p.count != 0 && table_ok(p, Limits{bb.vmax, bb.amax, bb.J}, ms, band, pk);
  };
  bool have = false;
  const auto descend = [&](const Problem& bb, double T, Vec y) {
    FastestTable bp{};
    Peaks<double> bpk{};
    if (!lm_solve(bb, T, y, kFirstIterations) || !accept(bb, T, y, bp, bpk)) return false;
    double hi = T, lo = t_lo;
    for (int it = 0; it < 40 && hi - lo > kBisectTol * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      Vec yt = y;
      FastestTable p{};
      Peaks<double> pk{};
      if (lm_solve(bb, mid, yt, kWarmIterations) && accept(bb, mid, yt, p, pk)) {
        hi = mid;
        y = yt;
        bp = p;
        bpk = pk;
      } else {
        lo = mid;
      }
    }
    if (!have || table_duration(bp) < table_duration(out)) {
      out = bp;
      out_pk = bpk;
      have = true;
    }
    return true;
  };
  // Mirrored: each pulse once. Whole: each move with both run rules (alternate_runs), skipping a
  // rule that gives the same seed.
  Vec last_seed{};
  std::size_t last_h = 0;
  for (std::size_t kk = 0; kk < (mirrored ? 1 : 2) * nseeds; ++kk) {
    const std::size_t k = mirrored ? kk : kk / 2;
    if (same_as_earlier_seed(seeds, k)) continue;  // it would descend exactly as that one did
    Problem bb = b;
    Vec y{};
    if (!seed_pattern(bb, seeds[k].g, !mirrored && kk % 2 == 1, y) || !bb.fits()) continue;
    const double T = std::fmin(seeds[k].time, t_cap);
    bb.t_ref = make_pattern(bb, y).end;
    fit_slacks(bb, T, y);
    if (!mirrored) {
      if (bb.h == last_h && y == last_seed) continue;
      last_seed = y;
      last_h = bb.h;
    }
    (void)descend(bb, T, y);
  }
  if (!mirrored || have) return have;
  // Mirrored, when no seed solved: generic staircase pulses at t_cap.
  constexpr double kFracs[] = {0.9, 0.6, 0.98, 0.4};
  Problem bg = b;
  bg.h = std::min(kMaxPairs, nc + 2);
  if (!bg.fits()) return have;
  for (int style = 0; style < 3 && !have; ++style) {
    for (double fr : kFracs) {
      Vec y{};
      staircase(bg, t_cap, fr, style, y);
      bg.t_ref = make_pattern(bg, y).end;
      fit_slacks(bg, t_cap, y);
      if (descend(bg, t_cap, y)) break;
    }
  }
  return have;
}

PiecewiseJerkParams accel_pulse(const PiecewiseJerkParams& to) noexcept {
  PiecewiseJerkParams h{};
  double a = 0.0, peak = 0.0;
  const double sg = to.distance < 0.0 ? -1.0 : 1.0;
  for (std::size_t i = 0; i < to.count; ++i) {
    h.durations[h.count] = to.durations[i];
    h.jerk[h.count] = sg * to.jerk[i];
    h.accel0[h.count] = sg * to.accel0[i];
    ++h.count;
    a += sg * to.jerk[i] * to.durations[i];
    peak = std::fmax(peak, std::fabs(a));
    if (peak > 0.0 && std::fabs(a) <= 1e-9 * peak) break;
  }
  h.distance = 1.0;
  return h;
}

Status read_modes(const MoveRequest& r, ModeSet& ms) noexcept {
  ms.m[0] = r.modes[0];
  ms.n = 1;
  if (r.mode_count > kMaxModes) return Status::unsupported_request;
  for (std::size_t i = 1; i < r.mode_count; ++i) {
    if (const Status st = mode_status(r.modes[i]); st != Status::ok) return st;
    ms.m[ms.n++] = r.modes[i];
  }
  return Status::ok;
}

// ----- family: bang-bang with limit arcs ------------------------------------------------------

// In the shortest move the jerk is +-J everywhere except on arcs where a limit holds: for the
// rigid body plus linear modes, Pontryagin's switching function is a quadratic plus damped
// sinusoids, which cannot vanish on an interval, so there is no singular arc (no coast off a
// limit). The move is then a chain of nodes joined by ramps at +-J:
//   limit  a hold at a = +-amax                         unknown: its length
//   peak   a turn of a within the limits, no hold        unknown: its level
//   cruise a hold at a = 0 with v = +vmax                unknown: its length; equation v = vmax
//   dwell  a hold at a = 0 with v = 0                    unknown: its length; equation v = 0
// The axis never moves backwards (v >= 0 for D > 0): without that rule the shortest move on a
// slow mode can swing far beyond both ends (a 1 mm move on a 2 rad/s mode swings +-28 mm); with
// it, v = 0 inside the move is a dwell node. With 2 + 2m nodes of kind limit or peak (m modes),
// the equations (v = 0 and p = D at the end, the transform's real and imaginary part at each
// mode's pole, one per cruise or dwell node) are as many as the unknowns: Newton's method on a
// square system of at most kMaxArcNodes unknowns. An active-set loop changes the chain where a
// solution breaks a condition it does not hold as an equation: a negative limit hold makes the
// node a peak, a peak beyond amax a limit, a velocity above vmax where a ramp crosses a = 0 a
// cruise there, one below zero a dwell.

enum class ArcKind : std::uint8_t { limit, peak, cruise, dwell };
struct ArcNode {
  ArcKind kind{ArcKind::limit};
  double sign{1.0};  // limit / peak: the side of a; cruise and dwell: +1 (D > 0)
};
// Room for a chain of n nodes: 2 n + 1 segments <= kFastestSegments (47: 23 nodes). Every search
// grows its chains to kChainNodes at most (15, the room before session 26: with 23 the refinement
// grew three-mode chains and paid 30 to 50 times the instructions on some grid cases); only the
// dwell changes (dwell_changes) use the whole room.
constexpr std::size_t kMaxArcNodes = (kFastestSegments - 1) / 2;
// Ids of plan_arcs' paths within a group (its wiggles: 3 sizes and 2 ends per ramp).
constexpr std::size_t kMaxPathIds = 5 * (kMaxArcNodes + 1);
constexpr std::size_t kChainNodes = 15;
using ArcVec = std::array<double, kMaxArcNodes>;
using ArcMat = std::array<ArcVec, kMaxArcNodes>;

struct ArcChain {
  std::array<ArcNode, kMaxArcNodes> node{};
  ArcVec x{};  // limit, cruise, dwell: the hold (s); peak: the level
  std::size_t n{0};
};

// Sign of the ramp into a node and out of it.
double ramp_in(const ArcNode& k) noexcept { return k.kind == ArcKind::cruise ? -1.0 : k.sign; }
double ramp_out(const ArcNode& k) noexcept {
  return k.kind == ArcKind::limit || k.kind == ArcKind::peak ? -k.sign : ramp_in(k);
}

// pulse: the chain is the acceleration pulse g of a mirrored move a(t) = g(t) - g(t - D / vmax)
// (g, a cruise at vmax, g mirrored): its transform is G(s) (1 - e^{-s D / vmax}), so G = 0 at each
// pole leaves every mode at rest; g ends at v = vmax and has no distance condition. With 1 + 2m
// nodes the system is square again. It holds long moves on damped or several modes, where the
// whole chain (one cruise between 2 + 2m nodes) has too few nodes on each side.
// A mode's pole and the scales its rows use (taken once per problem, not per evaluation).
struct ArcPole {
  Cx s, inv_s, inv_s2;
  double scale{0.0};
};
// The last argument and value of each ramp's two exponentials, per mode (arc_values). Most
// arguments repeat from one evaluation to the next: a ramp between limits has the same length
// whatever the holds, and its computed length (t + d) - t mostly the same bits (three modes: 73 %
// of the calls). A hit returns the value the call would: bit for bit the same as calling.
class ArcExpMemo {
 public:
  // Holds no value of the first `modes` modes (the others are never asked for, and their
  // tables are left unset).
  explicit ArcExpMemo(std::size_t modes) noexcept {
    for (std::size_t m = 0; m < modes; ++m) {
      ramp_[m].key.fill(kNone);
      end_[m].key.fill(kNone);
      seen_[m].key.fill(kNone);
    }
  }
  template <class F>
  Cx get(std::size_t m, std::size_t r, bool ramp, double arg, F&& compute) noexcept {
    Slots<kMaxArcNodes + 1>& s = (ramp ? ramp_ : end_)[m];
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(arg);
    if (s.key[r] == bits) return s.val[r];
    s.key[r] = bits;
    if (ramp) {
      Slots<kSeen>& h = seen_[m];
      const std::size_t i = (bits * 0x9E3779B97F4A7C15ull) >> (64 - kSeenBits);
      if (h.key[i] != bits) {
        h.key[i] = bits;
        h.val[i] = compute();
      }
      return s.val[r] = h.val[i];
    }
    return s.val[r] = compute();
  }

 private:
  static constexpr int kSeenBits = 6;
  static constexpr std::size_t kSeen = std::size_t{1} << kSeenBits;
  // No argument is this signalling NaN (arithmetic returns quiet ones): a key never asked for.
  static constexpr std::uint64_t kNone = 0x7FF0000000000001ull;
  template <std::size_t N>
  struct Slots {
    std::array<std::uint64_t, N> key;
    std::array<Cx, N> val;
  };
  std::array<Slots<kMaxArcNodes + 1>, kMaxModes> ramp_, end_;
  std::array<Slots<kSeen>, kMaxModes> seen_;
};

struct ArcProblem {
  double D{0.0}, J{0.0}, amax{0.0}, vmax{0.0};
  const ModeSet* ms{nullptr};
  bool pulse{false};
  std::array<ArcPole, kMaxModes> poles{};
  ArcExpMemo* exps{nullptr};  // plan_arcs' own
  // arc_newton and arc_restore: a stall below the rows' rounding (arc_rounding_floor) solves the
  // chain, not only below a tenth of it (stall_floor), and arc_newton's stall rule does not give
  // up (split_to_rounding's solves only).
  bool to_rounding{false};
  // The most nodes a chain may grow to (kChainNodes; dwell_changes: kMaxArcNodes).
  std::size_t max_nodes{kChainNodes};
  // arc_refine: a cruise slowed down to 0.1 vmax alone, not to each level of kSlowTo
  // (dwell_changes' round).
  bool one_slowdown{false};
  // arc_refine: no cruise slowed down, only stopped (the rounds of dwell_passes' stops).
  bool no_slowdown{false};
};

ArcProblem arc_problem(const MoveRequest& r, const ModeSet& ms) noexcept {
  ArcProblem pb{};
  pb.D = std::fabs(r.distance);
  pb.J = *r.limits.jmax;
  pb.amax = *r.limits.amax;
  pb.vmax = *r.limits.vmax;
  pb.ms = &ms;
  for (std::size_t m = 0; m < ms.n; ++m) {
    const Cx s = pole(ms.m[m].omega, ms.m[m].zeta);
    const double s_n2 = s.re * s.re + s.im * s.im;
    const Cx inv_s{s.re / s_n2, -s.im / s_n2};
    pb.poles[m] = {s, inv_s, inv_s * inv_s, 1.0 / (pb.D * ms.m[m].omega)};
  }
  return pb;
}

// The chain laid out: ramp r (r < n into node r, r = n the closing ramp) runs from b[r] to e[r]
// with jerk j[r]; node r holds from e[r] to b[r + 1]. Only the entries r <= n are written (and
// read): zeroing the rest, and copying the whole into each evaluation, was 2 % of a two-mode
// plan's instructions.
struct ArcLayout {
  std::array<double, kMaxArcNodes + 1> b, e, j;
  double T;
};

// The level of a node: +-amax on a limit, its own on a peak, 0 on a cruise or a dwell.
double node_level(const ArcProblem& pb, const ArcChain& c, std::size_t i) noexcept {
  const ArcNode& k = c.node[i];
  return k.kind == ArcKind::limit ? k.sign * pb.amax : k.kind == ArcKind::peak ? c.x[i] : 0.0;
}

// What lay_out reads of a chain's nodes: each ramp's jerk, each node's level but a peak's (its
// unknown), and which nodes are peaks. lay_out(pb, c, L) takes it and walks the chain with
// lay_out(shape, c, L); where many points of the same nodes are laid out (the line searches of
// arc_newton and arc_restore) it is taken once, and their walks test no kinds (on the three-mode
// request of issue 36, 2.8 M of its 51 M instructions).
struct ArcShape {
  std::array<double, kMaxArcNodes + 1> js;  // ramp r's jerk s J
  std::array<double, kMaxArcNodes> lev;     // a limit's sign amax, 0 on a cruise or dwell
  std::array<bool, kMaxArcNodes> peak;
};
ArcShape arc_shape(const ArcProblem& pb, const ArcChain& c) noexcept {
  ArcShape sh;
  for (std::size_t r = 0; r < c.n; ++r) {
    const ArcNode& k = c.node[r];
    sh.js[r] = ramp_in(k) * pb.J;
    sh.lev[r] = k.kind == ArcKind::limit ? k.sign * pb.amax : 0.0;
    sh.peak[r] = k.kind == ArcKind::peak;
  }
  sh.js[c.n] = ramp_out(c.node[c.n - 1]) * pb.J;
  return sh;
}
void lay_out(const ArcShape& sh, const ArcChain& c, ArcLayout& L) noexcept {
  const std::size_t n = c.n;
  double t = 0.0, a = 0.0;
  for (std::size_t r = 0; r < n; ++r) {
    const bool pk = sh.peak[r];
    const double lev = pk ? c.x[r] : sh.lev[r], hold = pk ? 0.0 : c.x[r];
    const double e = t + (lev - a) / sh.js[r];
    L.b[r] = t;
    L.e[r] = e;
    L.j[r] = sh.js[r];
    t = e + hold;
    a = lev;
  }
  L.b[n] = t;
  L.e[n] = t + (0.0 - a) / sh.js[n];
  L.j[n] = sh.js[n];
  L.T = L.e[n];
}
void lay_out(const ArcProblem& pb, const ArcChain& c, ArcLayout& L) noexcept { lay_out(arc_shape(pb, c), c, L); }
ArcLayout lay_out(const ArcProblem& pb, const ArcChain& c) noexcept {
  ArcLayout L;
  lay_out(pb, c, L);
  return L;
}

// The square system F(x) (dimensionless) and its Jacobian. Each quantity is a sum
// over the ramps of a function of the times u = T - t before the end; its derivative with
// respect to each switch time, summed from the back (every switch time is the sum of the
// lengths before it), gives the derivative with respect to each unknown. arc_values takes F and
// keeps what the Jacobian reuses (the layout, the exponentials at each ramp's ends), so a line
// search's rejected trials pay for F alone and an accepted one's Jacobian costs no exponential.
// (Its exponentials are plain pairs without initialisers: arc_values writes every entry the
// Jacobian reads, and zeroing 2 KB per evaluation cost the one-mode case 4 % of its instructions.)
struct CxSlot {
  double re, im;
  operator Cx() const noexcept { return {re, im}; }
};
struct ArcEval {
  ArcLayout L;
  double v;                                                            // at the end
  std::array<std::array<CxSlot, kMaxArcNodes + 1>, kMaxModes> eb, ee;  // E(u_b), E(u_e) per mode and ramp
  std::array<Cx, kMaxModes> val;                                       // the transform per mode
};

// With `stop` (a line search's norm to beat, of F - mu f0 when f0 is given): returns 0, and
// leaves f and ev unfinished, where the rows of v and p alone already reach it. Their squares
// are the first terms of the norm's sum, which adding the other rows' squares cannot lower, so
// the trial would be rejected all the same (arc_newton and arc_restore reject a norm that is
// not below; the merit of arc_restore adds nonnegative terms to the norm). The rows of v on
// each cruise or dwell (no exponential) are tested next, before the modes' (an exponential per
// mode and ramp): their squares are not the next terms of arc_norm's sum, and a sum of k
// nonnegative terms is rounded to within k eps of its value in any order (23 rows at most:
// 5e-15), so from them on a test rejects at stop (1 + 1e-12) only, and the trials rejected are
// the same. Not with `!speed_first`: where the caller fails on a trial the modes' rows do not
// reject (arc_newton's first step at 2^-9), a trial rejected before them would not fail it.
// With `shape` (arc_shape of c's nodes), c is laid out from it.
std::size_t arc_values(const ArcProblem& pb, const ArcChain& c, ArcVec& f, ArcEval& ev, double stop = HUGE_VAL,
                       const ArcVec* f0 = nullptr, double mu = 0.0, bool speed_first = true,
                       const ArcShape* shape = nullptr) noexcept {
  if (shape != nullptr) {
    lay_out(*shape, c, ev.L);
  } else {
    lay_out(pb, c, ev.L);
  }
  const ArcLayout& L = ev.L;
  const std::size_t n = c.n;
  const double T = L.T;
  std::size_t row = 0;
  // v and p at the end.
  double v = 0.0, p = 0.0;
  for (std::size_t r = 0; r <= n; ++r) {
    const double ub = T - L.b[r], ue = T - L.e[r], jr = L.j[r];
    v += jr * (ub * ub - ue * ue) / 2.0;
    p += jr * (ub * ub * ub - ue * ue * ue) / 6.0;
  }
  ev.v = v;
  f[row++] = (v - (pb.pulse ? pb.vmax : 0.0)) / pb.vmax;
  if (!pb.pulse) f[row++] = (p - pb.D) / pb.D;
  // The norm's sum over the rows so far: true where it reaches `stop` already (in_order: the
  // rows added are the first ones of arc_norm's sum, in its order).
  double sq = 0.0;
  bool in_order = true;
  const auto rejected = [&](std::size_t from, std::size_t to) {
    if (!(stop < HUGE_VAL)) return false;
    for (std::size_t k = from; k < to; ++k) {
      const double g = f0 ? f[k] - mu * (*f0)[k] : f[k];
      sq += g * g;
    }
    return std::sqrt(sq) >= (in_order ? stop : stop * (1.0 + 1e-12));
  };
  if (rejected(0, row)) return 0;
  // v = vmax on each cruise, v = 0 on each dwell (at the hold's start e[i]), in their rows after
  // the modes'.
  const std::size_t speed_row = row + 2 * pb.ms->n;
  std::size_t rows_end = speed_row;
  for (std::size_t i = 0; i < n; ++i) {
    const ArcKind kd = c.node[i].kind;
    if (kd != ArcKind::cruise && kd != ArcKind::dwell) continue;
    const double tc = L.e[i];
    double vc = 0.0;
    for (std::size_t r = 0; r <= i; ++r) {
      const double ub = tc - L.b[r], ue = tc - L.e[r], jr = L.j[r];
      vc += jr * (ub * ub - ue * ue) / 2.0;
    }
    f[rows_end++] = (vc - (kd == ArcKind::cruise ? pb.vmax : 0.0)) / pb.vmax;
  }
  if (speed_first && rows_end > speed_row) {
    in_order = false;
    if (rejected(speed_row, rows_end)) return 0;
  }
  // The transform at each pole, referred to the end and divided by D omega (the step's): sum_r
  // j_r (E(u_b) - E(u_e)) / s^2 with E(u) = e^{s u}.
  for (std::size_t m = 0; m < pb.ms->n; ++m) {
    const ArcPole& q = pb.poles[m];
    // The exponentials first, then the sums (the same operations: a loop without the calls
    // keeps its values in registers).
    std::array<CxSlot, kMaxArcNodes + 1> em1;  // not zeroed: the first n + 1 are written
    for (std::size_t r = 0; r <= n; ++r) {
      const double u = -(T - L.e[r]), d = L.e[r] - L.b[r];
      const Cx Ee = pb.exps->get(m, r, false, u, [&] { return cexp_neg(q.s, u); });
      ev.ee[m][r] = {Ee.re, Ee.im};
      const Cx x = pb.exps->get(m, r, true, d, [&] { return cexpm1(d * q.s); });
      em1[r] = {x.re, x.im};
    }
    Cx acc{};
    for (std::size_t r = 0; r <= n; ++r) {
      const double jr = L.j[r] * q.scale;
      const Cx Ee = ev.ee[m][r];
      // E(u_b) - E(u_e) = E(u_e) (e^{s d} - 1): no cancellation on short ramps.
      const Cx diff = Ee * Cx(em1[r]);
      const Cx Eb = Ee + diff;
      ev.eb[m][r] = {Eb.re, Eb.im};
      acc = acc + jr * diff;
    }
    ev.val[m] = acc * q.inv_s2;
    f[row++] = ev.val[m].re;
    f[row++] = ev.val[m].im;
    if (m + 1 < pb.ms->n && rejected(row - 2, row)) return 0;  // the other modes' rows not taken
  }
  return rows_end;
}

// The Jacobian at the point arc_values evaluated (ev).
void arc_jacobian(const ArcProblem& pb, const ArcChain& c, const ArcEval& ev, ArcMat& jac) noexcept {
  const ArcLayout& L = ev.L;
  const std::size_t n = c.n, ns = 2 * n + 2;  // switch times s_k: s_2r = b[r], s_2r+1 = e[r]
  // g[k][row] = d F_row / d s_k, every row's kept side by side, so that the suffix sums below run
  // over all rows at once (node by node: one test of the node's kind, and a loop over the rows
  // the compiler takes two at a time) rather than row by row, testing each node's kind per row
  // (the same sums, operation for operation; row by row they were 40 % of arc_jacobian's
  // instructions on a three-mode plan). Sized for the longest chain, but only the first ns switch
  // times and the rows made are written or read: zeroing the whole per row cost a one-mode plan
  // 8 % more instructions with the 47-segment table (23 nodes) than with 31 (15).
  std::array<std::array<double, kMaxArcNodes>, 2 * kMaxArcNodes + 2> g;
  std::size_t row = 0;
  const double T = L.T;
  // Each row writes every entry it sets from 0.0 (0.0 - x, 0.0 + x: the -= and += on a zeroed
  // row), and zeroes only those it does not set (a cruise's or dwell's row: the ramps after it).
  double gT = 0.0;  // d v / d T, summed over the ramps; ramp n's end is s_{ns-1} too
  for (std::size_t r = 0; r <= n; ++r) {
    const double ub = T - L.b[r], ue = T - L.e[r], jr = L.j[r];
    g[2 * r][row] = 0.0 - jr * ub;
    if (r < n) {
      g[2 * r + 1][row] = 0.0 + jr * ue;
    } else {
      gT += jr * ue;
    }
    gT += jr * (ub - ue);
  }
  g[ns - 1][row] = gT;
  for (std::size_t k = 0; k < ns; ++k) g[k][row] /= pb.vmax;
  ++row;
  if (!pb.pulse) {
    for (std::size_t r = 0; r <= n; ++r) {
      const double ub = T - L.b[r], ue = T - L.e[r], jr = L.j[r];
      g[2 * r][row] = 0.0 - jr * ub * ub / 2.0 / pb.D;
      g[2 * r + 1][row] = 0.0 + jr * ue * ue / 2.0 / pb.D;
    }
    g[ns - 1][row] += ev.v / pb.D;
    ++row;
  }
  // d/d b_r = -j_r E(u_b) / s, d/d e_r = j_r E(u_e) / s; d/dT of sum E(u): s times the sum.
  for (std::size_t m = 0; m < pb.ms->n; ++m) {
    const ArcPole& q = pb.poles[m];
    // Each switch time's term once (0.0 + as the sum from zero had it): the real parts in the
    // first row, the imaginary parts in the second. The products as Packed (numeric/complex.hpp:
    // the same products and sums as Cx's, lane by lane).
    const PackedFactor inv_s{q.inv_s};
    const Packed zero = pack(Cx{});
    for (std::size_t r = 0; r <= n; ++r) {
      const double jr = L.j[r] * q.scale;
      const Cx b = unpack(zero + splat(-jr) * (pack(ev.eb[m][r]) * inv_s));
      const Cx e = unpack(zero + splat(jr) * (pack(ev.ee[m][r]) * inv_s));
      g[2 * r][row] = b.re;
      g[2 * r + 1][row] = e.re;
      g[2 * r][row + 1] = b.im;
      g[2 * r + 1][row + 1] = e.im;
    }
    const Cx d_T = q.s * ev.val[m];
    g[ns - 1][row] += d_T.re;
    g[ns - 1][row + 1] += d_T.im;
    row += 2;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const ArcKind kd = c.node[i].kind;
    if (kd != ArcKind::cruise && kd != ArcKind::dwell) continue;
    const double tc = L.e[i];
    for (std::size_t r = 0; r <= i; ++r) {
      const double ub = tc - L.b[r], ue = tc - L.e[r], jr = L.j[r];
      g[2 * r][row] = 0.0 - jr * ub / pb.vmax;
      g[2 * r + 1][row] = 0.0 + jr * ue / pb.vmax;
    }
    for (std::size_t k = 2 * i + 2; k < ns; ++k) g[k][row] = 0.0;
    // d/d tc (= s_{2i+1}): the acceleration there, 0 by construction.
    ++row;
  }
  // d F / d x from g, as suffix sums suf_k = suf_{k+1} + g_k from suf_ns = 0, kept as they run
  // down and read at 2i + 3, 2i + 2 and 2i + 1 for node i (suf_0 is not read): hold i is the
  // length between s_{2i+1} and s_{2i+2}; a peak's level sets ramp i (before s_{2i+1}) and ramp
  // i+1 (before s_{2i+3}).
  const std::size_t rows = row;
  std::array<double, kMaxArcNodes> suf3;  // suf_{2i+3} per row
  for (std::size_t rw = 0; rw < rows; ++rw) suf3[rw] = 0.0 + g[ns - 1][rw];  // suf_{2n+1}
  for (std::size_t i = n; i-- > 0;) {
    const ArcNode& k = c.node[i];
    const std::array<double, kMaxArcNodes>&g2 = g[2 * i + 2], &g1 = g[2 * i + 1];
    if (k.kind == ArcKind::peak) {
      const double jk = ramp_in(k) * pb.J;
      for (std::size_t rw = 0; rw < rows; ++rw) {
        const double suf2 = suf3[rw] + g2[rw], suf1 = suf2 + g1[rw];
        jac[rw][i] = (suf1 + suf3[rw]) / jk;
        suf3[rw] = suf1;
      }
    } else {
      for (std::size_t rw = 0; rw < rows; ++rw) {
        const double suf2 = suf3[rw] + g2[rw];
        jac[rw][i] = suf2;
        suf3[rw] = suf2 + g1[rw];
      }
    }
  }
}

double arc_norm(const ArcVec& f, std::size_t n) noexcept {
  double s = 0.0;
  for (std::size_t i = 0; i < n; ++i) s += f[i] * f[i];
  return std::sqrt(s);
}

// How far rounding keeps |F| from 0 at c. The rows of v and p at the end (and v on each cruise
// or dwell) are sums of terms j (u_b^k - u_e^k) / k! that cancel to a small D: each is rounded to
// eps of the sum of the terms' sizes. And each switch time is a sum rounded to about eps T, which
// moves each row by its derivative with respect to it (a row's largest, per unit of time).
// From c's evaluation (ev, its `rows` rows) and the Jacobian there (jm): arc_newton holds them
// where its line search fails, so it pays for the Jacobian alone (grid case 2: 575 k instructions
// in the floor with the evaluation made again, session 35).
double arc_rounding_floor(const ArcProblem& pb, const ArcChain& c, const ArcEval& ev, const ArcMat& jm,
                          std::size_t rows) noexcept {
  const ArcLayout& L = ev.L;
  const double eps = std::numeric_limits<double>::epsilon();
  // v and p at the end, then v at each cruise or dwell (in arc_values' order of rows).
  const auto sizes = [&](double at, double& sv, double& sp) {
    sv = sp = 0.0;
    for (std::size_t r = 0; r <= c.n && L.b[r] < at; ++r) {
      const double ub = at - L.b[r], ue = std::fmax(0.0, at - L.e[r]), j = std::fabs(L.j[r]);
      sv += j * (ub * ub + ue * ue) / 2.0;
      sp += j * (ub * ub * ub + ue * ue * ue) / 6.0;
    }
  };
  double sv = 0.0, sp = 0.0, s = 0.0;
  sizes(L.T, sv, sp);
  std::array<double, kMaxArcNodes> ev_row{};
  std::size_t k = 0;
  ev_row[k++] = sv / pb.vmax;
  if (!pb.pulse) ev_row[k++] = sp / pb.D;
  k += 2 * pb.ms->n;
  for (std::size_t i = 0; i < c.n && k < rows; ++i) {
    if (c.node[i].kind != ArcKind::cruise && c.node[i].kind != ArcKind::dwell) continue;
    sizes(L.e[i], sv, sp);
    ev_row[k++] = sv / pb.vmax;
  }
  for (std::size_t r = 0; r < rows; ++r) {
    double m = 0.0;
    for (std::size_t i = 0; i < c.n; ++i) {
      // fmax's value (a NaN term is passed over) without its call: 8.8 k calls on grid case 2.
      const double a = std::fabs(jm[r][i]) * (c.node[i].kind == ArcKind::peak ? pb.J : 1.0);
      if (a > m) m = a;
    }
    const double e = eps * (L.T * m + ev_row[r]);
    s += e * e;
  }
  return std::sqrt(s);
}

// Below this norm a solve that stalls (a line search that cannot lower it) has solved its chain:
// a tenth of the rows' rounding, the whole of it for split_to_rounding's solves (pb.to_rounding).
// arc_newton's and arc_restore's rule (arc_newton, session 34).
double stall_floor(const ArcProblem& pb, const ArcChain& c, const ArcEval& ev, const ArcMat& jm,
                   std::size_t rows) noexcept {
  return (pb.to_rounding ? 1.0 : 0.1) * arc_rounding_floor(pb, c, ev, jm, rows);
}

// Newton's step J dx = -F by solve_in_place, its size a constant up to kChainNodes (every search
// but dwell_changes'): the same operations, every result the same bits, for a third fewer
// instructions (grid case 274, 7 unknowns: 289 k -> 187 k, 10 % -> 6 % of its plan; every --json of
// the 300 grid plans the same, session 34).
template <std::size_t... K>
bool arc_solve_sized(ArcMat& jm, ArcVec& dx, std::size_t rows, std::index_sequence<K...>) noexcept {
  bool ok = false;
  const bool fixed = ((rows == K + 1 ? (ok = solve_in_place_fixed<kMaxArcNodes, K + 1>(jm, dx), true) : false) || ...);
  return fixed ? ok : solve_in_place(jm, dx, rows);
}
bool arc_solve_step(ArcMat& jm, ArcVec& dx, std::size_t rows) noexcept {
  return arc_solve_sized(jm, dx, rows, std::make_index_sequence<kChainNodes>{});
}

// Newton's method with a backtracking line search on |F - mu F0| (each point's F and Jacobian
// taken together: the full step is nearly always taken): solves F(x) = mu F0, the chain's own
// equations when mu = 0. True when the norm falls below tol, or stalls within 1000 tol of it or
// below a tenth of the rows' rounding (arc_rounding_floor; the move is checked afterwards). The
// rounding's share: on grid case 110 a continuation's last step stalled at 5.2e-11 with glibc's
// exponentials and at 2.4e-10 with exponentials within 1 ulp of them (its rows round to 5.8e-9),
// so whether that path solved, and the plan (4.063 s or 4.739 s), hung on the exponentials'
// last bits; at a tenth of the rows' rounding it solves with both (session 34). The same rule in
// arc_restore: over the reference grid 4 plans shorter (47 by 5.5e-7, 59 by 3.4e-5, 99 by 1.3e-4,
// 110 by 6.0e-4), 59 and 99 now proven, none longer by 2e-9; at the whole rounding (not a tenth)
// grid case 86 at 7.3 times its units planned 1.5e-4 longer. A run whose norm fell by less than
// 1 % over its last 8 steps while above that is given up: such runs mostly creep on steps of
// about 2^-9 of Newton's until their iterations run out or the line search fails. Giving them up
// cut the reference grid's evaluations by 8 % and lengthened none of its plans (docs/fastest.md,
// "Cost", session 29; 7 steps at 2 % lengthened one). With `first_test` (a continuation's step on the
// way), a first step whose line search took 2^-9 of Newton's or less and gained under 1 % fails
// the run at once: the continuation's step is too long, and is cut. Over the reference grid
// 4 384 runs started so (5 % of its evaluations), 741 of them got through; failing them all cut
// the grid's evaluations by 5 % more and lengthened none of its plans.
//
// With `pause` (plan_arcs' probe, pause->allow), a run is set aside once pause->creeps of its steps
// have crept (a line search down to 2^-7 of Newton's step or less that gained under 5 %): it
// returns false with pause->paused and what its loop needs to go on (the iteration, the stall
// rule's norms, its evaluations), and a call with pause->resume takes the run up again from c
// where it stopped. The run so taken up is step for step the run it would have been, to the bit:
// its first evaluation is that of the point the set-aside step accepted (ArcExpMemo's values are
// the calls').
constexpr int kStallSteps = 8;
struct ArcPause {
  bool allow{false};   // the run may be set aside
  int creeps{1};       // after this many steps that crept
  bool paused{false};  // it was (c is where it stopped)
  bool resume{false};  // take it up again from it, before and evals
  int it{0}, evals{0};
  std::array<double, kStallSteps> before{};
};
bool arc_newton(const ArcProblem& pb, ArcChain& c, const ArcVec& f0, double mu, double tol, int max_iter,
                bool first_test = false, ArcPause* pause = nullptr) noexcept {
  std::array<double, kStallSteps> before{};  // the norm kStallSteps steps back, by it % kStallSteps
  int it0 = 0;
  if (pause != nullptr) {
    if (pause->resume) {
      before = pause->before;
      it0 = pause->it;
    }
    pause->paused = pause->resume = false;
  }
  ArcVec f{};
  ArcMat jm;  // arc_jacobian writes its rows x columns below c.n, all solve_in_place reads
  // c's evaluation (at) and the line search's trials' (tried), swapped where a trial is accepted:
  // where the line search fails, c's is at hand for the stall's floor.
  std::array<ArcEval, 2> evals_at;
  ArcEval* at = &evals_at[0];
  ArcEval* tried = &evals_at[1];
  const auto shifted_norm = [&](std::size_t rows) {
    for (std::size_t i = 0; i < rows; ++i) f[i] -= mu * f0[i];
    return arc_norm(f, rows);
  };
  const std::size_t rows = arc_values(pb, c, f, *at);
  if (rows != c.n) return false;  // not square: a chain the loop should not have made
  double n0 = shifted_norm(rows);
  int evals = it0 > 0 ? pause->evals : 1;  // of arc_values
  int creeps = 0;
  // The line search's point: its nodes and count are c's throughout (only the unknowns move), so
  // it is copied once, and an accepted step copies back the c.n unknowns alone (copying the whole
  // chain both ways per step was 0.5 % of a three-mode plan's instructions).
  ArcChain trial = c;
  const ArcShape shape = arc_shape(pb, c);
  for (int it = it0; it < max_iter; ++it) {
    if (!std::isfinite(n0)) return false;
    // A continuation's step on the way that has taken over 130 evaluations fails (its step is
    // cut). Over the reference grid's three-mode plans, 1 272 of the 26 365 steps of the solves
    // that failed took more (224 k of those steps' 0.91 M evaluations), 11 of the 3 850 steps that
    // succeeded in the solves that succeeded (their 99th percentile: 92). With the cap the grid's
    // evaluations fell by 3.0 % (three modes), 1.9 % (two) and 1.6 % (one), and no plan changed;
    // caps of 80 to 160 changed none, 70 lengthened three (by up to 0.08 %; session 31, an
    // instrumented build).
    if (first_test && evals > 130) return false;
    // The first step's rule for a continuation's step on the way (below: a line search down to
    // 2^-9 of Newton's that gains under 1 % fails the run) holds from its fourth Newton step on
    // too: such runs mostly creep until the stall rule, the cap or max_iter fails them all the
    // same, and most continuations on three modes fail. The three-mode benchmark request's
    // continuations took 5 062 evaluations instead of 6 960 (its instructions: 43.8 M instead of
    // 51.1 M) and no grid plan changed by 1e-9 (15 of their 300 --json outputs did in their last
    // digits). From the second or third Newton step on, or at 2^-8 from the fourth, it
    // lengthened grid case 254 by 1.1e-4 (session 33, an instrumented build).
    const bool cut_test = first_test && (it == 0 || it >= 3);
    if (n0 < tol) return true;
    const std::size_t slot = static_cast<std::size_t>(it % kStallSteps);
    if (it >= kStallSteps && n0 > 0.99 * before[slot] && n0 >= 1e3 * tol && !pb.to_rounding) return false;
    before[slot] = n0;
    // The Jacobian at c (at holds c's evaluation), only where a step is taken from it: not at
    // the point that meets the tolerance, nor at the last one.
    arc_jacobian(pb, c, *at, jm);
    ArcVec dx{};
    for (std::size_t i = 0; i < rows; ++i) dx[i] = -f[i];
    if (!arc_solve_step(jm, dx, rows)) return false;
    double lam = 1.0, n1 = HUGE_VAL;
    for (; lam > 1e-4; lam *= 0.5) {
      for (std::size_t i = 0; i < c.n; ++i) trial.x[i] = c.x[i] + lam * dx[i];
      // F alone (most trials are rejected), and not even that where v and p (or the speeds at
      // cruises and dwells) reject it; the speeds not first where the rule below fails the run
      // on this trial (a trial arc_values rejects does not reach that rule).
      ++evals;
      if (arc_values(pb, trial, f, *tried, n0, &f0, mu, !(cut_test && lam < 0.002), &shape) == 0) {
        n1 = HUGE_VAL;
        continue;
      }
      n1 = shifted_norm(rows);
      if (std::isfinite(n1) && n1 < n0) break;
      // A continuation's first step that halved below 2^-9 of Newton's fails unless that trial
      // gains 1 % (the rule below): a shorter step gains about its fraction of the norm at most,
      // so the halvings down to 1e-4 (five more evaluations) are not made. Over the reference
      // grid's 300 plans every plan is the same (to 1e-9) and the evaluations fall by 2.5 % on
      // three modes, 2.1 % on two, 0.8 % on one (session 31, an instrumented build).
      if (cut_test && lam < 0.002) return false;
    }
    if (!(lam > 1e-4)) {
      if (n0 < 1e3 * tol) return true;
      arc_jacobian(pb, c, *at, jm);  // the solve overwrote it
      return n0 < stall_floor(pb, c, *at, jm, rows);
    }
    if (cut_test && lam < 0.002 && n1 >= 0.99 * n0) return false;
    std::copy_n(trial.x.begin(), c.n, c.x.begin());
    std::swap(at, tried);
    creeps += lam < 0.01 && n1 >= 0.95 * n0 ? 1 : 0;
    n0 = n1;
    if (pause != nullptr && pause->allow && creeps >= pause->creeps && it + 1 < max_iter) {
      pause->paused = true;
      pause->it = it + 1;
      pause->evals = evals;
      pause->before = before;
      return false;
    }
  }
  return false;
}

// Solves the chain's equations from c. Newton's method first (arc_newton_only); when it fails (the
// start is too far from a solution), continuation from the start x0 (arc_continue): F(x) = (1 - lam) F(x0) holds at x0 for
// lam = 0, and lam is raised to 1 in steps that grow after each solve and shrink after a
// failure (to 1e-3 at least), solving loosely on the way and exactly at the end. The
// continuation gives up once a point on its way is a move longer than t_bound. From every
// limit/peak pattern and four starts on the commissioning case (docs/fastest.md, "Seeds"), 70 of
// 256 paths end in a feasible chain with it, 24 with Newton's method alone.
constexpr double kArcTol = 1e-13;
bool arc_newton_only(const ArcProblem& pb, ArcChain& c) noexcept {
  const ArcVec none{};
  return arc_newton(pb, c, none, 0.0, kArcTol, 40);
}
bool arc_continue(const ArcProblem& pb, ArcChain& c, double t_bound) noexcept;
bool arc_solve(const ArcProblem& pb, ArcChain& c, double t_bound = HUGE_VAL) noexcept {
  const ArcChain start = c;
  if (arc_newton_only(pb, c)) return true;
  c = start;
  return arc_continue(pb, c, t_bound);
}
bool arc_continue(const ArcProblem& pb, ArcChain& c, double t_bound) noexcept {
  constexpr double kTol = kArcTol, kLooseTol = 1e-6;
  ArcVec f0{};
  ArcEval at;
  if (arc_values(pb, c, f0, at) != c.n) return false;
  double lam = 0.0, step = 0.25;
  for (int k = 0; k < 40 && lam < 1.0; ++k) {
    const double next = std::fmin(1.0, lam + step);
    const bool last = next == 1.0;
    ArcChain trial = c;
    if (arc_newton(pb, trial, f0, 1.0 - next, last ? kTol : kLooseTol, last ? 40 : 20, !last)) {
      if (lay_out(pb, trial).T > t_bound) return false;
      c = trial;
      lam = next;
      step *= 1.5;
    } else if ((step *= 0.25) < 1e-3) {
      return false;
    }
  }
  return lam >= 1.0;
}

// What a solved chain breaks, first in the chain: the node to change and how. kind none: feasible.
struct ArcFix {
  enum Kind : std::uint8_t { none, to_peak, to_limit, drop, add_cruise, add_dwell, give_up } kind{none};
  std::size_t at{0};
};

// `margin` (relative) widens every tolerance: a chain broken with a margin is broken by more than
// a restoration's last steps at the rows' rounding move it (arc_restore's `t_abandon`). `laid`:
// c's layout where the caller has it (arc_restore's evaluation), not laid out again.
ArcFix arc_violation(const ArcProblem& pb, const ArcChain& c, double margin = 0.0,
                     const ArcLayout* laid = nullptr) noexcept {
  constexpr double kEps = 1e-12;
  const double a_lim = margin > 0.0 ? pb.amax * (1.0 + margin) : pb.amax;
  const double t_eps = margin > 0.0 ? kEps + margin * (laid != nullptr ? laid->T : lay_out(pb, c).T) : kEps;
  for (std::size_t i = 0; i < c.n; ++i) {
    const ArcNode& k = c.node[i];
    if (k.kind == ArcKind::peak) {
      // A turn may lie on either side of a = 0 (a maximum of a below zero is a bang-bang move
      // too: refusing it lost moves up to 19 % shorter, docs/fastest.md); beyond the other
      // limit it cannot.
      if (k.sign * c.x[i] > a_lim) return {ArcFix::to_limit, i};
      if (k.sign * c.x[i] < -a_lim) return {ArcFix::give_up, i};
    } else if (c.x[i] < -t_eps) {
      return {k.kind == ArcKind::limit ? ArcFix::to_peak : ArcFix::drop, i};
    }
  }
  ArcLayout own;
  const ArcLayout& L = laid != nullptr ? *laid : (own = lay_out(pb, c));
  double a = 0.0, v = 0.0;
  for (std::size_t r = 0; r <= c.n; ++r) {
    const double d = L.e[r] - L.b[r], j = L.j[r];
    if (d < -t_eps) return {ArcFix::give_up, r};
    const double a1 = a + j * d;
    if (a * a1 < 0.0) {  // a crosses zero inside the ramp: v has its extreme there
      const double tc = -a / j;
      const double vc = v + a * tc + 0.5 * j * tc * tc;
      if (vc > pb.vmax * (1.0 + 1e-9 + margin)) return {ArcFix::add_cruise, r};
      if (vc < -(1e-9 + margin) * pb.vmax) return {ArcFix::add_dwell, r};
    }
    v += a * d + 0.5 * j * d * d;
    a = a1;
    if (r < c.n) v += a * (L.b[r + 1] - L.e[r]);  // the hold
  }
  return {};
}

bool apply_fix(const ArcProblem& pb, const ArcFix& fx, ArcChain& c) noexcept {
  // A pulse that overshoots vmax or dips below 0 is not one of the mirrored moves: no cruise or
  // dwell inside it.
  if (pb.pulse && (fx.kind == ArcFix::add_cruise || fx.kind == ArcFix::add_dwell)) return false;
  switch (fx.kind) {
    case ArcFix::to_peak:
      c.node[fx.at].kind = ArcKind::peak;
      c.x[fx.at] = 0.9 * c.node[fx.at].sign * pb.amax;
      return true;
    case ArcFix::to_limit:
      c.node[fx.at].kind = ArcKind::limit;
      c.x[fx.at] = 0.0;
      return true;
    case ArcFix::drop:
      for (std::size_t i = fx.at; i + 1 < c.n; ++i) {
        c.node[i] = c.node[i + 1];
        c.x[i] = c.x[i + 1];
      }
      --c.n;
      return c.n > 0;
    case ArcFix::add_cruise:
    case ArcFix::add_dwell:
      if (c.n >= pb.max_nodes) return false;
      for (std::size_t i = c.n; i > fx.at; --i) {
        c.node[i] = c.node[i - 1];
        c.x[i] = c.x[i - 1];
      }
      c.node[fx.at] = {fx.kind == ArcFix::add_cruise ? ArcKind::cruise : ArcKind::dwell, 1.0};
      c.x[fx.at] = 0.0;
      ++c.n;
      return true;
    default:
      return false;
  }
}

// The chain as a table (the sign of `distance` applied); a pulse as g, the cruise, g mirrored.
// Empty when it does not fit, or a pulse is longer than the move leaves it (D / vmax).
FastestTable arc_table(const ArcProblem& pb, const ArcChain& c, double distance) noexcept {
  const ArcLayout L = lay_out(pb, c);
  const double sg = distance < 0.0 ? -1.0 : 1.0;
  const double cruise = pb.D / pb.vmax - L.T;
  if (pb.pulse && !(cruise >= 0.0)) return FastestTable{};
  FastestTable t{};
  t.distance = distance;
  for (const double side : {1.0, -1.0}) {
    for (std::size_t r = 0; r <= c.n; ++r) {
      const double hold = r < c.n ? L.b[r + 1] - L.e[r] : 0.0;
      if (!push_segment(t, L.e[r] - L.b[r], side * sg * L.j[r]) || (r < c.n && !push_segment(t, hold, 0.0))) {
        return FastestTable{};
      }
    }
    if (!pb.pulse) break;
    if (side > 0.0 && !push_segment(t, cruise, 0.0)) return FastestTable{};
  }
  return t;
}

// Seed chains: the kind of each node (signs alternate, + first; peaks start at half of amax)
// and the hold of each limit node, in units of the slowest mode's half period over the number
// of nodes. Chosen on the tests' grids and 60 random two-mode cases against trying every
// limit/peak pattern from four starts each (docs/fastest.md, "Seeds").
enum class SeedShape : std::uint8_t { limits, peaks, last_peak, inner_peaks, even_peaks };
struct ArcSeed {
  SeedShape shape;
  double hold;
};
constexpr std::array<ArcSeed, 5> kWholeSeeds{{{SeedShape::limits, 0.1},
                                              {SeedShape::limits, 1.0},
                                              {SeedShape::peaks, 0.0},
                                              {SeedShape::last_peak, 0.1},
                                              {SeedShape::inner_peaks, 0.1}}};
constexpr std::array<ArcSeed, 4> kPulseSeeds{
    {{SeedShape::limits, 0.1}, {SeedShape::limits, 1.0}, {SeedShape::peaks, 0.0}, {SeedShape::even_peaks, 0.1}}};

ArcChain seed_chain(const ArcSeed& sd, std::size_t n0, double unit_hold, double amax) noexcept {
  ArcChain c{};
  c.n = n0;
  for (std::size_t i = 0; i < n0; ++i) {
    const double sign = i % 2 == 0 ? 1.0 : -1.0;
    const bool peak = sd.shape == SeedShape::peaks || (sd.shape == SeedShape::last_peak && i + 1 == n0) ||
                      (sd.shape == SeedShape::inner_peaks && i > 0 && i + 1 < n0) ||
                      (sd.shape == SeedShape::even_peaks && i % 2 == 0);
    c.node[i] = {peak ? ArcKind::peak : ArcKind::limit, sign};
    c.x[i] = peak ? 0.5 * sign * amax : sd.hold * unit_hold;
  }
  return c;
}

// The rigid time-optimal move of distance d under the limits as chain nodes, appended to c: a
// turn + (a peak at a_p, or a limit holding h), a cruise where it reaches vmax, a turn -.
// Returns the move's duration; 0 when c has no room.
double push_rigid_move(const ArcProblem& pb, double d, ArcChain& c) noexcept {
  // Without vmax: jerk only while (d J^2 / 2)^(1/3) <= amax, else holds h at +-amax; where the
  // peak velocity a_p (a_p / J + h) passes vmax, the phases that reach vmax and a cruise.
  double a_p = std::fmin(std::cbrt(0.5 * d * pb.J * pb.J), pb.amax);
  double h = 0.0;
  if (a_p >= pb.amax) {
    const double t1 = pb.amax / pb.J;
    h = 0.5 * (-3.0 * t1 + std::sqrt(t1 * t1 + 4.0 * d / pb.amax));
  }
  double v_p = a_p * (a_p / pb.J + h), cruise = 0.0;
  if (v_p > pb.vmax) {
    a_p = std::fmin(pb.amax, std::sqrt(pb.vmax * pb.J));
    h = pb.vmax / a_p - a_p / pb.J;
    v_p = pb.vmax;
    cruise = d / pb.vmax - (2.0 * a_p / pb.J + h);
  }
  if (c.n + (cruise > 0.0 ? 3 : 2) > pb.max_nodes) return 0.0;
  const bool limit = a_p >= pb.amax;
  c.node[c.n] = {limit ? ArcKind::limit : ArcKind::peak, 1.0};
  c.x[c.n++] = limit ? h : a_p;
  if (cruise > 0.0) {
    c.node[c.n] = {ArcKind::cruise, 1.0};
    c.x[c.n++] = cruise;
  }
  c.node[c.n] = {limit ? ArcKind::limit : ArcKind::peak, -1.0};
  c.x[c.n++] = limit ? h : -a_p;
  return 2.0 * (2.0 * a_p / pb.J + h) + cruise;
}

// A chain that splits the move as a shaper with positive impulses splits a step: one rigid
// time-optimal sub-move per impulse (its share of D), each centred on its impulse's time, the
// axis at rest (a dwell) between them. With m modes and m + 1 impulses (ZV, joint ZV) it has
// 2 + 2m turn nodes and m dwells: square. Short moves on slow modes take this form (the
// reference's moves dwell at v = 0 for most of a half period between two pulses), which the
// seeds above, whose holds are short, do not reach.
bool split_chain(const ArcProblem& pb, const Shaper<double>& s, ArcChain& c) noexcept {
  if (s.count < 2) return false;
  c = ArcChain{};
  double prev_half = 0.0;
  for (std::size_t i = 0; i < s.count; ++i) {
    if (!(s.amp[i] > 0.0)) return false;
    const std::size_t at = c.n;
    if (i > 0) {
      if (c.n >= pb.max_nodes) return false;
      c.node[c.n] = {ArcKind::dwell, 1.0};
      c.x[c.n++] = 0.0;
    }
    const double half = 0.5 * push_rigid_move(pb, s.amp[i] * pb.D, c);
    if (!(half > 0.0)) return false;
    if (i > 0) c.x[at] = std::fmax(0.0, s.time[i] - s.time[i - 1] - prev_half - half);
    prev_half = half;
  }
  return true;
}

// The shaper whose impulses split_chain follows: ZV for one mode, the joint ZV for more.
bool split_shaper(const ModeSet& ms, Shaper<double>& s) noexcept {
  if (ms.n == 1) return design_shaper(ShaperKind::zv, ms.m[0].omega, ms.m[0].zeta, 0.05, s) == Status::ok;
  if (ms.n > kMaxJointModes) return false;
  std::array<double, kMaxJointModes> w{}, z{};
  for (std::size_t i = 0; i < ms.n; ++i) {
    w[i] = ms.m[i].omega;
    z[i] = ms.m[i].zeta;
  }
  return joint_zv_shaper(w.data(), z.data(), ms.n, s) == Status::ok;
}

// The solved chains met so far: a seed whose path reaches one of them would only repeat the
// path taken from there (the active-set loop is deterministic), so it stops.
class ChainMemo {
 public:
  // True when c (same kinds, values within 1e-7) was met before; otherwise remembers it.
  bool seen(const ArcChain& c, double amax) noexcept {
    for (std::size_t k = 0; k < count_; ++k) {
      if (same(chains_[k].c, c, amax)) return true;
    }
    if (count_ < chains_.size()) chains_[count_++].c = c;
    return false;
  }

 private:
  static bool same(const ArcChain& a, const ArcChain& b, double amax) noexcept {
    if (a.n != b.n) return false;
    for (std::size_t i = 0; i < a.n; ++i) {
      const double scale = std::fabs(b.x[i]) + (b.node[i].kind == ArcKind::peak ? amax : 1e-3);
      if (a.node[i].kind != b.node[i].kind || a.node[i].sign != b.node[i].sign ||
          std::fabs(a.x[i] - b.x[i]) > 1e-7 * scale) {
        return false;
      }
    }
    return true;
  }
  // Left unset until remembered (ArcChain's copy is trivial, so the assignment makes it the
  // slot's member): zeroing 24 chains of 23 nodes, 13 KB, cost a one-mode plan 1.4 % of its
  // instructions, per seed path.
  union Slot {
    Slot() noexcept {}
    ArcChain c;
  };
  std::array<Slot, 24> chains_;
  std::size_t count_{0};
};

// c with a pair of peaks inserted into its ramp into node k (k == c.n: the closing ramp): the
// ramp doubles back over 2 frac of its rise about the level `at` of the way along it (its middle
// unless said), a turn of the ramp's sign then one
// of the other, so that the signs still alternate. It seeds a chain for one mode more (the new
// mode's two conditions, the wiggle's two levels); a turn at or beyond a limit is a limit node
// (hold 0). False when it does not fit or the ramp is flat.
bool insert_wiggle(const ArcProblem& pb, const ArcChain& c, std::size_t k, double frac, ArcChain& out,
                   double at = 0.5) noexcept {
  if (c.n == 0 || c.n + 2 > pb.max_nodes || k > c.n) return false;
  const double a_prev = k == 0 ? 0.0 : node_level(pb, c, k - 1);
  const double a_next = k == c.n ? 0.0 : node_level(pb, c, k);
  const double s = k == c.n ? ramp_out(c.node[c.n - 1]) : ramp_in(c.node[k]);
  const double rise = a_next - a_prev;
  if (!(s * rise > 0.0)) return false;
  const double mid = a_prev + at * rise, half = frac * std::fabs(rise);
  out = ArcChain{};
  out.n = c.n + 2;
  for (std::size_t i = 0, o = 0; i <= c.n; ++i) {
    if (i == k) {
      // A turn at or beyond a limit is a hold there (a wiggle from limit to limit).
      for (const double side : {s, -s}) {
        const double lev = mid + side * half;
        const bool at_limit = std::fabs(lev) >= pb.amax;
        out.node[o] = {at_limit ? ArcKind::limit : ArcKind::peak, side};
        out.x[o++] = at_limit ? 0.0 : lev;
      }
    }
    if (i < c.n) {
      out.node[o] = c.node[i];
      out.x[o++] = c.x[i];
    }
  }
  return true;
}

// c with its nodes k .. k + span - 1 (node k alone unless said) replaced by the m nodes `with`
// (values `x`); false when they are not all in c or the result does not fit.
bool splice(const ArcChain& c, std::size_t k, const ArcNode* with, const double* x, std::size_t m, std::size_t cap,
            ArcChain& out, std::size_t span = 1) noexcept {
  if (span == 0 || k + span > c.n || c.n - span + m > cap) return false;
  out = ArcChain{};
  out.n = c.n - span + m;
  std::size_t o = 0;
  for (std::size_t i = 0; i < k; ++i, ++o) {
    out.node[o] = c.node[i];
    out.x[o] = c.x[i];
  }
  for (std::size_t j = 0; j < m; ++j, ++o) {
    out.node[o] = with[j];
    out.x[o] = x[j];
  }
  for (std::size_t i = k + span; i < c.n; ++i, ++o) {
    out.node[o] = c.node[i];
    out.x[o] = c.x[i];
  }
  return true;
}

// c with its hold at limit node k split in two by a dip: the acceleration turns from the limit
// to `level` and back, a peak between two holds of half the length each.
bool insert_dip(const ArcProblem& pb, const ArcChain& c, std::size_t k, double level, ArcChain& out) noexcept {
  if (k >= c.n || c.node[k].kind != ArcKind::limit) return false;
  const ArcNode lim = c.node[k];
  const std::array<ArcNode, 3> with{lim, ArcNode{ArcKind::peak, -lim.sign}, lim};
  const std::array<double, 3> x{0.5 * c.x[k], lim.sign * level * pb.amax, 0.5 * c.x[k]};
  return splice(c, k, with.data(), x.data(), with.size(), pb.max_nodes, out);
}

// c with a stop inserted into its cruise at node k, `at` of the way along it (its middle unless
// said): the cruise up to there, the rigid stop from vmax (a turn to -amax or a limit hold there),
// a dwell of `dwell`, the rigid start back to vmax, the rest of the cruise. Four nodes more: two
// turns, a dwell, a cruise.
bool insert_stop(const ArcProblem& pb, const ArcChain& c, std::size_t k, double dwell, ArcChain& out,
                 double at = 0.5) noexcept {
  if (k >= c.n || c.node[k].kind != ArcKind::cruise) return false;
  const double a_p = std::fmin(pb.amax, std::sqrt(pb.vmax * pb.J));
  const bool limit = a_p >= pb.amax;
  const ArcKind turn = limit ? ArcKind::limit : ArcKind::peak;
  const double h = limit ? pb.vmax / pb.amax - pb.amax / pb.J : 0.0;
  const std::array<ArcNode, 5> with{c.node[k], ArcNode{turn, -1.0}, ArcNode{ArcKind::dwell, 1.0}, ArcNode{turn, 1.0},
                                    c.node[k]};
  const std::array<double, 5> x{at * c.x[k], limit ? h : -a_p, dwell, limit ? h : a_p, (1.0 - at) * c.x[k]};
  return splice(c, k, with.data(), x.data(), with.size(), pb.max_nodes, out);
}

// c with a slow-down inserted in the middle of its cruise at node k: the cruise halved, a turn
// down and one up (holds at -amax and +amax of `hold`, or peaks), the other half. Three nodes more:
// two turns and a cruise.
bool insert_slowdown(const ArcProblem& pb, const ArcChain& c, std::size_t k, double frac, ArcChain& out) noexcept {
  if (k >= c.n || c.node[k].kind != ArcKind::cruise) return false;
  const double a_p = std::fmin(pb.amax, std::sqrt(frac * pb.vmax * pb.J));
  const bool limit = a_p >= pb.amax;
  const ArcKind turn = limit ? ArcKind::limit : ArcKind::peak;
  const double h = limit ? frac * pb.vmax / pb.amax - pb.amax / pb.J : 0.0;
  const std::array<ArcNode, 4> with{c.node[k], ArcNode{turn, -1.0}, ArcNode{turn, 1.0}, c.node[k]};
  const std::array<double, 4> x{0.5 * c.x[k], limit ? h : -a_p, limit ? h : a_p, 0.5 * c.x[k]};
  return splice(c, k, with.data(), x.data(), with.size(), pb.max_nodes, out);
}

// c (a move to rest) followed by a dwell of `dwell` and a short restart: a turn to a peak at
// amax / 2 and one back to -amax / 2, a fourth pulse that cancels the ringing c leaves. The
// reference's move on grid case 222 (one mode, a 12 s cruise) has this shape: the cruise, a stop,
// a 25 ms dwell and a short accelerate-decelerate to the target; insert_stop's stop in the middle
// of the cruise does not solve there (its Newton steps run the cruise halves to -172 s and
// +185 s). Three nodes more: a dwell and two peaks.
bool append_restart(const ArcProblem& pb, const ArcChain& c, double dwell, ArcChain& out) noexcept {
  if (c.n + 3 > pb.max_nodes) return false;
  out = c;
  out.node[out.n] = ArcNode{ArcKind::dwell, 1.0};
  out.x[out.n++] = dwell;
  out.node[out.n] = ArcNode{ArcKind::peak, 1.0};
  out.x[out.n++] = 0.5 * pb.amax;
  out.node[out.n] = ArcNode{ArcKind::peak, -1.0};
  out.x[out.n++] = -0.5 * pb.amax;
  return true;
}

// The shortest bang-bang chain found, with its form: what plan_arcs hands to the problem with one
// mode more.
constexpr std::size_t kLateStages = 4;
// The levels the slow-downs (stage 3) seed, in vmax: half first (alone it found 4 moves shorter
// on the grids), then a tenth, a quarter and three quarters (18 more; each found some the others
// did not).
constexpr std::array<double, 4> kSlowTo{0.5, 0.1, 0.25, 0.75};
struct ArcBest {
  ArcChain c{};
  bool pulse{false};
  bool have{false};
  // The shortest from each later stage of seeds (plan_arcs' last stage: the dips, the rigid
  // move's wiggles, the stops), where shorter than everything before it (whole form).
  std::array<ArcChain, kLateStages> late{};
  std::array<bool, kLateStages> late_have{};
  // c is proven the shortest move of its problem (certify_fastest) and the search stopped there:
  // late is then not searched (a later stage could only find a move as short, to the proof's
  // rounding).
  bool proven{false};
  // proven by a probe (plan_arcs' first pass): the move one pass would find, to the proof's
  // rounding, but not its bits. Where not set, c and late are one pass's to the bit (a probe
  // that proves nothing changes nothing).
  bool probed{false};
};

// The shortest bang-bang move found from the seeds above. Each seed's chain is solved and
// changed where it breaks a condition, up to 16 rounds; a path stops when it reaches a chain
// met before, or a solved chain longer than the shortest move so far (on the grids above
// neither stop lost a move; the second cuts the two-mode benchmark from about 600 to 170 us).
// With several modes, the shortest chain for all but the fastest mode (planned the same way,
// recursively) seeds more paths: that chain with a wiggle inserted into each of its ramps, for the
// fastest mode's two conditions (docs/fastest.md, "Seeds"). False when none is feasible.
// With dips, the late stages (dips, the rigid move's wiggles, stops, slow-downs) run last, after
// every other seed of both forms: out (and best_chain's c) is then the shortest move before them,
// dips->t the shortest from them where shorter (best_chain's late, each stage's own). plan_fewer
// and the top level pass it.
// With stop_proven, each new shortest move is checked by certify_fastest (the proof by LP duality
// that no move of the problem is shorter, docs/fastest.md "A certificate of the shortest move"),
// and the search stops at the first proven one: every later path could only find a move shorter by
// the proof's rounding (on the reference grid's 300 plans none differs by more than 1e-9 of its
// duration). The chain for one mode fewer is planned only when a path needs it, with the same stop:
// a proven one hands up no late chains. (It was planned again in full for them until session 32: over
// the grid 70 of those 74 searches found no late chain and the other 4 one as short to 1e-9, for 7 %
// of the grid's evaluations.)
struct DipBest {
  FastestTable t{};
  Peaks<double> pk{};
  bool have{false};
};

// The last kSlots certificates (certify_fastest) made for one problem, each with its table's
// segments to the bit (all the proof reads of the table): a table certified again reads its
// certificate here. Over the grid's 300 plans 115 of 945 certificates were of a table certified
// before (a throw-away counting build): plan_arcs' second pass reaching a chain whose proof its
// probe had failed (57), KeptUntilProven::violation at a refinement's starting chain that
// plan_arcs (51) or FastestSearch::record (6) had certified, record itself (1); each was within
// the last 10 certificates made, most within the last 2. A certificate costs about 150 k
// instructions.
class CertMemo {
 public:
  CertMemo() noexcept {}  // the slots are not zeroed: those below used_ alone are read, each written first
  FastestCertificate operator()(const FastestTable& t, const MoveRequest& r) noexcept {
    for (std::size_t i = 0; i < used_; ++i) {
      if (same(slot_[i], t)) return slot_[i].ce;
    }
    Slot& s = slot_[next_];
    next_ = (next_ + 1) % kSlots;
    used_ = std::max(used_, next_ == 0 ? kSlots : next_);
    s.ce = certify_fastest(t, r);
    s.count = t.count;
    std::copy_n(t.durations.begin(), t.count, s.durations.begin());
    std::copy_n(t.jerk.begin(), t.count, s.jerk.begin());
    return s.ce;
  }

 private:
  static constexpr std::size_t kSlots = 8;
  struct Slot {  // [0, count) written and read
    FastestCertificate ce;
    std::size_t count;
    std::array<double, kFastestSegments> durations, jerk;
  };
  static bool same(const Slot& s, const FastestTable& t) noexcept {
    if (s.count != t.count) return false;
    for (std::size_t k = 0; k < t.count; ++k) {
      if (std::bit_cast<std::uint64_t>(s.durations[k]) != std::bit_cast<std::uint64_t>(t.durations[k]) ||
          std::bit_cast<std::uint64_t>(s.jerk[k]) != std::bit_cast<std::uint64_t>(t.jerk[k])) {
        return false;
      }
    }
    return true;
  }
  std::array<Slot, kSlots> slot_;
  std::size_t used_{0}, next_{0};
};

// The probe's Newton runs set aside where they creep (arc_newton's pause), each with its path's
// place (plan_arcs, `probing`), in the order they were set aside. Held by the request's
// bang_bang_family (the recursion for one mode fewer has no probe, and its frames stay as they
// were).
struct ArcSetAside {
  ArcChain c;
  ArcPause pause;
  int round;
  std::size_t group, id;
};
struct ArcProbeRoom {
  std::array<ArcSetAside, 24> path;  // not zeroed: the first count are written, then read
  std::size_t count{0};
  ArcProbeRoom() noexcept {}
};

// How plan_arcs searches.
struct ArcSearch {
  // The request's own chains (plan_unsigned's), not the recursion's for one mode fewer: the seed
  // paths that never paid there are left out (plan_arcs' lean and three_top).
  bool request{false};
  // Each new shortest move is checked by certify_fastest, and the search stops at a proven one.
  bool stop_proven{false};
  // With stop_proven, each group of paths is probed before its second pass (plan_arcs,
  // `probing`): the request's search, and the quick chain for one mode fewer it plans first.
  bool probe{false};
};

// certs: the memo of the request's own problem (plan_unsigned's), used where ms holds r's modes
// (the proof's problem is then r's). Without it each proof is made (the recursion for one mode
// fewer: its certificates are of ever shorter tables, none certified twice).
bool plan_arcs(const MoveRequest& r, const ModeSet& ms, FastestTable& out, Peaks<double>& out_pk,
               ArcBest* best_chain = nullptr, const Shaper<double>* split = nullptr,
               DipBest* dips = nullptr, ArcSearch how = {}, CertMemo* certs = nullptr,
               ArcProbeRoom* aside = nullptr) noexcept;

// The shortest chain for all modes but the fastest (planned by plan_arcs, recursively, with that
// set's own split seed): the chain plan_arcs inserts its wiggles into. With probe, its search is
// probed first (its own room for the runs set aside: 24 chains on the stack, host and AArch64
// only, as all of `fastest`), and where the probe proves nothing the chain is the one pass's to
// the bit (ArcBest::probed).
ArcBest plan_fewer(const MoveRequest& r, const ModeSet& ms, bool stop_proven, bool probe = false) noexcept {
  ModeSet fewer{};
  std::size_t fastest = 0;
  for (std::size_t i = 1; i < ms.n; ++i) {
    if (ms.m[i].omega > ms.m[fastest].omega) fastest = i;
  }
  for (std::size_t i = 0; i < ms.n; ++i) {
    if (i != fastest) fewer.m[fewer.n++] = ms.m[i];
  }
  ArcBest sub{};
  FastestTable t{};
  Peaks<double> pk{};
  Shaper<double> fewer_split{};
  DipBest dips{};
  ArcProbeRoom aside;
  (void)plan_arcs(r, fewer, t, pk, &sub, split_shaper(fewer, fewer_split) ? &fewer_split : nullptr, &dips,
                  {.request = false, .stop_proven = stop_proven, .probe = probe}, nullptr, probe ? &aside : nullptr);
  return sub;
}

bool plan_arcs(const MoveRequest& r, const ModeSet& ms, FastestTable& out, Peaks<double>& out_pk, ArcBest* best_chain,
               const Shaper<double>* split, DipBest* dip_out, ArcSearch how, CertMemo* certs,
               ArcProbeRoom* aside) noexcept {
  const bool request = how.request, stop_proven = how.stop_proven;
  // A two-mode request's own chains (`request`: not the recursion's for one mode fewer, whose
  // chains three modes build on) skip three seed paths that never paid there: the dips, the
  // stops in a cruise and the wide wiggles in the mirrored pulse. Over the 100 two-mode cases of
  // the reference grid and the 537 two-mode plans of the Fastest tests none of them gave a
  // shorter move, and without them every one of those plans is the same to 1e-12 (session 27,
  // docs/fastest.md "Cost"); they were 2.8 % of those plans' evaluations.
  const bool lean = request && ms.n == 2;
  // A three-mode request's chains skip the seed paths that never paid there either: its own
  // last-peak and inner-peak seeds and the peaks at half the rigid level (the whole chain), and,
  // for it and for its chain for one mode fewer, the mirrored pulse's own seeds (the pulse's
  // wiggles stay: each gave a shorter move on a grid case). Over the 100 three-mode cases of the
  // reference grid none of these paths gave a shorter move at its level, and without them every
  // one of those plans is the same to 1e-9; they were 5.6 % of those plans' evaluations
  // (session 31, an instrumented build). Three modes only: the grid holds no request of four, so
  // one of four keeps every seed path.
  const bool three_top = request && ms.n == 3, three_pulse = r.mode_count == 3 && ms.n >= 2;
  ArcProblem pb = arc_problem(r, ms);
  ArcExpMemo exps(ms.n);
  pb.exps = &exps;
  double w_min = ms.m[0].omega;
  for (std::size_t i = 1; i < ms.n; ++i) w_min = std::fmin(w_min, ms.m[i].omega);
  // The chain for one mode fewer, planned where a path first needs it.
  ArcBest sub_store{};
  const ArcBest& sub = sub_store;
  bool sub_done = ms.n < 2;
  const auto need_sub = [&] {
    if (!sub_done) sub_store = plan_fewer(r, ms, stop_proven);
    sub_done = true;
  };
  // This set's problem, for the proof.
  MoveRequest problem = r;
  problem.mode_count = 0;
  for (std::size_t i = 0; i < ms.n; ++i) problem.modes[problem.mode_count++] = ms.m[i];
  bool r_modes = r.mode_count == ms.n;
  for (std::size_t i = 0; i < ms.n && r_modes; ++i) {
    r_modes = std::bit_cast<std::uint64_t>(r.modes[i].omega) == std::bit_cast<std::uint64_t>(ms.m[i].omega) &&
              std::bit_cast<std::uint64_t>(r.modes[i].zeta) == std::bit_cast<std::uint64_t>(ms.m[i].zeta);
  }
  const auto certify = [&](const FastestTable& t) {
    return certs != nullptr && r_modes ? (*certs)(t, problem) : certify_fastest(t, problem);
  };
  bool proven = false, probed = false;
  // The quick chain for one mode fewer (a probed recursion, below), where its probe proved it.
  ArcBest quick{};
  double sub_fast_wd = 0.0;  // the damped frequency of the mode plan_fewer left out (the fastest)
  for (std::size_t i = 0, f = 0; i < ms.n; ++i) {
    if (ms.m[i].omega > ms.m[f].omega) f = i;
    if (i + 1 == ms.n) sub_fast_wd = ms.m[f].omega * std::sqrt(1.0 - ms.m[f].zeta * ms.m[f].zeta);
  }
  bool have = false, best_cruises = false;
  double best = HUGE_VAL;
  ChainMemo memo;  // not memo{}: that zeroes its slots
  for (const int stage : {0, 1, 2}) {  // the whole chain, the mirrored pulse, the dips (whole)
    const bool pulse = stage == 1, dips = stage == 2;
    if (proven) break;
    // The mirrored pulse is for moves that cruise: tried when the whole chain found none, or its
    // shortest cruises at vmax (on the tests' grids it found nothing shorter otherwise). A pulse
    // reaching vmax lasts at least the time-optimal one, vmax/amax + amax/jmax: when the move
    // leaves less (D / vmax), no mirrored move fits.
    if (pulse && ((have && !best_cruises) || pb.D / pb.vmax < pb.vmax / pb.amax + pb.amax / pb.J)) continue;
    if (dips && dip_out == nullptr) break;
    pb.pulse = pulse;
    const std::size_t n0 = (pulse ? 1 : 2) + 2 * ms.n;
    if (n0 > pb.max_nodes) continue;
    const double unit_hold = 0.5 * two_pi_v<double>() / (w_min * static_cast<double>(n0));  // half period
    bool best_holds_amax = false;  // of this form's shortest
    // The seeds' group and the wiggles' group of paths, each in two passes where the search stops at
    // a proof for the request's own chains (`probing`). The first pass (a probe) walks each path
    // while Newton's method alone solves its chain, and keeps a move only where it is proven the
    // shortest; it changes nothing else (no bound, no memo), so that where it proves nothing the
    // second pass walks the group as one pass would, less the Newton runs the probe saw fail (the
    // same runs: arc_solve tries Newton's method first). A proven move found late in a group, by a
    // path Newton's method solves, is so reached before the group's failing continuations: the
    // three-mode request's own wiggles cost 3 766 evaluations before its proof, 859 with the probe.
    // Both groups are probed before either's second pass (the wiggles need only the chain for one
    // mode fewer, not the seeds' moves), and the probe walks the split seed first: over the
    // reference grid the probes so prove 182 of the 300 plans (174 in the groups' order, seeds
    // then wiggles, split last), 130 of them from the split seed (78), and plan_arcs' median of
    // evaluations per plan fell from 464, 2 296 and 4 493 to 36, 1 080 and 4 074 for one, two and
    // three modes (session 33, an instrumented build; every plan the same to 1e-9). Not in the
    // recursion for one mode fewer in its place: there a proof reached by another path is the same
    // move but not the same bits, and the search built on it lands elsewhere (with the probe there
    // too, grid case 5 at 1e-3 and 7.3 of its scale planned 0.5 % and 0.4 % longer; with it in
    // session 33's order grid case 134 0.9 % and 227 0.17 % longer). It is probed beside the one
    // pass's instead (quick_wiggles, below).
    // The probe sets aside each Newton run that creeps (arc_newton's pause: in the seeds' group
    // after three steps whose line search went down to 2^-7 of Newton's and gained under 5 %, in
    // the wiggles' group after one) and walks on; the split seed's is taken up again before the
    // chain for one mode fewer is planned, the others after the wiggles, in their order, each run
    // to its end as it would have been. Most runs that creep fail, and a proof by a path that
    // converges comes before them: on the reference grid's two-mode cases the median of
    // plan_fastest's instructions fell from 2.92 M to 2.13 M (cases 274 2.95 -> 1.80 M, 145 2.77
    // -> 1.56 M; session 34, cggrid.py, with arc_solve_step). A run set aside is one the probe had
    // not finished, so where a later path proves, a run set aside before it that would have proven
    // is not reached: that plan is another proven move, the same to the proof's rounding (7 of the
    // 300 grid plans differ, by 2.6e-14 to 1.3e-10 s, 173 the one longer, by 7e-13; all 256 proofs
    // kept). Every plan the probe does not prove is as before (every run taken up: newton_fails_at
    // as it was). After one creeping step in the seeds' group too, grid case 7 (its proof is a
    // seed's run that creeps) cost 1.45 -> 3.16 M; with the seeds' runs taken up before the chain
    // for one mode fewer, 181 2.88 -> 2.56 M (1.97 M so).
    const bool probing = stop_proven && how.probe;
    int pass = 0;  // 0: one pass; 1 (the probe), 2: after it
    bool may_set_aside = false;  // the probe's first walk of its paths
    // The round whose Newton run failed in the probe, by group (0: seeds, 1: wiggles, 2: the quick
    // chain's wiggles, which the second pass does not walk) and by the path's id in its group (-1:
    // none).
    std::array<std::array<int, kMaxPathIds>, 3> newton_fails_at{};
    bool quick_walked = false;  // this stage's probe walked the quick chain's wiggles
    std::size_t group = 0;
    // One path: the chain solved and changed where it breaks a condition. Its continuation is
    // given up once it passes a move 5 % longer than the shortest so far (on the tests' sets it
    // then found no move shorter than the one it stopped at, and two modes plan in about 4 ms
    // instead of 6). `id`: the path's within its group.
    // `from`: a probe's path set aside, taken up again at its round (the probe's sweeps, below).
    const std::size_t n_split = (pulse ? kPulseSeeds.size() : kWholeSeeds.size()) + 2;  // the split seed's id
    const auto walk = [&](ArcChain c, std::size_t id, const ArcSetAside* from = nullptr) {
      if (proven) return;
      const bool probe = pass == 1;
      for (int round = from != nullptr ? from->round : 0; round < 16; ++round) {
        bool solved = false;
        if (probe) {
          ArcPause ps{};
          if (from != nullptr && round == from->round) {
            ps = from->pause;
            ps.resume = true;
          }
          ps.allow = may_set_aside && aside->count < aside->path.size();
          ps.creeps = group == 0 ? 3 : 1;
          solved = arc_newton(pb, c, ArcVec{}, 0.0, kArcTol, 40, false, &ps);
          if (ps.paused) {
            aside->path[aside->count++] = {c, ps, round, group, id};
            return;
          }
          if (!solved) newton_fails_at[group][id] = round;
        } else if (pass == 2 && newton_fails_at[group][id] == round) {
          solved = arc_continue(pb, c, 1.05 * best);
        } else {
          solved = arc_solve(pb, c, 1.05 * best);
        }
        if (!solved || (!probe && memo.seen(c, pb.amax)) || lay_out(pb, c).T > best) return;
        const ArcFix fx = arc_violation(pb, c);
        if (fx.kind == ArcFix::none) {
          const FastestTable t = arc_table(pb, c, r.distance);
          if (t.count == 0) return;
          const double T = table_duration(t);
          Peaks<double> pk{};
          if (T < best && table_ok(t, Limits{pb.vmax, pb.amax, pb.J}, ms, 0.0, pk)) {
            const bool proof = stop_proven && certify(t).proof == FastestProof::proven;
            if (probe && !proof) return;
            best = T;
            out = t;
            out_pk = pk;
            have = true;
            if (best_chain != nullptr) *best_chain = {c, pulse, true};
            proven = proof;
            probed = proof && probe;
            best_holds_amax = best_cruises = false;
            for (std::size_t i = 0; i < c.n; ++i) {
              best_holds_amax |= c.node[i].kind == ArcKind::limit;
              best_cruises |= c.node[i].kind == ArcKind::cruise;
            }
          }
          return;
        }
        if (!apply_fix(pb, fx, c)) return;
      }
    };
    // The chain for one mode fewer, a small and a large wiggle in each ramp. Chosen on the tests'
    // sets against one size: 10 % of the rise alone or 80 % alone each found some of the other's
    // shorter moves; both together the shortest of either (docs/fastest.md, "Seeds"). And a
    // wiggle twice the rise, from limit to limit where it reaches them, in the ramps into or out
    // of a hold at amax: the reference's moves cancel a fast mode with a blip across the whole
    // range inside such a hold (on its grid 5 more cases reach it, among them 4 that were 7 % to
    // 26 % longer; in the other ramps it found nothing more and cost a third of the grid's time).
    const auto wiggles = [&](const ArcChain& base) {
      std::size_t id = 0;
      for (const double frac : {0.05, 0.4, 1.0}) {
        for (std::size_t k = 0; k <= base.n; ++k, ++id) {
          ArcChain c{};
          const bool by_limit = (k < base.n && base.node[k].kind == ArcKind::limit) ||
                                (k > 0 && base.node[k - 1].kind == ArcKind::limit);
          if (frac == 1.0 && !by_limit) continue;  // the wide wiggle: next to a hold at amax only
          if (frac == 1.0 && lean && pulse) continue;
          if (insert_wiggle(pb, base, k, frac, c)) walk(c, id);
        }
      }
      // And the small wiggle near either end of each ramp, centred a quarter period of the new
      // (fastest) mode from it, where the ramp is longer than that mode's half period (otherwise
      // it is the middle one above). The slower modes' conditions fix the ramps' ends; a fast mode
      // is cancelled by a short blip next to them, and on a heavily damped one only the blips
      // near the move's end count (its ringing decays within a few of its periods): the
      // reference's moves have such blips (grid case 113, 278.7 rad/s at zeta 0.3: a 4 ms notch
      // at the end of the closing ramp), which a wiggle in a ramp's middle does not reach.
      const double quarter = 0.25 * two_pi_v<double>() / sub_fast_wd;
      for (std::size_t k = 0; k <= base.n; ++k) {
        const double a_prev = k == 0 ? 0.0 : node_level(pb, base, k - 1);
        const double a_next = k == base.n ? 0.0 : node_level(pb, base, k);
        const double off = pb.J * quarter / std::fabs(a_next - a_prev);  // of the rise
        if (!(off < 0.5)) continue;
        for (const double at : {off, 1.0 - off}) {
          ArcChain c{};
          if (insert_wiggle(pb, base, k, 0.05, c, at)) walk(c, 3 * (kMaxArcNodes + 1) + 2 * k + (at == off ? 0 : 1));
        }
      }
    };
    if (dips) {
      need_sub();
      // A dip in a hold at amax (insert_dip): the acceleration leaves the limit, turns back at
      // a = 0 and returns to it, a peak between two holds. The reference's moves on long
      // accelerations at amax cancel a mode so (grid case 167: dips to a = 0.03 and -0.20 in
      // its two holds at +amax); the seeds above hold amax without a break. Inserted into each
      // hold of the rigid time-optimal move (one mode: 2 + 2 nodes, square) or of the chain for
      // one mode fewer. Last, so that every path before runs as without them. The chain for one
      // mode fewer that the recursion hands up is the one from before its dips; its dip chain
      // comes beside it (ArcBest::late), and its wiggles are seeds here, last too (handed up
      // instead, a dip chain's wiggles replaced the others: a random two-mode case of the tests
      // 2.4 % longer).
      const FastestTable before = out;
      const Peaks<double> before_pk = out_pk;
      const double before_best = best;
      const bool before_have = have;
      const ArcBest before_chain = best_chain != nullptr ? *best_chain : ArcBest{};
      // Only where the rigid move lasts a period of the slowest mode or more: a dip cancels a
      // mode that rings through a hold, and a shorter move's chains turn at its ends instead (on
      // the grids every move a dip shortened lasted 1.2 periods or more; the reference request
      // of BM_PlanFastest/one_mode, 0.6, paid 70 % more instructions for dips that led nowhere).
      ArcChain rigid{};
      const double t_rigid = push_rigid_move(pb, pb.D, rigid);
      const ArcChain* from = ms.n == 1 ? &rigid : sub.have && !sub.pulse ? &sub.c : nullptr;
      if (t_rigid * w_min < two_pi_v<double>()) from = nullptr;
      // From three modes on, the dips also go where the rigid move is shorter than that but lasts
      // a period of the fastest mode: into the holds of the chain for one mode fewer that last a
      // period of that mode or more (a dip there cancels the fastest mode, which rings through
      // the hold). Grid case 137 (4.5 / 155 / 203 rad/s, the rigid move 1.15 s, the slowest mode's
      // period 1.4 s): its optimum dips in the last hold at -amax, 0.15 s long. Holds shorter
      // than a period are left alone: the BM_PlanFastest/three_modes request's (25 ms, the
      // fastest mode's period 88 ms) cost 11 % more instructions for dips that led nowhere.
      const ArcChain* dip_from = from;
      bool short_holds_too = true;  // dip_from == from: every hold, as before
      if (from == nullptr && ms.n >= 3 && sub.have && !sub.pulse) {
        double w_max = 0.0;
        for (std::size_t i = 0; i < ms.n; ++i) w_max = std::fmax(w_max, ms.m[i].omega);
        if (t_rigid * w_max >= two_pi_v<double>()) {
          dip_from = &sub.c;
          short_holds_too = false;
        }
      }
      // Each stage sees what the stages before it found (as a bound), never the other way round,
      // and hands its own shortest up apart (ArcBest::late): what an earlier stage found, and what
      // the recursion hands up of it, is as without the later ones.
      std::array<ArcChain, kLateStages> got{};
      std::array<bool, kLateStages> got_have{};
      for (std::size_t st = 0; st < kLateStages; ++st) {
        const double start = best;
        if (st == 0) {
          for (std::size_t k = 0; dip_from != nullptr && !lean && k < dip_from->n; ++k) {
            if (!short_holds_too && dip_from->x[k] * sub_fast_wd < two_pi_v<double>()) continue;
            ArcChain c{};
            if (insert_dip(pb, *dip_from, k, 0.0, c)) walk(c, 0);
          }
        } else if (st == 1) {
          // The rigid move itself as the chain for one mode fewer (for one mode: the chain of
          // no mode), with the wiggles above.
          if (ms.n == 1 && from != nullptr) wiggles(rigid);
        } else {
          // Stage 2: a stop inside a cruise (insert_stop), the dwell a quarter period of the
          // newest mode; stage 3: slow-downs to the levels kSlowTo (insert_slowdown). Into the rigid
          // move's cruise (one mode) and each cruise of the chains for one mode fewer (of the
          // stages up to this one), where the rigid move lasts a period of the slowest mode (the
          // dips' rule).
          const double dwell = 0.25 * two_pi_v<double>() / sub_fast_wd;
          const bool long_move = from != nullptr;
          const std::array<const ArcChain*, 2 + kLateStages> bases{
              long_move && ms.n == 1 ? &rigid : nullptr, long_move && ms.n > 1 ? from : nullptr,
              long_move && sub.late_have[0] ? &sub.late[0] : nullptr,
              long_move && sub.late_have[1] ? &sub.late[1] : nullptr,
              long_move && sub.late_have[2] ? &sub.late[2] : nullptr,
              long_move && st == 3 && sub.late_have[3] ? &sub.late[3] : nullptr};
          for (const ArcChain* b : bases) {
            if (lean && st == 2) break;
            for (std::size_t k = 0; b != nullptr && k < b->n; ++k) {
              ArcChain c{};
              if (st == 2) {
                if (insert_stop(pb, *b, k, dwell, c)) walk(c, 0);
                if (b == &rigid && k + 1 == b->n && append_restart(pb, *b, dwell, c)) walk(c, 0);
                continue;
              }
              for (const double to : kSlowTo) {
                if (insert_slowdown(pb, *b, k, to, c)) walk(c, 0);
              }
            }
          }
        }
        // and the like chain for one mode fewer (its own stage, recursively) with the wiggles.
        if (sub.late_have[st]) wiggles(sub.late[st]);
        if (best < start && best_chain != nullptr) {
          got[st] = best_chain->c;
          got_have[st] = true;
        }
      }
      if (best < before_best) {
        *dip_out = {out, out_pk, true};
        out = before;
        out_pk = before_pk;
        have = before_have;
        if (best_chain != nullptr) {
          *best_chain = before_chain;
          best_chain->late = got;
          best_chain->late_have = got_have;
        }
      }
      break;
    }
    const ArcSeed* seeds = pulse ? kPulseSeeds.data() : kWholeSeeds.data();
    const std::size_t n_seeds = pulse ? kPulseSeeds.size() : kWholeSeeds.size();
    // The split seed: the move split at a shaper's impulses, at rest between the parts
    // (split_chain). Last in one pass, first in the probe.
    const auto walk_split = [&] {
      ArcChain c{};
      if (!pulse && split != nullptr && split_chain(pb, *split, c)) walk(c, n_split);
    };
    const auto seeds_group = [&] {
    for (std::size_t k = 0; k < n_seeds; ++k) {
      const ArcSeed& sd = seeds[k];
      // The peak chain is for moves whose acceleration stays below amax: in the whole form not
      // tried when its shortest move holds amax (on the grids it then found nothing shorter;
      // for the pulse it did). Inner peaks are for several modes (with one they found nothing
      // the others did not).
      if (sd.shape == SeedShape::peaks && !pulse && best_holds_amax) continue;
      if (sd.shape == SeedShape::inner_peaks && ms.n < 2) continue;
      if (pulse ? three_pulse
                : three_top && (sd.shape == SeedShape::last_peak || sd.shape == SeedShape::inner_peaks)) {
        continue;
      }
      walk(seed_chain(sd, n0, unit_hold, pb.amax), k);
    }
    if (!pulse) {
      // Peaks at half the level the rigid time-optimal move reaches, where that is below amax
      // (otherwise the seed is the all-peaks one above): short moves on fast modes turn far
      // below amax, and from peaks at amax / 2 Newton's method does not reach them. With one
      // mode also a notched deceleration: a turn back short of a = 0 and down again, the shape
      // of the reference's moves on a heavily damped fast mode (levels from two of them, 200 and
      // 47 rad/s at zeta 0.26 and 0.22: 0.97 / 0.98, -0.83 / -0.90, -0.12 / -0.16, -0.52 / -0.42
      // of the rigid level), where no other seed leads.
      const double a_rigid = std::fmin(std::cbrt(0.5 * pb.D * pb.J * pb.J), std::sqrt(pb.vmax * pb.J));
      if (a_rigid < pb.amax && !three_top) {
        ArcChain c = seed_chain({SeedShape::peaks, 0.0}, n0, unit_hold, pb.amax);
        for (std::size_t i = 0; i < c.n; ++i) c.x[i] = 0.5 * c.node[i].sign * a_rigid;
        walk(c, n_seeds);
        if (n0 == 4) {
          constexpr std::array<double, 4> kNotch{1.0, -0.85, -0.15, -0.5};
          for (std::size_t i = 0; i < c.n; ++i) c.x[i] = kNotch[i] * a_rigid;
          walk(c, n_seeds + 1);
        }
      }
    }
    if (pass != 1) walk_split();
    };
    // The probe's runs set aside, taken up again in the order they were set aside (the paths'
    // order) and run to their end. split_only: the split seed's alone (the probe's first path),
    // the others kept aside.
    const auto take_up = [&](bool split_only) {
      if (aside == nullptr || aside->count == 0) return;
      const bool split_first = aside->path[0].group == 0 && aside->path[0].id == n_split;
      if (split_only && !split_first) return;
      const bool was = may_set_aside;  // the runs taken up are not set aside again
      may_set_aside = false;
      if (split_only) {
        const ArcSetAside from = aside->path[0];
        std::copy(aside->path.begin() + 1, aside->path.begin() + static_cast<std::ptrdiff_t>(aside->count),
                  aside->path.begin());
        --aside->count;
        group = from.group;
        walk(from.c, from.id, &from);
      } else {
        for (std::size_t k = 0; k < aside->count && !proven; ++k) {
          const ArcSetAside& from = aside->path[k];
          group = from.group;
          walk(from.c, from.id, &from);
        }
        aside->count = 0;
      }
      may_set_aside = was;
    };
    // The quick chain for one mode fewer (three modes or more, the request's probe): the recursion
    // planned with its own probe. Where that probe proves it, its wiggles are probed (group 2, no
    // run set aside), and where they prove nothing the chain one pass plans is planned after all
    // (need_sub): the proof is the same move in other bits, and the search built on it lands
    // elsewhere (the recursion probed in its place lengthened grid cases 134 by 0.9 % and 227 by
    // 0.17 %, session 33). Where its probe proves nothing, its second pass made one pass's chain
    // to the bit, and need_sub takes it. So every plan the request's probe does not prove is as
    // before, and the three-mode request's chain for one mode fewer (5 / 23 rad/s), which its
    // probe proves, carries the request's proof. Walked right after the split seed (both_groups):
    // BM_PlanFastest/three_modes 33.0 -> 14.9 M instructions, the grid's three-mode median 14.5 ->
    // 10.4 M; 23 of those 100 plans cost more (the probe's runs that solve are run again, and a
    // quick chain whose wiggles prove nothing is planned twice: 83 39.7 -> 54.3 M), the sum 13.8 ->
    // 14.05 G (session 35, cggrid.py; docs/fastest.md "Session 35: the quick chain"). The
    // grid's plans that differ are 13 proven ones, by at most 1.3e-10 s; no unproven plan changed
    // a bit (jsongrid.py). Not for two modes: their median 2.06 -> 1.95 M, but 35 of the 100 cost
    // more and the sum rose 4.75 -> 4.85 G (their chain for one mode fewer is one mode's, cheap).
    const auto quick_wiggles = [&] {
      if (!(pass == 1 && request && ms.n >= 3) || proven) return;
      if (!sub_done) {
        quick = plan_fewer(r, ms, stop_proven, true);
        if (!quick.probed) {
          sub_store = quick;
          sub_done = true;
        }
      }
      if (!quick.probed || quick.pulse != pulse) return;
      const bool was = may_set_aside;
      may_set_aside = false;
      group = 2;
      wiggles(quick.c);
      may_set_aside = was;
      quick_walked = true;
    };
    // The one pass's chain the same to the bit as the quick chain whose wiggles were probed: its
    // wiggles' probe would walk the same runs to the same ends (a run set aside ends as it would
    // have, and none proved), so it is not walked again, and the second pass reads where those
    // runs failed.
    const auto sub_is_quick = [&] {
      if (!quick_walked || !sub.have || sub.pulse != pulse || sub.c.n != quick.c.n) return false;
      for (std::size_t i = 0; i < sub.c.n; ++i) {
        if (sub.c.node[i].kind != quick.c.node[i].kind ||
            std::bit_cast<std::uint64_t>(sub.c.node[i].sign) != std::bit_cast<std::uint64_t>(quick.c.node[i].sign) ||
            std::bit_cast<std::uint64_t>(sub.c.x[i]) != std::bit_cast<std::uint64_t>(quick.c.x[i])) {
          return false;
        }
      }
      return true;
    };
    // Both groups in their order; the probe's runs set aside are taken up after each (none are
    // set aside outside the probe, and take_up does nothing without them).
    const auto both_groups = [&] {
      group = 0;
      quick_walked = false;
      if (pass == 1) {
        walk_split();
        quick_wiggles();
        group = 0;
      }
      seeds_group();
      take_up(true);
      if (!proven) need_sub();
      group = 1;
      if (pass == 1 && !proven && sub_is_quick()) {
        newton_fails_at[1] = newton_fails_at[2];
      } else if (sub.have && sub.pulse == pulse) {
        wiggles(sub.c);
      }
      take_up(false);
    };
    if (probing) {
      for (auto& fails : newton_fails_at) fails.fill(-1);
      pass = 1;
      may_set_aside = aside != nullptr;
      if (aside != nullptr) aside->count = 0;
      both_groups();
      may_set_aside = false;
      pass = 2;
    }
    both_groups();
    pass = 0;
  }
  if (best_chain != nullptr) {
    best_chain->proven = proven;
    best_chain->probed = probed;
  }
  return have;
}

// ---- The chain as a time minimisation (docs/fastest.md, "More turns than equations") ----
// A chain with more unknowns than equations (turns inserted into a solved chain) has its extra
// freedom fixed by minimising the move's length T, which is linear in the unknowns (each hold
// counts once, a peak's level sets the lengths of the ramps on either side of it), subject to the
// chain's equations F = 0 and the linear inequalities of a chain (holds >= 0, peaks within
// +-amax, ramps of length >= 0). arc_minimise is a gradient projection with an active set: the
// step is -dT/dz projected onto the null space of the equations' Jacobian and the active
// inequalities (z: holds in s, peaks' levels over J, so that every unknown is a time), then the
// equations are restored by minimum-norm Gauss-Newton steps in the same null space of the active
// rows; a step is kept when the restored chain is shorter and breaks no condition of the chain
// (arc_violation: v within [0, vmax] too). An active inequality whose multiplier says T falls
// when it is left is released.
//
// Where to insert turns: at a solved chain with multipliers lambda (dT/dz = lambda J + mu A), a
// pair of turns of zero width inserted anywhere changes nothing, and the derivative of T with
// respect to opening it is the reduced gradient of its new unknowns, c_new - lambda J_new: the
// needle variation of Pontryagin's principle. Where it is negative the chain is not a stationary
// move of any chain with more turns, and opening the pair shortens it; where it is nowhere
// negative (at the points tried) the chain passes the first-order test and is left as it is.

constexpr std::size_t kMaxIneq = 3 * kMaxArcNodes + 1;
constexpr std::size_t kMaxBasisRows = kMaxArcNodes + kMaxIneq;

// The rows' span by modified Gram-Schmidt (twice): the minimum-norm solution of A z = b, the
// projection onto A's null space, and the multipliers w of A^T w = the row-space part of a
// vector. Dependent rows (within 1e-10 of the span of those before) are left out (w = 0).
class RowBasis {
 public:
  explicit RowBasis(std::size_t n) noexcept : n_(n) {}
  // Each product with a basis vector is fused with the subtraction of the one before (and the
  // last with the residual's norm), in the order the two passes take them: the same operations
  // in the same order as a dot product and an update per vector, so every bit is the same, with
  // r read once where it was read twice. Where Packed is a vector (x86-64; not the Cortex-M
  // cores: their flash), each chain length has its own copy with the length fixed (add_packed),
  // its loops unrolled and r kept in registers, two entries a vector
  // (the same operations: on grid case 112, add took 316 M instructions where it took 408 M).
  void add(const ArcVec& a) noexcept {
#if SETTLE_PACKED_VECTOR
    add_by_length(a, std::make_index_sequence<kMaxArcNodes + 1>{});
#else
    add_n<0>(a);
#endif
  }

 private:
  // add's copy for the chain's length, add_n<n_> (0 and 1, and any length beyond: the loop
  // itself, add_n<0>). A chain of tests the compiler makes one jump, as the switch it replaces
  // (grid case 112: 758.2 M instructions with the switch, 755.6 M so; through a table of member
  // pointers, which cannot be inlined, 761.5 M).
  template <std::size_t... NC>
  void add_by_length(const ArcVec& a, std::index_sequence<NC...>) noexcept {
    if (!((n_ == NC ? (add_n<NC>(a), true) : false) || ...)) add_n<0>(a);
  }
  // add, for chains of NC nodes (0: n_, any).
  template <std::size_t NC>
  void add_n(const ArcVec& a) noexcept {
    const std::size_t i = rows_++;
    if (nq_ >= n_) return;
#if SETTLE_PACKED_VECTOR
    if constexpr (NC > 1) {
      add_packed<NC>(a, i);
      return;
    }
#endif
    const std::size_t n = NC > 0 ? NC : n_, m = nq_;
    std::array<double, kMaxArcNodes> r;
    double a_norm = 0.0, d = 0.0;  // d: r's product with the next basis vector to take out
    for (std::size_t c = 0; c < n; ++c) {
      r[c] = a[c];
      a_norm += a[c] * a[c];
    }
    if (m > 0) {
      for (std::size_t c = 0; c < n; ++c) d += q_[0][c] * r[c];
    }
    a_norm = std::sqrt(a_norm);
    if (!(a_norm > 0.0) || !std::isfinite(a_norm)) return;
    std::array<double, kMaxArcNodes>& coef = l_[i];  // entries [0, nq_] are read, no more
    double rn = a_norm;
    if (m > 0) {
      for (std::size_t p = 0; p < m; ++p) coef[p] = 0.0;
      rn = 0.0;
      for (std::size_t t = 0;; ++t) {  // t: the passes' vector steps, p = t mod m
        const std::size_t p = t < m ? t : t - m;
        coef[p] += d;
        const ArcVec& qp = q_[p];
        if (t + 1 == 2 * m) {
          for (std::size_t c = 0; c < n; ++c) {
            r[c] -= d * qp[c];
            rn += r[c] * r[c];
          }
          break;
        }
        const ArcVec& qn = q_[p + 1 == m ? 0 : p + 1];
        double dn = 0.0;
        for (std::size_t c = 0; c < n; ++c) {
          r[c] -= d * qp[c];
          dn += qn[c] * r[c];
        }
        d = dn;
      }
      rn = std::sqrt(rn);
    }
    if (!(rn > 1e-10 * a_norm)) return;
    for (std::size_t c = 0; c < n; ++c) q_[nq_][c] = r[c] / rn;
    coef[nq_] = rn;
    row_of_[nq_] = i;
    ++nq_;
  }
#if SETTLE_PACKED_VECTOR
  // add_n's steps for a chain of NC nodes with r held as NC / 2 pairs (and the last entry alone
  // where NC is odd), which the compiler keeps in registers: each update r -= d q lane by lane,
  // each sum from 0.0 over the entries in their order (both lanes of a pair added low, then
  // high), the same operations in the same order as add_n's loops.
  template <std::size_t NC>
  void add_packed(const ArcVec& a, std::size_t i) noexcept {
    constexpr std::size_t H = NC / 2;
    constexpr bool odd = NC % 2 != 0;
    const std::size_t m = nq_;
    Packed rv[H];  // (not std::array: it would drop __m128d's attributes)
    double rt = 0.0;  // entry NC - 1 where NC is odd
    const auto add_lanes = [](double& s, Packed x) {
      const Cx l = unpack(x);
      s += l.re;
      s += l.im;
    };
    // Sum from 0.0 of w[c] r[c].
    const auto dot = [&](const double* w) {
      double s = 0.0;
#pragma GCC unroll 16
      for (std::size_t h = 0; h < H; ++h) add_lanes(s, _mm_loadu_pd(w + 2 * h) * rv[h]);
      if constexpr (odd) s += w[NC - 1] * rt;
      return s;
    };
    // r -= d q.
    const auto take = [&](double d, const double* q) {
      const Packed dd = splat(d);
#pragma GCC unroll 16
      for (std::size_t h = 0; h < H; ++h) rv[h] = rv[h] - dd * _mm_loadu_pd(q + 2 * h);
      if constexpr (odd) rt -= d * q[NC - 1];
    };
#pragma GCC unroll 16
    for (std::size_t h = 0; h < H; ++h) rv[h] = _mm_loadu_pd(a.data() + 2 * h);
    if constexpr (odd) rt = a[NC - 1];
    double a_norm = dot(a.data()), d = 0.0;
    if (m > 0) d = dot(q_[0].data());
    a_norm = std::sqrt(a_norm);
    if (!(a_norm > 0.0) || !std::isfinite(a_norm)) return;
    std::array<double, kMaxArcNodes>& coef = l_[i];
    double rn = a_norm;
    if (m > 0) {
      for (std::size_t p = 0; p < m; ++p) coef[p] = 0.0;
      for (std::size_t t = 0;; ++t) {
        const std::size_t p = t < m ? t : t - m;
        coef[p] += d;
        take(d, q_[p].data());
        if (t + 1 == 2 * m) break;
        d = dot(q_[p + 1 == m ? 0 : p + 1].data());
      }
      // r's squares: a sum from 0.0, as rn's.
      double sq = 0.0;
#pragma GCC unroll 16
      for (std::size_t h = 0; h < H; ++h) add_lanes(sq, rv[h] * rv[h]);
      if constexpr (odd) sq += rt * rt;
      rn = std::sqrt(sq);
    }
    if (!(rn > 1e-10 * a_norm)) return;
    const Packed rnv = splat(rn);
#pragma GCC unroll 16
    for (std::size_t h = 0; h < H; ++h) _mm_storeu_pd(q_[nq_].data() + 2 * h, rv[h] / rnv);
    if constexpr (odd) q_[nq_][NC - 1] = rt / rn;
    coef[nq_] = rn;
    row_of_[nq_] = i;
    ++nq_;
  }
#endif

 public:
  // z of least norm with A z = b (the kept rows).
  ArcVec solve(const std::array<double, kMaxBasisRows>& b) const noexcept {
    std::array<double, kMaxArcNodes> y{};
    for (std::size_t p = 0; p < nq_; ++p) {
      const std::size_t i = row_of_[p];
      double acc = b[i];
      for (std::size_t j = 0; j < p; ++j) acc -= l_[i][j] * y[j];
      y[p] = acc / l_[i][p];
    }
    ArcVec z{};
    for (std::size_t p = 0; p < nq_; ++p) {
      for (std::size_t c = 0; c < n_; ++c) z[c] += y[p] * q_[p][c];
    }
    return z;
  }
  // g's part in A's null space (returned), and w with A^T w = g's part in A's row space.
  ArcVec project(const ArcVec& g, std::array<double, kMaxBasisRows>& w) const noexcept {
    std::array<double, kMaxArcNodes> y{};
    ArcVec d = g;
    for (std::size_t p = 0; p < nq_; ++p) {
      for (std::size_t c = 0; c < n_; ++c) y[p] += q_[p][c] * g[c];
      for (std::size_t c = 0; c < n_; ++c) d[c] -= y[p] * q_[p][c];
    }
    w.fill(0.0);
    for (std::size_t p = nq_; p-- > 0;) {
      double acc = y[p];
      for (std::size_t s = p + 1; s < nq_; ++s) acc -= w[row_of_[s]] * l_[row_of_[s]][p];
      w[row_of_[p]] = acc / l_[row_of_[p]][p];
    }
    return d;
  }

 private:
  // Not zeroed (8 KB per basis, built once per restoration step): add writes the first n_
  // entries of q_[p], l_[i][0..p] and row_of_[p] of every kept row (p its vector) before anything
  // reads them; solve and project read no more.
  std::size_t n_{0}, rows_{0}, nq_{0};
  std::array<ArcVec, kMaxArcNodes> q_;
  std::array<std::array<double, kMaxArcNodes>, kMaxBasisRows> l_;
  std::array<std::size_t, kMaxArcNodes> row_of_;  // the row each basis vector came from
};

// The chain's linear inequalities g(x) = a x + b >= 0 (value and a in z) and dT/dz.
// Only the first count rows of a, val and tol are written (a's only in the chain's n columns,
// all that is read): zeroing the 46 rows of a (8 KB) at each of arc_minimise's iterations was
// 2 % of a long two-mode plan's instructions.
struct ArcIneq {
  std::array<ArcVec, kMaxIneq> a;
  std::array<double, kMaxIneq> val, tol;
  std::size_t count{0};
  ArcVec dt{};   // dT / dz
  ArcVec unit{}; // dx / dz: 1 for a hold, J for a peak's level
};

// The inequalities' values and tolerances alone, in arc_ineq's order: what the restoration's
// merit reads at each trial. Their rows a depend on the chain's kinds and signs alone (a ramp's
// jerk is its sign times J), the same at every point of a restoration, so the merit does not
// build them (building and zeroing the 46 rows was 14 % of the grid's instructions; every value
// is computed by the same operations as before, so every plan is the same to the bit).
struct ArcIneqVals {
  std::array<double, kMaxIneq> val, tol;  // the first count written
  std::size_t count;
};
void arc_ineq_vals(const ArcProblem& pb, const ArcChain& c, const ArcLayout& L, ArcIneqVals& q) noexcept {
  q.count = 0;
  const auto add = [&](double v, double tol) {
    q.val[q.count] = v;
    q.tol[q.count++] = tol;
  };
  const double t_tol = 1e-12 * L.T, a_tol = 1e-12 * pb.amax;
  for (std::size_t i = 0; i < c.n; ++i) {
    const ArcNode& k = c.node[i];
    if (k.kind == ArcKind::peak) {
      add(pb.amax - k.sign * c.x[i], a_tol);  // not beyond its own limit
      add(pb.amax + k.sign * c.x[i], a_tol);  // nor beyond the other
    } else {
      add(c.x[i], t_tol);
    }
  }
  // Ramp r (into node r; r = n the closing one) lasts (level_r - level_{r-1}) / j_r.
  for (std::size_t r = 0; r <= c.n; ++r) {
    const bool in_peak = r < c.n && c.node[r].kind == ArcKind::peak;
    const bool from_peak = r > 0 && c.node[r - 1].kind == ArcKind::peak;
    if (in_peak || from_peak) add(L.e[r] - L.b[r], t_tol);
  }
}

// dT/dz and dx/dz alone (pair_gain reads nothing else).
void arc_ineq_dt(const ArcProblem& pb, const ArcChain& c, const ArcLayout& L, ArcVec& dt, ArcVec& unit) noexcept {
  dt = ArcVec{};
  unit = ArcVec{};
  for (std::size_t i = 0; i < c.n; ++i) unit[i] = c.node[i].kind == ArcKind::peak ? pb.J : 1.0;
  for (std::size_t r = 0; r <= c.n; ++r) {
    if (r < c.n && c.node[r].kind == ArcKind::peak) dt[r] += 1.0 / L.j[r] * unit[r];
    if (r > 0 && c.node[r - 1].kind == ArcKind::peak) dt[r - 1] += -1.0 / L.j[r] * unit[r - 1];
  }
  for (std::size_t i = 0; i < c.n; ++i) {
    if (c.node[i].kind != ArcKind::peak) dt[i] = 1.0;
  }
}

ArcIneq arc_ineq(const ArcProblem& pb, const ArcChain& c, const ArcLayout& L) noexcept {
  ArcIneq q;
  arc_ineq_dt(pb, c, L, q.dt, q.unit);
  ArcIneqVals v;
  arc_ineq_vals(pb, c, L, v);
  q.count = v.count;
  std::copy_n(v.val.begin(), v.count, q.val.begin());
  std::copy_n(v.tol.begin(), v.count, q.tol.begin());
  for (std::size_t r = 0; r < q.count; ++r) std::fill_n(q.a[r].begin(), c.n, 0.0);
  // The rows, in the order of arc_ineq_vals.
  std::size_t row = 0;
  for (std::size_t i = 0; i < c.n; ++i) {
    const ArcNode& k = c.node[i];
    if (k.kind == ArcKind::peak) {
      q.a[row++][i] = -k.sign * q.unit[i];
      q.a[row++][i] = k.sign * q.unit[i];
    } else {
      q.a[row++][i] = q.unit[i];
    }
  }
  for (std::size_t r = 0; r <= c.n; ++r) {
    const bool in_peak = r < c.n && c.node[r].kind == ArcKind::peak;
    const bool from_peak = r > 0 && c.node[r - 1].kind == ArcKind::peak;
    if (in_peak) q.a[row][r] = 1.0 / L.j[r] * q.unit[r];
    if (from_peak) q.a[row][r - 1] = -1.0 / L.j[r] * q.unit[r - 1];
    if (in_peak || from_peak) ++row;
  }
  return q;
}

// The minimum-norm step dz (in z: x moves by dz unit) with J dz = -f on the rows and a dz = -val on
// each inequality that `held` names (it is linear: the step sets it to 0): its row from qi, its
// value from qv (qi's own, or the values at another chain of the same node kinds).
template <class Vals, class Held>
ArcVec min_norm_step(const ArcChain& c, const ArcMat& jm, const ArcVec& f, std::size_t rows, const ArcVec& unit,
                     const ArcIneq& qi, const Vals& qv, Held held) noexcept {
  RowBasis basis(c.n);
  std::array<double, kMaxBasisRows> b;  // the first k written, all that solve reads
  std::size_t k = 0;
  for (std::size_t r = 0; r < rows; ++r) {
    ArcVec a;  // the first c.n written, all that add reads
    for (std::size_t i = 0; i < c.n; ++i) a[i] = jm[r][i] * unit[i];
    basis.add(a);
    b[k++] = -f[r];
  }
  for (std::size_t r = 0; r < qv.count; ++r) {
    if (!held(r)) continue;
    basis.add(qi.a[r]);
    b[k++] = -qv.val[r];
  }
  return basis.solve(b);
}

// Of the inequalities a step leaves free (not `held`) and `near` names, those the step dz takes
// below 0 (to first order: val + a dz < 0; the rows are linear), marked in `broken`: true when
// any is. Whether an inequality at its bound is held turns on the sign of its rounding
// (+1.8e-12 against a tolerance of 1.1e-11 at one scale, below 0 at another), and a free one the
// step crosses folds the chain (a hold or a ramp of negative length), where the rows are no longer
// the step's linearisation: the step fails, or is accepted only at its half.
template <class Vals, class Held, class Near>
bool step_breaks(const ArcChain& c, const ArcIneq& qi, const Vals& qv, const ArcVec& dz, Held held, Near near,
                 std::array<bool, kMaxIneq>& broken) noexcept {
  bool any = false;
  for (std::size_t r = 0; r < qv.count; ++r) {
    if (held(r) || !near(r)) continue;
    double ad = 0.0;
    for (std::size_t i = 0; i < c.n; ++i) ad += qi.a[r][i] * dz[i];
    if (qv.val[r] + ad < 0.0) broken[r] = any = true;
  }
  return any;
}

// min_norm_step holding `held`, and where that step breaks an inequality `near` names
// (step_breaks), the step again holding those too.
template <class Vals, class Held, class Near>
ArcVec step_holding_breaks(const ArcChain& c, const ArcMat& jm, const ArcVec& f, std::size_t rows, const ArcIneq& qi,
                           const Vals& qv, Held held, Near near) noexcept {
  const ArcVec dz = min_norm_step(c, jm, f, rows, qi.unit, qi, qv, held);
  std::array<bool, kMaxIneq> broken{};
  if (!step_breaks(c, qi, qv, dz, held, near, broken)) return dz;
  return min_norm_step(c, jm, f, rows, qi.unit, qi, qv, [&](std::size_t r) { return held(r) || broken[r]; });
}

// Restores F(c) = 0 by minimum-norm Gauss-Newton steps that keep the active rows (linear) as
// they are. True when |F| < 1e-13 (or stalls within 1e-10 of it, or below a tenth of the rows'
// rounding: arc_newton's rule). With pb.to_rounding (a seed on a move whose rows round above
// that: cruise_stops_refined) also when |F| falls below a tenth of the rows' rounding
// (arc_rounding_floor at the start), or stalls below that rounding: grid case
// 121's rows, sums of terms jmax T^3 / 6 = 2e8 m cancelling to D = 5.6 m, round to 2e-8 and its
// restorations stalled there (returning at a tenth of it cut the seed's instructions from 162 M
// to 115 M against stalling each time, the same chain to 3e-9 of its duration). With
// `hold_breaks`, an inequality within its tolerance that a step would break is held at 0 in that
// step too (step_breaks; restore_seed's retry).
//
// With `t_abandon` (arc_minimise's trials), a restoration whose chain, once its rows are below
// 1e-8, is longer than t_abandon or breaks a condition of the chain (arc_violation), both by a
// margin (abandon_margin), is given up (false, *abandoned set): the trial would be refused as it
// is. Its last steps take rows of 1e-11 to 1e-13 (of grid case 5's restorations in arc_refine's
// candidates, 5 148 of 7 941 steps started below 1e-10), but along the chain's ill-conditioned
// directions: they moved T by 1.3e-8 of itself (grid case 35, rows at 1e-10) and v at a turn by
// more than 1e-8 vmax (112, rows at 1.7e-13) and 1e-7 vmax (5, rows at 3.8e-11). A margin of
// 1e-8 gave up trials that would have been kept (5, 35, 112; 5 then planned 3.59167 s, not
// proven, against 3.59144 s proven), 1e-7 none, and 1e-6 (1e6 times the rows where larger), ten
// times that, none on the grid: every plan the same to the bit (the steps taken are those taken
// without it). Grid case 5 1 493 M -> 1 261 M instructions, 112 1 037 M -> 756 M (from rows
// below 1e-10: 1 281 M and 779 M; below 1e-6 no fewer than 1e-8).
double abandon_margin(double n) noexcept { return std::fmax(1e-6, 1e6 * n); }
bool arc_restore(const ArcProblem& pb, ArcChain& c, const ArcIneq& q, const std::array<bool, kMaxIneq>& active,
                 ArcVec& f, ArcEval& ev, bool hold_breaks = false, std::size_t* rows_out = nullptr,
                 double t_abandon = HUGE_VAL, bool* abandoned = nullptr) noexcept {
  ArcMat jm;  // arc_jacobian writes its rows x columns below c.n, all that is read
  // c's rows and evaluation in one pair (fc, ec: first the caller's f and ev), each trial's in the
  // other, the two swapped where a trial is accepted: where the line search fails, c's are still
  // there, not evaluated again (over the grid's 300 plans, evaluations of a chain's system 2.681 M
  // -> 2.633 M; every value the same: arc_values with a `stop` it does not reach computes what it
  // computes without).
  ArcVec f_other;
  ArcEval ev_other;
  ArcVec* fc = &f;
  ArcEval* ec = &ev;
  ArcVec* ft = &f_other;
  ArcEval* et = &ev_other;
  std::size_t rows = arc_values(pb, c, *fc, *ec);
  // The equations' norm plus how far an inequality is broken (relative to its scale); the active
  // rows and the broken ones are set to 0 exactly (they are linear: one step does it).
  const auto merit = [&](const ArcChain& x, const ArcVec& fx, std::size_t nx, const ArcEval& e, ArcIneqVals& qx) {
    arc_ineq_vals(pb, x, e.L, qx);
    double m = arc_norm(fx, nx);
    for (std::size_t r = 0; r < qx.count; ++r) {
      if (qx.val[r] < 0.0) m += -qx.val[r] / (qx.tol[r] * 1e12);
    }
    return m;
  };
  // The values at c (its rows are q's: the same kinds) and at the trial, swapped on an accepted
  // step (not copied: 1.1 KB), as the trial's nodes are c's (only its unknowns are copied back).
  std::array<ArcIneqVals, 2> q_at;
  ArcIneqVals* qc = &q_at[0];
  ArcIneqVals* qt = &q_at[1];
  double n0 = merit(c, *fc, rows, *ec, *qc);
  // In the loop, where a line search stalls, jm is still c's Jacobian (the steps only read it);
  // after the last step it is the point's before.
  const auto stalled_solved = [&](double n, bool jm_at_c) {
    if (n < 1e-10) return true;
    if (!jm_at_c) arc_jacobian(pb, c, *ec, jm);
    return n < stall_floor(pb, c, *ec, jm, rows);
  };
  // c's rows and evaluation left in the caller's f and ev.
  const auto done_with = [&](bool ok) {
    if (fc != &f) {
      f = *fc;
      ev = *ec;
    }
    if (rows_out != nullptr) *rows_out = rows;
    return ok;
  };
  // From c's evaluation in hand (*ec), not a new one; jm is made again at the loop's first step.
  const auto at_c_rounding = [&] {
    arc_jacobian(pb, c, *ec, jm);
    return arc_rounding_floor(pb, c, *ec, jm, rows);
  };
  const double done = pb.to_rounding ? std::fmax(1e-13, 0.1 * at_c_rounding()) : 1e-13;
  const ArcShape shape = arc_shape(pb, c);  // the trials' nodes are c's
  ArcChain trial = c;
  for (int it = 0; it < 30; ++it) {
    if (!std::isfinite(n0)) return done_with(false);
    if (n0 < done) return done_with(true);
    if (abandoned != nullptr && n0 < 1e-8 &&
        (ec->L.T > t_abandon * (1.0 + abandon_margin(n0)) ||
         arc_violation(pb, c, abandon_margin(n0), &ec->L).kind != ArcFix::none)) {
      *abandoned = true;
      return done_with(false);
    }
    arc_jacobian(pb, c, *ec, jm);
    const auto held = [&](std::size_t r) { return active[r] || qc->val[r] < 0.0; };
    const ArcVec dz =
        hold_breaks
            ? step_holding_breaks(c, jm, *fc, rows, q, *qc, held,
                                  [&](std::size_t r) { return qc->val[r] < qc->tol[r]; })
            : min_norm_step(c, jm, *fc, rows, q.unit, q, *qc, held);
    double n1 = HUGE_VAL;
    std::size_t trial_rows = rows;
    for (double lam = 1.0; lam > 1e-3; lam *= 0.5) {
      for (std::size_t i = 0; i < c.n; ++i) trial.x[i] = c.x[i] + lam * dz[i] * q.unit[i];
      const std::size_t got = arc_values(pb, trial, *ft, *et, n0, nullptr, 0.0, true, &shape);  // 0: rejected early
      if (got == 0) {
        n1 = HUGE_VAL;
        continue;
      }
      trial_rows = got;
      n1 = merit(trial, *ft, trial_rows, *et, *qt);
      if (std::isfinite(n1) && n1 < n0) break;
    }
    if (!(n1 < n0)) {
      // stalled near a solution, nothing broken
      return done_with(stalled_solved(n0, true) && arc_norm(*fc, rows) == n0);
    }
    std::copy_n(trial.x.begin(), c.n, c.x.begin());
    std::swap(qc, qt);
    n0 = n1;
    rows = trial_rows;
    std::swap(fc, ft);
    std::swap(ec, et);
  }
  return done_with(stalled_solved(n0, false) && arc_norm(*fc, rows) == n0);
}

// A seed (a chain with turns or parts inserted) restored to its chain's equations from where it
// lies, no inequality held, and still a move (no velocity bound broken): what every seed passes
// before it is minimised or kept. Where that fails, restored again from the seed holding each
// inequality within its tolerance that a step would break (arc_restore's hold_breaks): on the
// grid, grid case 254 at scale 7.3 then screens the dwell changes as at scale 1 (1.69041 s against
// 1.69034 s, was 1.69772 s), 112 at 7.3 and 134 at 1e-3 and 7.3 plan as at scale 1, and 134 at
// scale 1 0.077 % shorter (1.48437 s; every other grid plan at scale 1 the same); D 1 on 7 and 19
// rad/s 1.38151 s, the linear program's, where it was 1.1 % over (1.39701 s). Only as a retry:
// held in every restoration, the search at scale 1 lands elsewhere (5, 86 and 254 longer).
bool restore_seed(const ArcProblem& pb, ArcChain& c) noexcept {
  const ArcIneq q0 = arc_ineq(pb, c, lay_out(pb, c));
  const std::array<bool, kMaxIneq> none{};
  ArcVec f{};
  ArcEval ev;
  const ArcChain seed = c;
  if (arc_restore(pb, c, q0, none, f, ev) && arc_violation(pb, c).kind == ArcFix::none) return true;
  c = seed;
  return arc_restore(pb, c, q0, none, f, ev, true) && arc_violation(pb, c).kind == ArcFix::none;
}

// arc_values' rows with v and p (at the end, and v at each cruise or dwell) integrated forward
// over the chain's own lengths (each ramp (level - level before) / j, each hold its x) with the
// acceleration exactly 0 on each cruise or dwell: the table's own v and p as arc_table_direct and
// rests_exact lay it out, each sum rounded to eps of the move's v and p, where arc_values' sums of
// j (u_b^k - u_e^k) / k! round to eps of jmax T^k / k!. On grid case 265 (two modes, D 1.6 mm,
// jmax 1210, T 3.8 s) the chain arc_values solves has v = -1.2e-13 m/s at its second dwell, which
// over its 2.2 s runs back 1.6e-10 D.
std::size_t arc_values_forward(const ArcProblem& pb, const ArcChain& c, ArcVec& f, ArcEval& ev) noexcept {
  const std::size_t rows = arc_values(pb, c, f, ev);
  double a = 0.0, v = 0.0, p = 0.0, lev0 = 0.0;
  std::size_t k = (pb.pulse ? 1 : 2) + 2 * pb.ms->n;
  const auto run = [&](double d, double j) {
    if (!(d > 0.0)) return;
    p += d * (v + d * (a / 2.0 + j * d / 6.0));
    v += d * (a + j * d / 2.0);
    a += j * d;
  };
  for (std::size_t r = 0; r <= c.n; ++r) {
    const bool closing = r == c.n;
    const double s = closing ? ramp_out(c.node[c.n - 1]) : ramp_in(c.node[r]);
    const double lev = closing ? 0.0 : node_level(pb, c, r);
    run((lev - lev0) / (s * pb.J), s * pb.J);
    lev0 = lev;
    if (closing) break;
    const ArcKind kd = c.node[r].kind;
    if (kd == ArcKind::cruise || kd == ArcKind::dwell) {
      a = 0.0;  // exactly, as rests_exact makes the table's
      if (k < rows) f[k++] = (v - (kd == ArcKind::cruise ? pb.vmax : 0.0)) / pb.vmax;
    }
    if (kd != ArcKind::peak) run(c.x[r], 0.0);
  }
  f[0] = (v - (pb.pulse ? pb.vmax : 0.0)) / pb.vmax;
  if (!pb.pulse) f[1] = (p - pb.D) / pb.D;
  return rows;
}

// c's rows of v and p (arc_values_forward) brought nearer 0 by minimum-norm Gauss-Newton steps
// that leave the modes' rows as they are (to first order: they are solved to the rounding of
// their own sums) and the active inequalities (a hold of 0, a ramp of 0) exactly, while those
// rows' norm falls. True when it fell. With `modes`, the modes' rows are brought nearer 0 with
// them: where the chain was solved to a rounding above the modes' own (a stall at 2e-8 spreads it
// over every row), the modes are left ringing that much (keep_or_polish). An inequality a step
// would break is held at 0 in that step (step_breaks): grid case 86 at scale 0.37 has a hold
// above its tolerance that the first step takes below 0; that step left the rows at twice their
// norm and the polish stopped at once, its chain refused for 1.29e-12 D run back (7.1494 s, at
// scale 1 polished to 1e-18 D); holding it, the first step brings the rows to 5e-16.
bool arc_polish(const ArcProblem& pb, ArcChain& c, bool modes = false) noexcept {
  ArcVec f{};
  ArcEval ev;
  ArcMat jm;  // arc_jacobian writes its rows x columns below c.n, all that is read
  // Rows [first_mode, held_end) are held: left out of the norm and of the step's target (none with `modes`).
  const std::size_t first_mode = pb.pulse ? 1 : 2, held_end = modes ? first_mode : first_mode + 2 * pb.ms->n;
  const auto kinematic = [&](ArcVec& g, std::size_t n) {
    for (std::size_t r = first_mode; r < held_end && r < n; ++r) g[r] = 0.0;
    return arc_norm(g, n);
  };
  std::size_t rows = arc_values_forward(pb, c, f, ev);
  const double start = kinematic(f, rows);
  double n0 = start;
  for (int it = 0; it < 8 && n0 > 0.0; ++it) {
    arc_jacobian(pb, c, ev, jm);
    const ArcIneq q = arc_ineq(pb, c, ev.L);
    const ArcVec dz = step_holding_breaks(
        c, jm, f, rows, q, q, [&](std::size_t r) { return q.val[r] <= q.tol[r]; }, [](std::size_t) { return true; });
    ArcChain trial = c;
    for (std::size_t i = 0; i < c.n; ++i) trial.x[i] = c.x[i] + dz[i] * q.unit[i];
    ArcVec ft{};
    ArcEval et;
    const std::size_t rt = arc_values_forward(pb, trial, ft, et);
    const double n1 = kinematic(ft, rt);
    if (rt != rows || !(n1 < n0)) break;
    c = trial;
    f = ft;
    ev = et;
    n0 = n1;
  }
  return n0 < start;
}

// The multipliers of a solved chain's equations at its minimum (arc_minimise), in z.
struct ArcKkt {
  std::array<double, kMaxArcNodes> lambda{};
  std::size_t rows{0};
};

// arc_minimise stops where its last 8 accepted steps gained less than 1e-12 T together: steps
// that gain only the rounding (docs/fastest.md, "Cost", session 30). At 5 steps grid case 254 at
// scale 7.3 plans 1.691 s (the test's bound 1.6905 s) and the CLI tests' three-mode plan file no
// longer matches (a segment 3.4e-8 s off at the same duration).
constexpr std::size_t kMinimiseStallSteps = 8;
constexpr double kMinimiseStallGain = 1e-12;

// Minimises T over c (solved: F(c) = 0) as above. Returns the chain's multipliers in kkt; c
// changes only to a shorter chain that breaks no condition.
void arc_minimise(const ArcProblem& pb, ArcChain& c, ArcKkt& kkt, int max_iter) noexcept {
  ArcVec f{};
  ArcEval ev;
  ArcMat jm;  // arc_jacobian writes its rows x columns below c.n, all that is read
  std::size_t rows = arc_values(pb, c, f, ev);
  double T = ev.L.T, trust = 0.05 * T;
  // What the last kMinimiseStallSteps accepted steps gained (a ring, `accepted` in all).
  std::array<double, kMinimiseStallSteps> gains{};
  std::size_t accepted = 0;
  for (int it = 0; it < max_iter; ++it) {
    if (accepted >= kMinimiseStallSteps) {
      double gained = 0.0;
      for (std::size_t u = 0; u < kMinimiseStallSteps; ++u) {
        gained += gains[(accepted - 1 - u) % kMinimiseStallSteps];
      }
      if (gained < kMinimiseStallGain * T) return;  // stalled: steps that gain only rounding
    }
    const double t_before = T;
    arc_jacobian(pb, c, ev, jm);
    const ArcIneq q = arc_ineq(pb, c, ev.L);
    std::array<bool, kMaxIneq> active{};
    for (std::size_t r = 0; r < q.count; ++r) active[r] = q.val[r] <= q.tol[r];
    ArcVec d{};
    bool moved = false;
    for (std::size_t release = 0; release <= q.count; ++release) {
      RowBasis basis(c.n);
      for (std::size_t r = 0; r < rows; ++r) {
        ArcVec a{};
        for (std::size_t i = 0; i < c.n; ++i) a[i] = jm[r][i] * q.unit[i];
        basis.add(a);
      }
      std::array<std::size_t, kMaxIneq> which{};
      std::size_t na = 0;
      for (std::size_t r = 0; r < q.count; ++r) {
        if (!active[r]) continue;
        basis.add(q.a[r]);
        which[na++] = r;
      }
      std::array<double, kMaxBasisRows> w{};
      d = basis.project(q.dt, w);
      kkt.rows = rows;
      for (std::size_t r = 0; r < rows; ++r) kkt.lambda[r] = w[r];
      // dT/dz = lambda J + mu A with mu >= 0 at a minimum: release the most negative mu.
      std::size_t worst = q.count;
      double most = -1e-9;
      for (std::size_t s = 0; s < na; ++s) {
        if (w[rows + s] < most) {
          most = w[rows + s];
          worst = which[s];
        }
      }
      if (worst == q.count) break;
      active[worst] = false;
    }
    double dn = 0.0;
    for (std::size_t i = 0; i < c.n; ++i) dn = std::fmax(dn, std::fabs(d[i]));
    if (!(dn > 1e-9)) return;  // stationary: dT/dz is the equations' and active rows' combination
    // The step -d, to the first inactive inequality it meets, within the trust length.
    double a_max = trust / dn;
    for (std::size_t r = 0; r < q.count; ++r) {
      if (active[r]) continue;
      double ad = 0.0;
      for (std::size_t i = 0; i < c.n; ++i) ad -= q.a[r][i] * d[i];
      if (ad < 0.0) a_max = std::fmin(a_max, q.val[r] / -ad);
    }
    ArcFix bound{};  // the velocity's bound the smallest step tried broke
    // The steps of the trials whose restoration was given up (arc_restore's t_abandon) since the
    // last that set `bound`, in the order tried: where no trial is kept, `bound` is the last
    // trial's that restored and broke a velocity's bound, so those are restored in full again,
    // last first, until one sets it (the bound set without giving up).
    std::array<double, 32> given_up{};
    std::size_t n_given_up = 0;
    // The trial at step alpha (the same point where a given-up trial is restored again), and
    // whether a restored trial breaks a velocity's bound.
    const auto trial_at = [&](double alpha) {
      ArcChain t = c;
      for (std::size_t i = 0; i < c.n; ++i) t.x[i] = c.x[i] - alpha * d[i] * q.unit[i];
      return t;
    };
    const auto breaks_speed = [](const ArcFix& fx) {
      return fx.kind == ArcFix::add_cruise || fx.kind == ArcFix::add_dwell;
    };
    for (double alpha = a_max; alpha * dn > 1e-12 * T; alpha *= 0.25) {
      ArcChain trial = trial_at(alpha);
      ArcVec ft{};
      ArcEval et;
      std::size_t rows_t = 0;
      bool abandoned = false;
      const bool may_abandon = n_given_up < given_up.size();
      if (!arc_restore(pb, trial, q, active, ft, et, false, &rows_t, T, may_abandon ? &abandoned : nullptr)) {
        if (abandoned) given_up[n_given_up++] = alpha;
        continue;
      }
      const ArcFix fx = arc_violation(pb, trial);
      if (breaks_speed(fx)) {
        bound = fx;
        n_given_up = 0;
      }
      if (!(et.L.T < T - 1e-14 * T) || fx.kind != ArcFix::none) continue;
      // A peak that reached its limit holds there from now on (a limit node of hold 0).
      bool held = false;
      for (std::size_t i = 0; i < trial.n; ++i) {
        if (trial.node[i].kind == ArcKind::peak && trial.node[i].sign * trial.x[i] >= pb.amax * (1.0 - 1e-12)) {
          trial.node[i].kind = ArcKind::limit;
          trial.x[i] = 0.0;
          held = true;
        }
      }
      c = trial;
      // The restoration's rows are c's where no peak became a hold (the same values as evaluated again).
      if (held) {
        rows = arc_values(pb, c, f, ev);
      } else {
        rows = rows_t;
        f = ft;
        ev = et;
      }
      T = ev.L.T;
      if (alpha * dn >= 0.99 * trust) trust *= 2.0;
      gains[accepted++ % kMinimiseStallSteps] = t_before - T;
      moved = true;
      break;
    }
    for (std::size_t u = n_given_up; !moved && u-- > 0;) {
      ArcChain trial = trial_at(given_up[u]);
      ArcVec ft{};
      ArcEval et;
      if (!arc_restore(pb, trial, q, active, ft, et)) continue;
      const ArcFix fx = arc_violation(pb, trial);
      if (breaks_speed(fx)) {
        bound = fx;
        break;
      }
    }
    if (!moved && bound.kind != ArcFix::none) {
      // The move touches v = 0 (or vmax) where a crosses zero and would pass it: hold there (a
      // dwell or a cruise of length 0, one unknown and one equation more), and go on.
      ArcChain e = c;
      if (!apply_fix(pb, bound, e)) return;
      const ArcIneq qe = arc_ineq(pb, e, lay_out(pb, e));
      const std::array<bool, kMaxIneq> none{};
      ArcVec fe{};
      ArcEval ee;
      if (arc_restore(pb, e, qe, none, fe, ee) && ee.L.T < T * (1.0 + 1e-9) &&
          arc_violation(pb, e).kind == ArcFix::none) {
        c = e;
        rows = arc_values(pb, c, f, ev);
        T = ev.L.T;
        continue;
      }
    }
    if (!moved) {
      trust *= 0.1;
      if (trust < 1e-9 * T) return;
      // c is unchanged, and so are its Jacobian, rows, step d and the bound branch's fix: where
      // a_max was set by an inequality that still binds within the smaller trust, the next
      // iteration tries the same steps, fails the same way and only cuts the trust again. Those
      // iterations are counted and their trust cuts made without running them (8 % of the
      // refinement's evaluations over the grid; every plan the same to the bit).
      while (it + 1 < max_iter && a_max <= trust / dn) {
        ++it;
        trust *= 0.1;
        if (trust < 1e-9 * T) return;
      }
    }
  }
}

// A pair of turns of zero width inserted into c: into ramp k (k == c.n the closing one) at
// `frac` of its rise (a turn of the ramp's sign, one of the other, both at the same level), or
// into the hold of limit node k at `frac` of it (a dip: the hold split, a turn back of zero depth
// between). Writes the chain and the index of the first new unknown; the pair opens as the
// new unknowns move by `open` (in z). False where it does not fit.
bool zero_pair(const ArcProblem& pb, const ArcChain& c, std::size_t k, bool dip, double frac, ArcChain& out,
               std::size_t& first, ArcVec& open) noexcept {
  open = ArcVec{};
  if (!dip) {
    if (!insert_wiggle(pb, c, k, 0.0, out, frac)) return false;
    if (out.node[k].kind != ArcKind::peak || out.node[k + 1].kind != ArcKind::peak) return false;
    first = k;
    open[k] = out.node[k].sign;
    open[k + 1] = -out.node[k].sign;
    return true;
  }
  if (k >= c.n || c.node[k].kind != ArcKind::limit || !(c.x[k] > 0.0)) return false;
  const ArcNode lim = c.node[k];
  const std::array<ArcNode, 3> with{lim, ArcNode{ArcKind::peak, -lim.sign}, lim};
  const std::array<double, 3> x{frac * c.x[k], lim.sign * pb.amax, (1.0 - frac) * c.x[k]};
  if (!splice(c, k, with.data(), x.data(), with.size(), pb.max_nodes, out)) return false;
  first = k + 1;
  open[k + 1] = -lim.sign;
  return true;
}

// The derivative of T with respect to opening the pair (per unit of z), at the multipliers of c.
double pair_gain(const ArcProblem& pb, const ArcChain& e, std::size_t first, const ArcVec& open,
                 const ArcKkt& kkt) noexcept {
  ArcVec f{};
  ArcEval ev;
  ArcMat jm;  // arc_jacobian writes its rows x columns below c.n, all that is read
  const std::size_t rows = arc_values(pb, e, f, ev);
  if (rows != kkt.rows) return 0.0;
  arc_jacobian(pb, e, ev, jm);
  ArcVec dt, unit;
  arc_ineq_dt(pb, e, ev.L, dt, unit);
  double g = 0.0;
  for (std::size_t i = first; i < first + 2 && i < e.n; ++i) {
    if (open[i] == 0.0) continue;
    double r = dt[i];
    for (std::size_t k = 0; k < rows; ++k) r -= kkt.lambda[k] * jm[k][i] * unit[i];
    g += r * open[i];
  }
  return std::isfinite(g) ? g : 0.0;
}

// arc_refine's keep where no search stands behind it: nothing kept, never proven.
struct KeepNone {
  bool operator()(const ArcChain&) const noexcept { return false; }
  double violation(const ArcChain&) const noexcept { return -1.0; }
};

// c shortened by turns inserted where the first-order test says they shorten it (up to `rounds`
// pairs, each the best of the points tried), each chain minimised over its unknowns. True when
// c got shorter. Each chain minimised shorter than the chain it started from (and the first
// minimisation's) goes to `keep`, a candidate move (kept_until_proven): where keep says the
// shortest move so far is proven the shortest of the problem, the refinement stops there, c the
// shortest chain of the round so far (FastestSearch::proven: what follows could only be shorter
// by the proof's rounding). Each round first stops and slows down the cruise where keep's failed
// proof of c locates a negative measure (keep.violation: a slow-down or a stop there is shorter),
// so that a proof comes sooner.
template <class Keep = KeepNone>
bool arc_refine(const ArcProblem& pb, ArcChain& c, int rounds, Keep keep = {}) noexcept {
  constexpr std::array<double, 7> kAt{0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875};
  ArcKkt kkt{};
  const double T0 = lay_out(pb, c).T;
  double w_fast = 0.0;  // the fastest mode's damped frequency: a stop dwells a quarter period of it
  for (std::size_t m = 0; m < pb.ms->n; ++m) w_fast = std::fmax(w_fast, std::fabs(pb.poles[m].s.im));
  const double quarter = 0.25 * two_pi_v<double>() / w_fast;
  arc_minimise(pb, c, kkt, 40);
  if (keep(c)) return lay_out(pb, c).T < T0;
  bool stop = false;
  for (int round = 0; round < rounds && c.n + 2 <= pb.max_nodes; ++round) {
    // The three most negative derivatives over the points tried.
    struct Cand {
      double g{0.0};
      std::size_t k{0};
      bool dip{false};
      double frac{0.0};
    };
    std::array<Cand, 3> top{};
    for (std::size_t k = 0; k <= c.n; ++k) {
      for (const bool dip : {false, true}) {
        for (const double frac : kAt) {
          ArcChain e{};
          std::size_t first = 0;
          ArcVec open{};
          if (!zero_pair(pb, c, k, dip, frac, e, first, open)) continue;
          const double g = pair_gain(pb, e, first, open, kkt);
          for (std::size_t s = 0; s < top.size(); ++s) {
            if (g < top[s].g) {
              for (std::size_t u = top.size() - 1; u > s; --u) top[u] = top[u - 1];
              top[s] = {g, k, dip, frac};
              break;
            }
          }
        }
      }
    }
    const double T = lay_out(pb, c).T;
    ArcChain best = c;
    ArcKkt best_kkt = kkt;
    double t_best = T;
    // Each chain tried is minimised; the shortest is kept.
    const auto minimise_from = [&](ArcChain e) {
      if (stop) return;
      ArcKkt ek{};
      arc_minimise(pb, e, ek, 60);
      const double te = lay_out(pb, e).T;
      if (te < t_best) {
        t_best = te;
        best = e;
        best_kkt = ek;
      }
      if (te < T && keep(e)) stop = true;
    };
    const auto cruise_changes = [&](std::size_t k) {
      for (int kind = 0; kind < 1 + static_cast<int>(kSlowTo.size()); ++kind) {
        if (kind != 0 && (pb.no_slowdown || (pb.one_slowdown && kSlowTo[static_cast<std::size_t>(kind - 1)] != 0.1))) {
          continue;
        }
        ArcChain e{};
        const bool ok = kind == 0 ? insert_stop(pb, c, k, quarter, e)
                                  : insert_slowdown(pb, c, k, kSlowTo[static_cast<std::size_t>(kind - 1)], e);
        if (ok && restore_seed(pb, e)) minimise_from(e);
      }
    };
    std::size_t located = c.n;  // the cruise the proof's violation lies in
    if (c.n + 4 <= pb.max_nodes && !pb.pulse) {
      const double at = keep.violation(c);
      const ArcLayout L = lay_out(pb, c);
      for (std::size_t k = 0; k < c.n && at >= 0.0; ++k) {
        if (c.node[k].kind == ArcKind::cruise && L.e[k] <= at && at <= L.b[k + 1]) located = k;
      }
    }
    if (located < c.n) cruise_changes(located);
    for (const Cand& cd : top) {
      if (!(cd.g < -1e-9)) break;
      ArcChain e{};
      std::size_t first = 0;
      ArcVec open{};
      if (zero_pair(pb, c, cd.k, cd.dip, cd.frac, e, first, open)) minimise_from(e);
    }
    // and pairs of finite size where the test cannot see them: a stop or a slow-down inside a
    // cruise (the velocity's bound makes their first-order effect vanish at zero size).
    for (std::size_t k = 0; k < c.n && c.n + 4 <= pb.max_nodes; ++k) {
      if (c.node[k].kind == ArcKind::cruise && k != located) cruise_changes(k);
    }
    if (stop) {
      if (t_best < T) c = best;
      break;
    }
    if (!(t_best < T * (1.0 - 1e-12))) break;
    c = best;
    kkt = best_kkt;
  }
  return lay_out(pb, c).T < T0;
}

}  // namespace

namespace {

// Where the move is made to vanish: for every mode, the transform (and its derivatives up to
// `order`) at the poles of omega (1 + spread x_i), x_i evenly spread over [-1, 1] (one point: at
// omega itself). Non-robust: one zero of order 0. Robust: multiple zeros (derivatives, Singh &
// Vadali) or zeros spread over the band (EI-like), whichever is shortest and holds the band.
struct ZeroSet {
  int points{1};
  double spread{0.0};
  int order{0};
  // humps > 0: the zeros of the two- or three-hump EI shaper designed for each mode (points =
  // humps + 1), relative to the mode's omega.
  int humps{0};
  std::array<std::array<double, 4>, kMaxModes> rel{};
};

double zero_frequency(const ZeroSet& z, std::size_t m, double omega, int i) noexcept {
  if (z.humps > 0) return omega * z.rel[m][static_cast<std::size_t>(i)];
  if (z.points == 1) return omega;
  return omega * (1.0 + z.spread * (-1.0 + 2.0 * i / (z.points - 1)));
}

std::size_t zero_conditions(const ZeroSet& z, const ModeSet& ms, std::array<Condition, kMaxConds>& cond) noexcept {
  std::size_t nc = 0;
  for (std::size_t m = 0; m < ms.n; ++m) {
    for (int i = 0; i < z.points; ++i) {
      const double w = zero_frequency(z, m, ms.m[m].omega, i);
      for (int q = 0; q <= z.order; ++q) {
        if (nc >= kMaxConds) return kMaxConds + 1;
        cond[nc++] = {pole(w, ms.m[m].zeta), w, q};
      }
    }
  }
  return nc;
}

// The zero set of the two- or three-hump EI shaper of every mode, and that shaper composed over
// the modes. False where a mode has no such design.
bool hump_zero_set(int humps, const ModeSet& ms, ZeroSet& z, Shaper<double>& shaper) noexcept {
  ZeroSet set{};
  set.humps = humps;
  set.points = humps + 1;
  Shaper<double> s{};
  for (std::size_t m = 0; m < ms.n; ++m) {
    Shaper<double> one{}, both{};
    if (multi_hump_ei_shaper(static_cast<std::size_t>(humps), ms.m[m].omega, ms.m[m].zeta, 0.05, one,
                             set.rel[m].data()) != Status::ok ||
        compose(s, one, both) != Status::ok) {
      return false;
    }
    s = both;
  }
  z = set;
  shaper = s;
  return true;
}

// The shaper with the same zeros: ZV / ZVD / ZVDD at each point, composed over points and modes,
// or for a hump set the multi-hump EI shaper of each mode (hump_zero_set designs it).
bool zero_shaper(const ZeroSet& z, const ModeSet& ms, Shaper<double>& out) noexcept {
  constexpr ShaperKind kByOrder[] = {ShaperKind::zv, ShaperKind::zvd, ShaperKind::zvdd};
  if (z.order < 0 || z.order > 2) return false;
  if (z.humps > 0) {
    ZeroSet same{};
    return z.order == 0 && hump_zero_set(z.humps, ms, same, out);
  }
  Shaper<double> s{};
  for (std::size_t m = 0; m < ms.n; ++m) {
    for (int i = 0; i < z.points; ++i) {
      Shaper<double> one{}, both{};
      if (design_shaper(kByOrder[z.order], zero_frequency(z, m, ms.m[m].omega, i), ms.m[m].zeta, 0.05, one) !=
              Status::ok ||
          compose(s, one, both) != Status::ok) {
        return false;
      }
      s = both;
    }
  }
  out = s;
  return true;
}

// The search over the families: the request as read, the time-optimal move, and the shortest
// candidate so far (with every family's own shortest time). plan_fastest runs its stages in order.
struct FastestSearch {
  const MoveRequest& r;
  // The certificates of r's problem: record's, KeptUntilProven::violation's and plan_arcs'. Held
  // apart (plan_unsigned's): a member, it was zeroed with the search (6.3 KB; 14 k instructions).
  CertMemo& certs;
  ModeSet ms{};
  double band{0.0};
  Limits lim{};
  PiecewiseJerkParams to{};  // the time-optimal move
  double t_to{0.0};
  Best best{};
  std::array<double, kFastestFamilies> times{};
  Shaper<double> joint{};  // the joint ZV shaper of several modes, when has_joint
  bool has_joint{false};
  std::array<ZeroSet, 11> sets{};  // the zero sets bang-coast solves for
  std::size_t nsets{0};
  DipBest dips{};  // bang-bang's chains from the dip seeds, considered last
  ArcBest chains{};  // bang-bang's shortest chains (before the dips, and each late stage's)
  bool arcs_best{false};  // bang-bang's chain is the shortest move so far (bang_coast_family)
  // proven: the shortest move so far is proven the shortest of the problem (by plan_arcs, or with
  // stop_proven, the refined chains, by record's check of each new shortest jerk-table move), and
  // the search stops.
  bool stop_proven{false}, proven{false};

  void record(FastestFamily f, const FastestParams& p, const Peaks<double>& pk, double t) noexcept {
    double& slot = times[static_cast<std::size_t>(f)];
    if (slot == 0.0 || t < slot) slot = t;
    const double before = best.time;
    consider(best, p, pk, t);
    if (stop_proven && best.time < before && !is_ramp_cycloid(best.p.family)) {
      proven = certs(best.p.table, r).proof == FastestProof::proven;
    }
  }
  void record_table(FastestFamily f, const FastestTable& t, const Peaks<double>& pk) noexcept {
    FastestParams p{};
    p.family = f;
    p.table = t;
    record(f, p, pk, table_duration(t));
  }
  void try_shaped(const Shaper<double>& s, FastestFamily fam) noexcept {
    FastestTable t{};
    if (!flatten_shaped(to, s, t)) return;
    Peaks<double> pk{};
    if (!table_ok(t, lim, ms, band, pk)) return;
    record_table(fam, t, pk);
  }
};

// The request's checks and what the search reads from it (modes, band, limits).
Status read_fastest_request(const MoveRequest& r, FastestSearch& fs) noexcept {
  if (!r.limits.vmax || !r.limits.amax || !r.limits.jmax) return Status::missing_time_or_limits;
  if (r.time) return Status::unsupported_request;  // the fastest move has no requested time
  const Status st = read_modes(r, fs.ms);
  if (st != Status::ok) return st;
  if (r.robust) {
    if (!std::isfinite(*r.robust)) return Status::non_finite_input;
    if (!(*r.robust > 0.0 && *r.robust <= 50.0)) return Status::bad_shape_parameter;
    fs.band = *r.robust / 100.0;
  }
  fs.lim = {*r.limits.vmax, *r.limits.amax, *r.limits.jmax};
  return Status::ok;
}

// (c) the time-optimal move convolved with ZV / ZVD / ZVDD / EI, one shaper per mode.
void shaped_families(FastestSearch& fs) noexcept {
  const ModeSet& ms = fs.ms;
  const double band = fs.band;
  constexpr ShaperKind kShapers[] = {ShaperKind::zv, ShaperKind::zvd, ShaperKind::zvdd, ShaperKind::ei};
  constexpr FastestFamily kShaped[] = {FastestFamily::shaped_zv, FastestFamily::shaped_zvd, FastestFamily::shaped_zvdd,
                                       FastestFamily::shaped_ei};
  for (std::size_t k = 0; k < 4; ++k) {
    // EI leaves its tolerance (5 %) at the design frequency: never an exact design, and its
    // damped design is iterative (about 25 us), so it is only tried for --robust.
    if (kShapers[k] == ShaperKind::ei && band == 0.0) continue;
    Shaper<double> s{};
    bool ok = true;
    for (std::size_t i = 0; i < ms.n && ok; ++i) {
      Shaper<double> one{}, both{};
      ok = design_shaper(kShapers[k], ms.m[i].omega, ms.m[i].zeta, 0.05, one) == Status::ok &&
           compose(s, one, both) == Status::ok;
      if (ok) s = both;
    }
    if (ok) fs.try_shaped(s, kShaped[k]);
  }
  // (c') two or more modes: one ZV designed for all of them at once. Its n + 1 impulses (one ZV
  // per mode takes 2^n) are often shorter, and for three modes the only shaped move that fits
  // the table; it also seeds bang-coast below as the best move so far.
  if (ms.n >= 2 && ms.n <= kMaxJointModes && band == 0.0) {
    std::array<double, kMaxJointModes> w{}, z{};
    for (std::size_t i = 0; i < ms.n; ++i) {
      w[i] = ms.m[i].omega;
      z[i] = ms.m[i].zeta;
    }
    fs.has_joint = joint_zv_shaper(w.data(), z.data(), ms.n, fs.joint) == Status::ok;
    if (fs.has_joint) fs.try_shaped(fs.joint, FastestFamily::shaped_joint_zv);
  }

}

// (b) the ramp-cycloid S-curves: one mode, exact at its design (not robust designs).
void scurve_families(FastestSearch& fs) noexcept {
  const ModeSet& ms = fs.ms;
  const Limits& l = fs.lim;
  if (ms.n == 1 && fs.band == 0.0) {
    const bool damped = ms.m[0].zeta > 0.0;
    FastestParams p{};
    if (plan_fastest_scurve(fs.r.distance, l.vmax, l.amax, l.jmax, ms.m[0].omega, ms.m[0].zeta, damped, p.curve) ==
        Status::ok) {
      p.family = damped ? FastestFamily::scurve_damped : FastestFamily::scurve;
      const Peaks<double> pk = ramp_cycloid_peaks(p.curve);
      if (within_limits(pk, l) && !runs_backwards(p.curve)) {
        fs.record(p.family, p, pk, Fastest<double>{p}.duration());
      }
    }
  }
}

// Robust: the zero sets to try, and (c) once more with the shapers of the spread zero sets
// (ZV at omega (1 +- spread)).
void zero_sets(FastestSearch& fs) noexcept {
  const ModeSet& ms = fs.ms;
  const double band = fs.band;
  std::array<ZeroSet, 11>& sets = fs.sets;
  std::size_t& nsets = fs.nsets;
  if (band == 0.0) {
    sets[nsets++] = {1, 0.0, 0};
  } else {
    sets[nsets++] = {1, 0.0, 1};
    sets[nsets++] = {1, 0.0, 2};
    for (double f : {0.5, 0.7, 0.9}) sets[nsets++] = {2, f * band, 0};
    for (double f : {0.7, 0.9}) sets[nsets++] = {3, f * band, 0};
    sets[nsets++] = {2, 0.8 * band, 1};
    sets[nsets++] = {1, 0.0, 0};
    for (std::size_t k = 0; k < nsets; ++k) {
      Shaper<double> s{};
      if (sets[k].points > 1 && zero_shaper(sets[k], ms, s)) fs.try_shaped(s, FastestFamily::shaped_spread);
    }
    // The two- and three-hump EI shapers hold the widest bands (about +-36 % and +-48 % of an
    // undamped mode at 5 %): shaped moves, and zero sets whose pulse seeds fit the table where
    // the spread sets' do not (docs/fastest.md, "--robust PCT").
    for (const int humps : {2, 3}) {
      Shaper<double> s{};
      if (!hump_zero_set(humps, ms, sets[nsets], s)) continue;
      fs.try_shaped(s, humps == 2 ? FastestFamily::shaped_ei2 : FastestFamily::shaped_ei3);
      ++nsets;
    }
  }
}

// (a) bang-bang with limit arcs (exact designs): when it beats the families above, the
// bang-coast search below is not made (it is a local search from seeds, and slow), unless the
// fastest mode rings more than three periods over the move. The switching function then has
// more zeros than the 2 + 2m nodes of a chain hold, the shortest move may switch more often,
// and bang-coast's coasts can follow it (without this rule its shorter moves were lost in 4
// cases of docs/fastest.md's grids, by up to 10 %).
bool bang_bang_family(FastestSearch& fs) noexcept {
  const ModeSet& ms = fs.ms;
  bool arcs_won = false;
  if (fs.band == 0.0) {
    FastestTable t{};
    Peaks<double> pk{};
    // The split seed follows the joint ZV shaper (designed above for several modes) or ZV.
    Shaper<double> zv{};
    const Shaper<double>* split = fs.has_joint ? &fs.joint : ms.n == 1 && split_shaper(ms, zv) ? &zv : nullptr;
    // The chains from the dip seeds are candidates after bang-coast (fs.dips): whether
    // bang-coast runs, and what it starts from, are as without them (where bang-coast ran, it
    // started from the dip chain and ended 0.016 % longer on a grid case).
    ArcProbeRoom aside;
    const bool found = plan_arcs(fs.r, ms, t, pk, &fs.chains, split, &fs.dips,
                                 {.request = true, .stop_proven = true, .probe = true}, &fs.certs, &aside);
    if (found && table_duration(t) < fs.best.time) {
      fs.record_table(FastestFamily::bang_bang, t, pk);
      double w_max = 0.0;
      for (std::size_t i = 0; i < ms.n; ++i) w_max = std::fmax(w_max, ms.m[i].omega);
      arcs_won = w_max * table_duration(t) <= 3.0 * two_pi_v<double>();
      fs.arcs_best = true;
    }
  }
  return arcs_won;
}

// (a') bang-coast switch times under the zero conditions, in both forms (mirrored pulse, whole
// move), seeded from the time-optimal move (or its pulse) convolved with the shaper of the
// same zeros and the next order.
//
// After a bang-bang chain that is the shortest move so far (it rings three periods or more of
// the fastest mode, bang_bang_family), only the whole form from that move is searched: its
// coasts refine the chain's move where the switching function has more zeros than the chain's
// nodes. The shaped seeds and the pulse form were not what won there: over the 300 plans of the
// reference grid and the 1387 of the Fastest* tests, without them every duration, family and
// family time is the same to the bit (session 25), and the commissioning request pays 38 % fewer
// instructions (78.5 M -> 48.5 M). Dropping bang-coast there altogether lengthens one test plan
// (Fastest.BangCoastStillRefinesALongRingingChain).
void bang_coast_family(FastestSearch& fs) noexcept {
  const MoveRequest& r = fs.r;
  const ModeSet& ms = fs.ms;
  const double band = fs.band, t_to = fs.t_to;
  const Best& best = fs.best;
  const PiecewiseJerkParams h = accel_pulse(fs.to);
  for (std::size_t k = 0; k < fs.nsets; ++k) {
    const ZeroSet& z = fs.sets[k];
    std::array<Condition, kMaxConds> cond{};
    const std::size_t nc = zero_conditions(z, ms, cond);
    if (nc > kMaxConds) continue;
    const double t_cap = std::isfinite(best.time) ? best.time : 4.0 * t_to + 8.0 * 3.14159 / ms.m[0].omega;
    std::array<Seed, 3> pulses{};
    std::array<Seed, 3> whole{};
    std::size_t ns = 0, nw = 0;
    for (int extra = 0; extra <= 1 && !fs.arcs_best; ++extra) {
      ZeroSet zs = z;
      zs.order += extra;
      Shaper<double> s{};
      if (!zero_shaper(zs, ms, s)) continue;
      if (flatten_shaped(h, s, pulses[ns].g)) {
        pulses[ns].time = t_to + s.duration();
        ++ns;
      }
      if (flatten_shaped(fs.to, s, whole[nw].g)) {
        whole[nw].time = table_duration(whole[nw].g);
        ++nw;
      }
    }
    // for three modes or more, the pulse convolved with the joint ZV shaper (exact designs),
    // where the convolved shapers above do not fit (on two modes it lengthened a case: bang-coast
    // ended elsewhere from the shorter bound it set, docs/fastest.md "Several modes"),
    if (!fs.arcs_best && fs.has_joint && ms.n >= 3 && z.points == 1 && z.order == 0 &&
        flatten_shaped(h, fs.joint, pulses[ns].g)) {
      pulses[ns].time = t_to + fs.joint.duration();
      ++ns;
    }
    // and from the shortest jerk-table move so far (its zeros lie near these).
    if (std::isfinite(best.time) && !is_ramp_cycloid(best.p.family)) {
      whole[nw].g = best.p.table;
      whole[nw].time = best.time;
      ++nw;
    }
    FastestTable p{};
    Peaks<double> pk{};
    if (!fs.arcs_best && plan_pattern(r, ms, true, cond, nc, pulses.data(), ns, t_to, t_cap, band, p, pk)) {
      fs.record_table(FastestFamily::bang_coast, p, pk);
    }
    if (plan_pattern(r, ms, false, cond, nc, whole.data(), nw, t_to, std::isfinite(best.time) ? best.time : t_cap,
                     band, p, pk)) {
      fs.record_table(FastestFamily::bang_coast, p, pk);
    }
  }
}

// How far a table's move runs backwards in all (the sum over its segments of the lowest
// velocity against sign(D) times the segment's length, where negative): an upper bound.
double backwards_travel(const FastestTable& p) noexcept {
  const double sg = p.distance < 0.0 ? -1.0 : 1.0;
  double v = 0.0, a = 0.0, back = 0.0;
  for (std::size_t i = 0; i < p.count; ++i) {
    const double d = p.durations[i], j = p.jerk[i];
    double lo = sg * v;
    if (j != 0.0) {
      const double u = -a / j;
      if (u > 0.0 && u < d) lo = std::fmin(lo, sg * (v + a * u + j * u * u / 2.0));
    }
    v += d * (a + j * d / 2.0);
    a += j * d;
    lo = std::fmin(lo, sg * v);
    if (lo < 0.0) back -= lo * d;
  }
  return back;
}

// A refined chain where it is a move (its table checked like every other) and kept by rounding
// (refined_chains below).
void keep_refined(FastestSearch& fs, const ArcProblem& pb, const ArcChain& c) noexcept {
  const FastestTable t = arc_table(pb, c, fs.r.distance);
  Peaks<double> pk{};
  // The chain's rows hold to rounding (a dwell's v = 0 to about 1e-13 vmax), and the table's
  // accelerations return to 0 to the rounding of their sums (about 1e-14 amax): a move whose
  // velocity dips below zero by rounding for longer than that allows (over its segments, at most
  // 1e-12 D backwards, the bound the tests check between two samples) is not kept. (5e-13 D until
  // the split chains: grid case 160's, 0.48 % shorter, runs back 5.1e-13 D over its dwells at
  // v = -3.6e-13 m/s, the rounding of its table's sums where vmax is 8.4 m/s.)
  if (t.count != 0 && table_ok(t, fs.lim, fs.ms, 0.0, pk) && !(backwards_travel(t) > 1e-12 * pb.D)) {
    fs.record_table(FastestFamily::bang_bang, t, pk);
  }
}

// The length d of a ramp of jerk j from a that ends at a + j d = 0 exactly, or, where no double d
// does, nearest 0 (of the few ulps tried each way). A step of d by one ulp can move j d by more
// than one ulp of a, so that j d skips -a: on grid case 263 (three modes, jmax 1481) a ramp from
// -14.45 m/s^2 of 9.8 ms ends at -1.8e-15 or +1.8e-15 (an ulp of a either side), never at 0.
double ramp_to_rest(double a, double j) noexcept {
  double d = -a / j, best = d;
  for (int k = 0; k < 8 && a + j * d != 0.0; ++k) {
    d = std::nextafter(d, (a + j * d > 0.0) == (j > 0.0) ? 0.0 : HUGE_VAL);
    if (std::fabs(a + j * d) < std::fabs(a + j * best)) best = d;
  }
  return best;
}

// A table's holds at a = 0 (a dwell, a cruise: a zero-jerk segment after a ramp that ends within
// 1e-9 amax of 0) made to hold at exactly 0: the ramp into each is lengthened or shortened by the
// ulps that make its sum a + j d exactly 0 (or an ulp of a from it, ramp_to_rest: over 0.39 s of
// dwell 1.8e-15 m/s^2 runs back 1.3e-16 m, 1.5e-14 D on 263). The table's acceleration is a sum
// over its segments, rounded to about 1e-13 of amax, and on a long dwell that runs the axis back:
// on grid case 265 (two modes, D 1.6 mm, amax 150, a 2.2 s dwell) a = 2.7e-13 runs back 6.7e-12 D.
// False when a ramp's length comes out 0 or less.
bool rests_exact(FastestTable& t, double amax) noexcept {
  double a = 0.0;
  for (std::size_t i = 0; i < t.count; ++i) {
    t.accel0[i] = a;
    const double next = a + t.jerk[i] * t.durations[i];
    if (i + 1 < t.count && t.jerk[i] != 0.0 && t.jerk[i + 1] == 0.0 && next != 0.0 &&
        std::fabs(next) <= 1e-9 * amax) {
      const double d = ramp_to_rest(a, t.jerk[i]);
      if (!(d > 0.0)) return false;
      t.durations[i] = d;
    }
    a += t.jerk[i] * t.durations[i];
  }
  return true;
}

// The chain (whole form) as a table whose segments are its own lengths, each ramp
// (level - level before) / j, each hold its x: the segments arc_values_forward integrates
// (arc_table's are differences of the switch times, each rounded to about eps T).
FastestTable arc_table_direct(const ArcProblem& pb, const ArcChain& c, double distance) noexcept {
  if (pb.pulse) return FastestTable{};
  const double sg = distance < 0.0 ? -1.0 : 1.0;
  FastestTable t{};
  t.distance = distance;
  double a = 0.0;
  for (std::size_t r = 0; r <= c.n; ++r) {
    const bool closing = r == c.n;
    const double s = closing ? ramp_out(c.node[c.n - 1]) : ramp_in(c.node[r]);
    const double lev = closing ? 0.0 : node_level(pb, c, r);
    const double hold = closing || c.node[r].kind == ArcKind::peak ? 0.0 : c.x[r];
    if (!push_segment(t, (lev - a) / (s * pb.J), sg * s * pb.J) || !push_segment(t, hold, 0.0)) return FastestTable{};
    a = lev;
  }
  return t;
}

// keep_refined, and where the chain's table runs back over its bound, the chain's v and p
// polished to the table's own sums (arc_polish), laid out of its own lengths (arc_table_direct)
// with its holds at a = 0 exact (rests_exact), and kept where that table passes. A chain solved
// to arc_values' rounding holds each dwell at v = 0 and a = 0 only to about 1e-13 of vmax and
// amax, and over a long dwell that runs back more than the bound allows: grid case 184 (two
// modes, 1.05 rad/s and 19.3 rad/s; dwells of 1.5 s and 0.2 s): split_refined's chain, 1.0 %
// shorter than its move, ran back 1.44e-12 D in all and was refused; 265 (below,
// split_to_rounding) 6.7e-12 D. Where that table still fails, the chain is polished again with
// the modes' rows too (arc_polish's `modes`): grid case 121's chain, minimised to its rows'
// rounding (2e-8, cruise_stops_refined), left the modes 1.5e-8 D from rest polished in v and p
// alone (design_ok: 1e-10 D) at scale 0.37 (at 1 and 7.3 it passed; at 7.3 not while the
// restorations stalled at the floor each time); polished in every row, 1.6e-16 D. Only where the
// first polish's table fails: every table kept before is kept alike.
void keep_or_polish(FastestSearch& fs, const ArcProblem& pb, const ArcChain& c) noexcept {
  FastestTable t = arc_table(pb, c, fs.r.distance);
  if (t.count == 0 || !(backwards_travel(t) > 1e-12 * pb.D)) {
    keep_refined(fs, pb, c);
    return;
  }
  for (const bool modes : {false, true}) {
    ArcChain e = c;
    (void)arc_polish(pb, e, modes);
    if (arc_violation(pb, e).kind != ArcFix::none) return;
    t = arc_table_direct(pb, e, fs.r.distance);
    Peaks<double> pk{};
    if (t.count != 0 && rests_exact(t, pb.amax) && table_ok(t, fs.lim, fs.ms, 0.0, pk) &&
        !(backwards_travel(t) > 1e-12 * pb.D)) {
      fs.record_table(FastestFamily::bang_bang, t, pk);
      return;
    }
  }
}

// arc_refine's keep for the refinement of bang-bang's chains (refined_chains) and for
// zero_holds_to_peaks': each chain it minimises is a candidate (keep_or_polish), and the
// refinement stops where the shortest move so far is proven. The first chain of a refinement that
// is the shortest move so far, not proven, and holds a limit node for no time (which the proof
// cannot model) is tried once with those nodes made peaks and minimised (zero_holds_to_peaks'
// change, without its round), and kept only where that proves it. Grid case 237's proof came only
// from zero_holds_to_peaks after arc_refine's three rounds; its second round's first chain (a
// slow-down in the cruise the proof located) with its two turns held for no time made peaks proves
// 1.5625169715 s, 4e-11 s from the plan before. Over the grid's 300 plans (a throw-away counting
// build), evaluations of a chain's system 3.31 M -> 3.12 M (237 121 k -> 44 k, 1 67 k -> 29 k, 28
// 37 k -> 19 k, 170 48 k -> 35 k; 8 and 200 up to 6 % more: a try that proves nothing); 19 proven
// now, 5.7e-9 s shorter; every other plan the same within 1e-9. Handed to every search that refines
// (the split chains, the spliced seeds, dwell_passes' rounds: 3.01 M), grid case 224 stopped in
// dwell_pulse_refined's refinement at a chain the planner proves and tools/fastest-certificate does
// not (a jump at a dwell's end of -3.2e-7 against its -1e-7), where it went on to one 4e-12 shorter
// that both prove. Tried at every such chain, not once: 184 20 k -> 31 k for nothing; kept where
// not proven: 8, 86, 137 and 200 shorter, but the scaled plans off by more than 1e-9 31 (29).
// c's limit nodes held for no time (1e-12 of the move) made peaks at the same level: true when
// there was one (zero_holds_to_peaks, KeptUntilProven).
bool held_for_no_time_to_peaks(const ArcProblem& pb, ArcChain& c) noexcept {
  const double T = lay_out(pb, c).T;
  bool any = false;
  for (std::size_t k = 0; k < c.n; ++k) {
    if (c.node[k].kind != ArcKind::limit || !(c.x[k] <= 1e-12 * T)) continue;
    c.node[k].kind = ArcKind::peak;
    c.x[k] = c.node[k].sign * pb.amax;
    any = true;
  }
  return any;
}

struct KeptUntilProven {
  FastestSearch& fs;
  const ArcProblem& pb;
  bool peaks_tried{false};
  bool operator()(const ArcChain& e) noexcept {
    const double before = fs.best.time;
    keep_or_polish(fs, pb, e);
    if (fs.proven || !(fs.best.time < before) || peaks_tried) return fs.proven;
    ArcChain z = e;
    if (!held_for_no_time_to_peaks(pb, z)) return false;
    peaks_tried = true;
    if (!restore_seed(pb, z)) return false;
    ArcKkt kkt{};
    arc_minimise(pb, z, kkt, 40);
    const Best best = fs.best;
    const auto times = fs.times;
    keep_or_polish(fs, pb, z);
    if (!fs.proven) {
      fs.best = best;
      fs.times = times;
    }
    return fs.proven;
  }
  // Where the proof of c fails on a negative measure (a slow-down or a stop there is shorter):
  // its time in the move; -1 otherwise. Ordered so on 237 the located cruise's slow-down proves the
  // move before the other cruise's are minimised (64.9 k evaluations without the order, 44.0 k).
  double violation(const ArcChain& c) const noexcept {
    const FastestTable t = arc_table(pb, c, fs.r.distance);
    if (t.count == 0) return -1.0;
    const FastestCertificate ce = fs.certs(t, fs.r);
    return ce.proof == FastestProof::negative_measure ? ce.at : -1.0;
  }
};
KeptUntilProven kept_until_proven(FastestSearch& fs, const ArcProblem& pb) noexcept { return {fs, pb, false}; }

// A one-mode chain with a blip in a hold (a limit node, a short turn of the other sign, the limit
// again) with the blip moved to either end of the hold and restored to the chain's equations (a
// square chain: nothing left to minimise; the grid's durations are the same with arc_minimise
// after). The equations have several solutions over the same nodes: on grid case 231 (one mode,
// +amax, -amax, +amax, -amax) bang-bang's chain puts the short +amax hold mid-way through the
// -amax hold (0.51 s and 0.61 s on either side, 0.29 % over the reference), the reference right
// after the +amax hold (0.047 s, then 1.07 s), where its move is 0.30 % shorter. Seeded at 5 % and
// 95 % of the hold; a candidate only where shorter (keep_refined, then record).
void blip_moved(FastestSearch& fs, const ArcProblem& pb, const ArcChain& c) noexcept {
  constexpr std::array<double, 2> kAt{0.05, 0.95};
  for (std::size_t i = 0; i + 2 < c.n; ++i) {
    const ArcNode& a = c.node[i];
    const ArcNode& b = c.node[i + 1];
    const ArcNode& d = c.node[i + 2];
    if (a.kind != ArcKind::limit || d.kind != ArcKind::limit || a.sign != d.sign || b.sign != -a.sign ||
        (b.kind != ArcKind::limit && b.kind != ArcKind::peak)) {
      continue;
    }
    const double hold = c.x[i] + c.x[i + 2];
    for (const double f : kAt) {
      ArcChain e = c;
      e.x[i] = f * hold;
      e.x[i + 2] = (1.0 - f) * hold;
      if (!fs.proven && restore_seed(pb, e)) keep_or_polish(fs, pb, e);
    }
  }
}

// Split chains with more parts than a square chain holds, minimised (arc_refine). With m modes
// split_chain's m + 1 parts (ZV, joint ZV) make a square chain, which plan_arcs solves; the
// reference's shortest moves on short moves over slow modes sometimes have more (grid case 256,
// two modes: four pulses with dwells between them, where the square chain has three). Seeded with
// the move split at the impulses of ZV for one mode convolved with ZV for another (four parts, 11
// nodes: 2 unknowns more than equations for two modes, square for three, whose third mode's
// conditions the restoration meets), for each pair of modes; restored to the chain's equations,
// then minimised with turns inserted where the first-order test says.
void split_refined(FastestSearch& fs, ArcProblem& pb) noexcept {
  pb.pulse = false;
  for (std::size_t m0 = 0; m0 < fs.ms.n; ++m0) {
    for (std::size_t m1 = m0 + 1; m1 < fs.ms.n && !fs.proven; ++m1) {
      Shaper<double> z0{}, z1{}, s{};
      if (design_shaper(ShaperKind::zv, fs.ms.m[m0].omega, fs.ms.m[m0].zeta, 0.05, z0) != Status::ok ||
          design_shaper(ShaperKind::zv, fs.ms.m[m1].omega, fs.ms.m[m1].zeta, 0.05, z1) != Status::ok ||
          compose(z0, z1, s) != Status::ok) {
        continue;
      }
      ArcChain c{};
      if (!split_chain(pb, s, c)) continue;
      if (!restore_seed(pb, c)) continue;
      arc_refine(pb, c, 3);
      keep_or_polish(fs, pb, c);
    }
  }
}

// The move split at the joint ZV shaper's impulses (split_chain, as plan_arcs seeds it), solved
// to the rounding of its rows rather than to 1e-10, changed where it breaks a condition as
// plan_arcs' paths are, then refined (arc_refine). Short moves over slow modes sum ramps of size
// jmax T^3 to a distance many orders smaller: on grid cases 34 and 265 (two modes, D 1.3 and
// 1.6 mm, moves of 2 s and 3.8 s) the rows of p and v at the end round to about 4e-10 of D, so
// Newton's method stalls there, the chain counted as not solved, and no bang-bang chain was
// left: the move was time-optimal * joint ZV, 0.28 % and 0.28 % over the reference, where the
// split chain solved to its rounding is 0.013 % and 0.019 % under it. Only where bang-bang found
// no chain for all the modes (accepting such stalls in every path of plan_arcs changed other
// paths: a three-mode grid case 1.3e-7 longer).
void split_to_rounding(FastestSearch& fs, ArcProblem& pb) noexcept {
  ArcChain c{};
  if (!fs.has_joint || !split_chain(pb, fs.joint, c)) return;
  pb.pulse = false;
  pb.to_rounding = true;
  bool solved = false;
  for (int round = 0; round < 16 && !solved; ++round) {
    if (!arc_solve(pb, c)) break;
    const ArcFix fx = arc_violation(pb, c);
    solved = fx.kind == ArcFix::none;
    if (!solved && !apply_fix(pb, fx, c)) break;
  }
  pb.to_rounding = false;
  if (!solved) return;
  keep_or_polish(fs, pb, c);
  if (!fs.proven && arc_refine(pb, c, 3)) keep_or_polish(fs, pb, c);
}

// Two modes (exact designs): the move split at ZV of the slower mode (split_chain: two rigid parts
// and a dwell, the slower mode's own chain) with two blips across to the other limit in each hold
// next to the dwell (at a sixth and five sixths of it), restored to the chain's equations and
// refined (arc_refine). The reference's move on grid case 184 (1.05 rad/s and 19.3 rad/s, D 1.53
// m; a 1.8 s dwell) is that: +amax, then -amax broken by two blips, the dwell, +amax broken by two
// blips, -amax (12 turns and a dwell: six unknowns more than equations). The wiggles of plan_arcs
// insert one pair into the slower mode's chain (a square chain), and split_refined's chain keeps
// three parts: 1.57 % and 0.53 % over; this chain reaches it (0.07 % under).
void blips_refined(FastestSearch& fs, ArcProblem& pb) noexcept {
  if (fs.ms.n != 2 || fs.band != 0.0) return;
  const std::size_t slow = fs.ms.m[0].omega < fs.ms.m[1].omega ? 0 : 1;
  Shaper<double> zv{};
  if (design_shaper(ShaperKind::zv, fs.ms.m[slow].omega, fs.ms.m[slow].zeta, 0.05, zv) != Status::ok) return;
  pb.pulse = false;
  ArcChain c{};
  if (!split_chain(pb, zv, c)) return;
  for (std::size_t k = c.n; k-- > 0;) {
    const ArcNode lim = c.node[k];
    const bool by_dwell = (k + 1 < c.n && c.node[k + 1].kind == ArcKind::dwell) ||
                          (k > 0 && c.node[k - 1].kind == ArcKind::dwell);
    if (lim.kind != ArcKind::limit || !by_dwell || !(c.x[k] > 0.0)) continue;
    const ArcNode other{ArcKind::limit, -lim.sign};
    const std::array<ArcNode, 5> with{lim, other, lim, other, lim};
    const double h = c.x[k];
    const std::array<double, 5> x{h / 6.0, 0.0, 2.0 * h / 3.0, 0.0, h / 6.0};
    ArcChain e{};
    if (!splice(c, k, with.data(), x.data(), with.size(), pb.max_nodes, e)) return;
    c = e;
  }
  // Refined only where the restored seed is already shorter than the shortest move so far
  // (184: 4.0510 s against 4.0741 s): on 81 of the grid's 100 two-mode cases the seed lies within
  // 5 % of it, and refining each cost the two-mode grid 10 % to 28 % more planning time.
  if (lay_out(pb, c).T > 1.05 * fs.best.time || !restore_seed(pb, c) || !(lay_out(pb, c).T < fs.best.time)) return;
  arc_refine(pb, c, 3);
  keep_or_polish(fs, pb, c);
}

// Two modes, a long cruise (four periods of the slower mode or more): the rigid move that stops
// and starts again three times before the end, each time for a sixth of the faster mode's damped
// period, the three parts after the first cruising three quarters of the slower mode's period, half
// the faster's and a sixth of it (four parts, three dwells: 15 nodes, two unknowns more than
// equations), restored to the chain's equations and minimised (arc_refine; the chain is full,
// nothing is inserted). With the rigid start, whose ringing the
// cruise leaves to decay, the stops are a stop shaped at the velocity's bounds (v = vmax or 0
// between the turns: the unity-magnitude shaper's form, shorter than a staircase), and the
// reference's move on grid case 121 (3.58 / 7.94 rad/s; D 5.62 m, vmax 0.109, a 51.6 s cruise)
// has that form: its end stops, restarts and stops again over its last 2.4 s, 52.122 s in all,
// where time-optimal * joint ZV took 52.694 s; the chain refines to 52.0286 s (cruises 49.60,
// 1.436, 0.387, 0.107 s; dwells 0.158, 0.082, 0.201 s). Seeded at half the slower mode's period
// instead, the seed sits on the edge of that minimum: it refined to it or, its first dwell closed,
// to 52.047 s, as its last bits fell; at three quarters, 16 seeds with each value moved by up to
// 15 % all refined to 52.0286 s (restorations then stalling at the floor each time). Its rows of
// v and p sum ramps of size jmax T^3 / 6 to D and round to 2e-8: restored and minimised to the
// rows' rounding (pb.to_rounding), then polished to the table's own sums (keep_or_polish).
void cruise_stops_refined(FastestSearch& fs, ArcProblem& pb) noexcept {
  if (fs.ms.n != 2 || fs.band != 0.0) return;
  const double w0 = std::fabs(pb.poles[0].s.im), w1 = std::fabs(pb.poles[1].s.im);
  const double t_slow = two_pi_v<double>() / std::fmin(w0, w1), t_fast = two_pi_v<double>() / std::fmax(w0, w1);
  const double a_p = std::fmin(pb.amax, std::sqrt(pb.vmax * pb.J));
  const double rise = 2.0 * a_p / pb.J + (a_p >= pb.amax ? pb.vmax / pb.amax - pb.amax / pb.J : 0.0);
  const std::array<double, 3> cruise{0.75 * t_slow, 0.5 * t_fast, t_fast / 6.0};
  double tail = 0.0;
  for (const double h : cruise) tail += pb.vmax * (h + rise);
  if (!((pb.D - tail) / pb.vmax - rise >= 4.0 * t_slow)) return;
  ArcChain c{};
  pb.pulse = false;
  if (!(push_rigid_move(pb, pb.D - tail, c) > 0.0)) return;
  for (const double h : cruise) {
    if (c.n >= pb.max_nodes) return;
    c.node[c.n] = {ArcKind::dwell, 1.0};
    c.x[c.n++] = t_fast / 6.0;
    if (!(push_rigid_move(pb, pb.vmax * (h + rise), c) > 0.0)) return;
  }
  pb.to_rounding = true;
  if (restore_seed(pb, c)) {
    arc_refine(pb, c, 3);
    keep_or_polish(fs, pb, c);
  }
  pb.to_rounding = false;
}

// `base` with node k replaced by `with` (lengths and levels x), restored to the chain's equations,
// refined one round (arc_refine) and kept where shorter (keep_or_polish): the tail every seed
// that inserts turns into one node of a chain shares.
template <std::size_t N>
void spliced_refined(FastestSearch& fs, const ArcProblem& pb, const ArcChain& base, std::size_t k,
                     const std::array<ArcNode, N>& with, const std::array<double, N>& x) noexcept {
  ArcChain c{};
  if (fs.proven || !splice(base, k, with.data(), x.data(), N, pb.max_nodes, c) || !restore_seed(pb, c)) return;
  arc_refine(pb, c, 1);
  keep_or_polish(fs, pb, c);
}

// Two modes: bang-bang's shortest chain with a blip of finite size to the other limit (5 % of the
// hold) at 85 % of one of its holds at a limit, for each such hold, restored to the chain's
// equations and refined one round (arc_refine). The first-order test of arc_refine opens pairs of
// zero size, and a blip of zero hold restored to the equations closes again; the reference's move
// on grid case 40 (26.8 / 98.9 rad/s; D 1.99 m, amax 3.586) has such a blip of finite size late
// in a hold: +amax 0.633 s, -amax 0.041, +amax 0.115, -amax 0.644, +amax 0.003, -amax 0.053, ...,
// where the refined chain had +amax 0.618, -amax 0.045, +amax 0.129, -amax 0.402, +amax 0.003,
// -amax 0.296, ... (0.26 % over).
void hold_blips_refined(FastestSearch& fs, const ArcProblem& pb, const ArcChain& base) noexcept {
  for (std::size_t k = 0; k < base.n; ++k) {
    const ArcNode lim = base.node[k];
    if (lim.kind != ArcKind::limit || !(base.x[k] > 0.0)) continue;
    const std::array<ArcNode, 3> with{lim, ArcNode{ArcKind::limit, -lim.sign}, lim};
    const std::array<double, 3> x{0.85 * base.x[k], 0.05 * base.x[k], 0.15 * base.x[k]};
    spliced_refined(fs, pb, base, k, with, x);
  }
}

// bang-bang's shortest chain with each dwell broken at `before` of it (and `after` of it left) by
// a turn up to 0.07 amax and one down to -0.07 amax, restored and refined one round.
void dwell_pulse_at(FastestSearch& fs, const ArcProblem& pb, const ArcChain& base, double before,
                    double after) noexcept {
  for (std::size_t k = 0; k < base.n; ++k) {
    if (base.node[k].kind != ArcKind::dwell || !(base.x[k] > 0.0)) continue;
    const std::array<ArcNode, 4> with{base.node[k], ArcNode{ArcKind::peak, 1.0}, ArcNode{ArcKind::peak, -1.0},
                                      base.node[k]};
    const std::array<double, 4> x{before * base.x[k], 0.07 * pb.amax, -0.07 * pb.amax, after * base.x[k]};
    spliced_refined(fs, pb, base, k, with, x);
  }
}

// A pulse inside a dwell: bang-bang's shortest chain with each dwell broken, at 95 % of it, by a
// turn up to 0.07 amax and one down to -0.07 amax (the axis moves a little forward and stops
// again), restored to the chain's equations and refined (arc_refine). The reference's move on
// grid case 250 (two modes, 3.36 / 34.2 rad/s; D 0.128 m, a 0.6 s dwell between two cruising
// parts) has one: the dwell, a pulse at +-4 m/s^2 (0.07 amax) 0.56 s into it, 0.06 s more; the
// planner's chain had the two parts and the dwell and was 0.17 % over. Neither the first-order
// test (a dwell's v = 0 makes a pair of zero size there invisible to it) nor the stops and
// slow-downs (inside cruises) insert it.
void dwell_pulse_refined(FastestSearch& fs, const ArcProblem& pb, const ArcChain& base) noexcept {
  dwell_pulse_at(fs, pb, base, 0.95, 0.05);
}

// The pulse a quarter into each dwell (dwell_pulse_refined's seed at 0.25 / 0.75), three modes or
// more. The reference's move on grid case 263 (1.7 / 3.05 / 10.4 rad/s; D 8.9 mm, three dwells
// between four pulses) has five pulses; bang-bang's chain, four, was 0.20 % over. With a pulse a
// quarter into its second dwell it refines to 2.932548 s, 0.004 % under the reference.
void dwell_pulse_quarter(FastestSearch& fs, const ArcProblem& pb, const ArcChain& base) noexcept {
  dwell_pulse_at(fs, pb, base, 0.25, 0.75);
}

// A slow-down late in each cruise (three modes or more): the chain with a turn down to a peak
// sqrt(0.05 vmax jmax) (at most 0.9 amax) and back, four fifths into the cruise, restored to the
// chain's equations and refined one round (arc_refine). The reference's move on grid case 44
// (44.2 / 103.1 / 194.5 rad/s; D 0.338 m, vmax 0.5785) slows down 0.354 s into its 0.40 s cruise;
// the refined chain had its slow-down 0.233 s in (0.31 % over), and moving it there and restoring
// closed it. Seeded late with a finite size it refines to the reference's (0.355 s in).
void cruise_slowdown_late(FastestSearch& fs, const ArcProblem& pb, const ArcChain& base) noexcept {
  for (std::size_t k = 0; k < base.n; ++k) {
    if (base.node[k].kind != ArcKind::cruise || !(base.x[k] > 0.0)) continue;
    const double a_p = std::fmin(0.9 * pb.amax, std::sqrt(0.05 * pb.vmax * pb.J));
    const std::array<ArcNode, 4> with{base.node[k], ArcNode{ArcKind::peak, -1.0}, ArcNode{ArcKind::peak, 1.0},
                                      base.node[k]};
    const std::array<double, 4> x{0.8 * base.x[k], -a_p, a_p, 0.2 * base.x[k]};
    spliced_refined(fs, pb, base, k, with, x);
  }
}

// dwell_changes: passes at most, each from the chain the pass before refined; the minimisation
// steps that rank a pass's changes; and the least a pass's round must shorten its chain by for
// another pass.
constexpr int kDwellPasses = 3, kDwellScreenSteps = 5;
constexpr double kDwellPassGain = 1e-4;
// How close to a = 0 (of amax) a pulse's or a slow-down's turns are when drop_closed_pulses takes
// it out.
constexpr double kClosedPulse = 0.01;
// Where in a cruise dwell_changes stops it (of its length), and how short a stop's dwell is (of
// the chain's duration) when merge_closed_stops takes the stop out.
constexpr double kLateStop = 0.9, kClosedStop = 1e-9;

// The velocity where the ramp into node k + 1 crosses a = 0 (node k a turn down, k + 1 a turn up:
// the slowest point of a slow-down between them), from the chain's own lengths.
double slowdown_floor(const ArcProblem& pb, const ArcChain& c, std::size_t k) noexcept {
  double a = 0.0, v = 0.0;
  for (std::size_t r = 0; r <= k + 1; ++r) {
    const double lev = node_level(pb, c, r);
    const double j = ramp_in(c.node[r]) * pb.J;
    if (r == k + 1) {
      const double u = -a / j;
      return v + a * u + 0.5 * j * u * u;
    }
    const double d = (lev - a) / j;
    v += a * d + 0.5 * j * d * d;
    a = lev;
    if (c.node[r].kind != ArcKind::peak) v += a * c.x[r];
  }
  return v;
}

// A pulse inside a dwell (a dwell, a turn up, a turn down, a dwell) or a slow-down inside a
// cruise (a cruise, a turn down, a turn up, a cruise) whose turns closed to within kClosedPulse
// amax of a = 0 taken out of c (one dwell or cruise as long as the four nodes), the chain
// restored and minimised; c becomes that chain where that shortens it by kDwellPassGain or more.
// Such a pair leaves the minimisation at a degenerate point (its turns' columns vanish), where it
// stops at a duration that depends on the rounding, and holds nodes the next pass lacks: grid
// case 74's chain at 7.3 times its units stopped at 3.60777 s (a pulse's turns at 1e-11 and
// 1.7e-7 m/s^2) against 3.60695 s at 1, and taken out it minimises to that; case 5's third pass
// left two slow-downs at 1e-5 m/s^2 in its last cruise (3.60309 s), and taken out its chain has
// the reference's form (cruises 1.540, 0.099, 0.268 s, dwells 1.029, 0.143 s; the reference's
// 1.512, 0.093, 0.262 and 1.013, 0.129 s) and minimises to 3.59144 s (the reference 3.59176 s).
void drop_closed_pulses(const ArcProblem& pb, ArcChain& c) noexcept {
  ArcChain e = c;
  bool any = false;
  for (std::size_t k = 0; k + 3 < e.n;) {
    const ArcKind hold = e.node[k].kind;
    const double first = hold == ArcKind::dwell ? 1.0 : -1.0;  // a pulse up, a slow-down down
    const bool closed = (hold == ArcKind::dwell || hold == ArcKind::cruise) && e.node[k + 1].kind == ArcKind::peak &&
                        e.node[k + 2].kind == ArcKind::peak && e.node[k + 3].kind == hold &&
                        e.node[k + 1].sign == first && e.node[k + 2].sign == -first &&
                        std::fabs(e.x[k + 1]) <= kClosedPulse * pb.amax &&
                        std::fabs(e.x[k + 2]) <= kClosedPulse * pb.amax;
    if (!closed) {
      ++k;
      continue;
    }
    // The four nodes become one hold as long as they are.
    const ArcNode merged = e.node[k];
    const double x = e.x[k] + e.x[k + 3] + 2.0 * std::fabs(e.x[k + 1] - e.x[k + 2]) / pb.J;
    ArcChain f{};
    if (!splice(e, k, &merged, &x, 1, e.n, f, 4)) return;
    e = f;
    any = true;
  }
  if (!any || !restore_seed(pb, e)) return;
  ArcKkt kkt{};
  arc_minimise(pb, e, kkt, 40);
  if (lay_out(pb, e).T < lay_out(pb, c).T * (1.0 - kDwellPassGain) && arc_violation(pb, e).kind == ArcFix::none) {
    c = e;
  }
}

// A stop inside a cruise (a cruise, a turn down, a dwell, a turn up, a cruise) whose dwell closed
// to kClosedStop of the chain's duration or less taken out of c: the five nodes become one cruise
// over the same span. Not restored: dwell_changes splices its changes into the chain that is left
// and restores each. Such a stop touches v = 0 for no time and holds four nodes a change needs:
// on grid case 227 the first pass's round (a stop late in the second cruise) left one at the end
// of the last (a 4.7e-16 T dwell, 23 nodes, full); taken out, the next pass's pulse in the third
// dwell has room to grow into a restart to vmax, the reference's form (six parts, five dwells).
void merge_closed_stops(const ArcProblem& pb, ArcChain& c) noexcept {
  const double T = lay_out(pb, c).T;
  const auto turn = [&](std::size_t i, double sign) {
    return (c.node[i].kind == ArcKind::limit || c.node[i].kind == ArcKind::peak) && c.node[i].sign == sign;
  };
  for (std::size_t k = 0; k + 4 < c.n;) {
    if (c.node[k].kind != ArcKind::cruise || !turn(k + 1, -1.0) || c.node[k + 2].kind != ArcKind::dwell ||
        !turn(k + 3, 1.0) || c.node[k + 4].kind != ArcKind::cruise || !(c.x[k + 2] <= kClosedStop * T)) {
      ++k;
      continue;
    }
    const ArcLayout L = lay_out(pb, c);
    const ArcNode cruise = c.node[k];
    const double x = L.b[k + 5] - L.e[k];  // from the first cruise's start to the second's end
    ArcChain e{};
    if (!splice(c, k, &cruise, &x, 1, c.n, e, 5)) return;
    c = e;
  }
}

// The passes of dwell_changes from `refined`. stops: a stop kLateStop into each cruise
// (insert_stop: the rigid stop and start, a dwell of a quarter period of the fastest mode) is a
// change too; the first pass's changes are those stops alone, and it goes on only where one
// screens shorter than the shortest move so far (the passes without stops included: on grid case
// 74 a stop screened shorter than its chain, 3.6489 s, but not than those passes' 3.6069 s, and its
// rounds cost 4.8 times the plan's instructions for nothing); each later pass first takes the
// stops whose dwell closed out of the chain it changes (merge_closed_stops). Their rounds stop
// cruises but do not slow them down (ArcProblem::no_slowdown: on 227 the slow-downs cost 2 033 ->
// 1 474 M instructions, and none was kept).
void dwell_passes(FastestSearch& fs, ArcProblem& pb, const ArcChain& refined, double quarter, bool stops) noexcept {
  ArcChain c = refined;
  for (int pass = 0; pass < kDwellPasses && !fs.proven; ++pass) {
    const double t_c = lay_out(pb, c).T;
    ArcChain pick{};
    double t_pick = HUGE_VAL;
    // Restored and minimised a few steps; the shortest that did not return to t_c is picked.
    const auto screen = [&](ArcChain e) {
      if (!restore_seed(pb, e)) return;
      ArcKkt kkt{};
      arc_minimise(pb, e, kkt, kDwellScreenSteps);
      const double te = lay_out(pb, e).T;
      if (std::fabs(te - t_c) > 1e-7 * t_c && te < t_pick && arc_violation(pb, e).kind == ArcFix::none) {
        t_pick = te;
        pick = e;
      }
    };
    ArcChain e{};
    if (stops) {
      if (pass > 0) merge_closed_stops(pb, c);
      for (std::size_t k = 0; k < c.n; ++k) {
        if (c.node[k].kind == ArcKind::cruise && c.x[k] > 0.0 && insert_stop(pb, c, k, quarter, e, kLateStop)) screen(e);
      }
      if (pass == 0 && !(t_pick < fs.best.time)) return;
    }
    if (!stops || pass > 0) {
      for (std::size_t k = 0; k + 1 < c.n; ++k) {
        const ArcNode& dn = c.node[k];
        const ArcNode& up = c.node[k + 1];
        const bool turns = (dn.kind == ArcKind::limit || dn.kind == ArcKind::peak) &&
                           (up.kind == ArcKind::limit || up.kind == ArcKind::peak);
        if (!turns || dn.sign > 0.0 || up.sign < 0.0 || !(slowdown_floor(pb, c, k) < 0.25 * pb.vmax)) continue;
        const std::array<ArcNode, 2> with{dn, ArcNode{ArcKind::dwell, 1.0}};
        const std::array<double, 2> x{c.x[k], quarter};
        if (splice(c, k, with.data(), x.data(), with.size(), pb.max_nodes, e)) screen(e);
      }
      for (std::size_t k = 0; k < c.n; ++k) {
        if (c.node[k].kind != ArcKind::dwell) continue;
        if (splice(c, k, nullptr, nullptr, 0, pb.max_nodes, e)) screen(e);
        for (const double before : {0.25, 0.75}) {
          const std::array<ArcNode, 4> with{c.node[k], ArcNode{ArcKind::peak, 1.0}, ArcNode{ArcKind::peak, -1.0},
                                            c.node[k]};
          const std::array<double, 4> x{before * c.x[k], 0.07 * pb.amax, -0.07 * pb.amax, (1.0 - before) * c.x[k]};
          if (splice(c, k, with.data(), x.data(), with.size(), pb.max_nodes, e)) screen(e);
        }
      }
    }
    if (!(t_pick < HUGE_VAL)) return;
    pb.one_slowdown = true;
    pb.no_slowdown = stops;
    (void)arc_refine(pb, pick, 1);
    pb.one_slowdown = pb.no_slowdown = false;
    drop_closed_pulses(pb, pick);
    keep_or_polish(fs, pb, pick);
    if (fs.proven) return;
    if (!(lay_out(pb, pick).T < t_c * (1.0 - kDwellPassGain)) || arc_violation(pb, pick).kind != ArcFix::none) return;
    c = pick;
  }
}

// Three modes or more: a refined chain with its dwells changed one at a time, each restored to
// the chain's equations and minimised a few steps (kDwellScreenSteps); of the changes that did not
// return to the chain's duration, the shortest is refined one round (arc_refine, with room up to
// kMaxArcNodes, one level of slow-down) and kept where a shorter move; where that round shortened
// the chain by kDwellPassGain or more it starts the next pass (kDwellPasses). The reference's moves
// on such problems stop and start again three to six times, more than a chain of kChainNodes holds
// (grid cases 35 and 74: four and five parts with dwells between, 17 nodes each; 227: six parts,
// 23), and where they stop differs from the refined chain. The changes: a dwell of a quarter period
// of the fastest mode inserted where a slow-down between two turns falls below a quarter of vmax;
// each dwell left out; a pulse (turns to +-0.07 amax) a quarter and three quarters into each dwell.
// Then, on a chain full at kChainNodes (`stops`: refined_chains' call for a chain arc_refine could
// not grow), the passes again from it, the first with a stop late in each cruise (dwell_passes'
// stops): a stop adds a part, which arc_refine had no room to add there; screened on every chain the
// changes run on, the stops cost the grid's costliest plans instructions for nothing (5 +0.4 %,
// 254 +0.7 %). Grid case 227's reference stops
// 0.92 s into its 0.99 s second cruise; among the changes above the stop was picked over the pulses
// on 227, but on other chains it took the place of the pulse that shortened them (86 at 7.3 times
// its units: 7.15689 s against 7.14965 s), so it starts passes of its own. Only
// where the refined chain is within 1 % of the shortest move so far (of the chains the changes
// shortened none started further off; grid case 290's, 2.4 % over, cost 2.4 s for nothing). One
// round per pass, not one per change: a round (every cruise stopped and slowed down, pairs
// inserted, each minimised) costs tens of a change's screening, and refining every change, as
// first written (session 26), cost grid cases 197 and 290 2.5 s each for nothing.
void dwell_changes(FastestSearch& fs, const ArcProblem& narrow, const ArcChain& refined, double quarter,
                   bool stops) noexcept {
  if (lay_out(narrow, refined).T > 1.01 * fs.best.time) return;
  ArcProblem pb = narrow;
  pb.max_nodes = kMaxArcNodes;
  dwell_passes(fs, pb, refined, quarter, false);
  if (stops && !fs.proven) dwell_passes(fs, pb, refined, quarter, true);
}

// A refined chain's limit nodes held for no time (a turn that touches amax and leaves it at once)
// made into peaks at amax and refined again (arc_refine). The same move, but a limit's hold cannot
// go below 0 where a peak's level can go below amax: as a limit node the minimisation cannot take
// the turn away from amax, as a peak it can (the bound's multiplier releases it). On grid case
// 229 (two modes, 65.3 / 247.2 rad/s; D 0.152 m, a 0.51 s move) the refined chain's last turn
// holds +amax for 1e-16 s, 0.26 % over the reference; the reference's move turns at +1.34 m/s^2
// there and holds its other turns a little differently, and the chain with a peak refines to it.
void zero_holds_to_peaks(FastestSearch& fs, const ArcProblem& pb, const ArcChain& refined) noexcept {
  ArcChain c = refined;
  if (held_for_no_time_to_peaks(pb, c) && restore_seed(pb, c) && arc_refine(pb, c, 1, kept_until_proven(fs, pb))) keep_or_polish(fs, pb, c);
}

// (a'') bang-bang's shortest chains with turns inserted and their length minimised (arc_refine),
// last: every family before is as without it, and a refined chain is a candidate only where it is
// shorter than everything they found.
void refined_chains(FastestSearch& fs) noexcept {
  const ArcBest& got = fs.chains;
  ArcProblem pb = arc_problem(fs.r, fs.ms);
  ArcExpMemo exps(fs.ms.n);
  pb.exps = &exps;
  double w_fast = 0.0;  // the fastest mode's damped frequency
  for (std::size_t m = 0; m < fs.ms.n; ++m) w_fast = std::fmax(w_fast, std::fabs(pb.poles[m].s.im));
  const double quarter = 0.25 * two_pi_v<double>() / w_fast;  // a stop dwells a quarter period of it (dwell_changes)
  // Each step below stops the search where the shortest move so far is proven the shortest
  // (FastestSearch::proven): the steps after it could only find one shorter by the proof's rounding.
  fs.stop_proven = true;
  // The split chains under the rule below (the fastest mode rings a period or more over the
  // shortest move so far).
  if (fs.ms.n >= 2 && w_fast * fs.best.time >= two_pi_v<double>()) split_refined(fs, pb);
  if (!got.have && !fs.proven) split_to_rounding(fs, pb);
  if (w_fast * fs.best.time >= two_pi_v<double>() && !fs.proven) blips_refined(fs, pb);
  if (!fs.proven) cruise_stops_refined(fs, pb);
  // The late stages' chains last first: each is shorter than every chain before it (ArcBest::late),
  // so the shortest is refined first, and where its refinement is proven the shortest move the
  // longer chains' are skipped. Grid case 237 (one mode) refined bang-bang's chain (1.6078 s) to
  // 1.5793 s, longer than the third late stage's chain it then refined and proved (1.5625 s): the
  // evaluations of a chain's system in its plan 264 k -> 121 k (a throw-away counting build); 40,
  // 167 and 170 also proven sooner, every grid plan the same.
  for (std::size_t i = 0; i <= kLateStages && !fs.proven; ++i) {
    const std::size_t k = kLateStages - i;
    const bool have = k == 0 ? got.have : got.late_have[k - 1];
    if (!have) continue;
    ArcChain c = k == 0 ? got.c : got.late[k - 1];
    pb.pulse = k == 0 && got.pulse;
    // Only where the fastest mode rings a period or more over the move: every request of the
    // tests and the grid that the refinement shortened (186 of 932) lasts 1.35 of its (damped)
    // periods or more, and the one-mode reference request (0.6 periods) paid 2.6 times its
    // instructions for a test that found nothing to insert.
    const double t_move = lay_out(pb, c).T + (pb.pulse ? pb.D / pb.vmax : 0.0);
    if (w_fast * t_move < two_pi_v<double>()) continue;
    if (fs.ms.n == 1) blip_moved(fs, pb, c);
    if (k == 0 && !fs.proven) dwell_pulse_refined(fs, pb, got.c);
    if (k == 0 && fs.ms.n >= 3 && !fs.proven) dwell_pulse_quarter(fs, pb, got.c);
    if (fs.ms.n >= 3 && !fs.proven) cruise_slowdown_late(fs, pb, c);
    if (fs.proven) return;
    const bool shorter = arc_refine(pb, c, 3, kept_until_proven(fs, pb));
    // A three-mode chain full at kChainNodes (no pair fits: arc_refine only minimised it) gets its
    // dwells changed all the same, with dwell_changes' room: grid case 74's chain (14 nodes, three
    // stops) was left 1.16 % over the reference, which stops four times (18 nodes); and stops late
    // in its cruises: 227's (15 nodes, four parts), whose reference has six.
    if (!shorter && fs.ms.n >= 3 && c.n + 2 > pb.max_nodes) dwell_changes(fs, pb, c, quarter, true);
    if (!shorter) continue;
    keep_or_polish(fs, pb, c);
    if (!fs.proven) zero_holds_to_peaks(fs, pb, c);
    if (fs.ms.n >= 3 && !fs.proven) dwell_changes(fs, pb, c, quarter, false);
    // Two modes, the shortest chain before the late stages, where refining it shortened it.
    if (fs.ms.n == 2 && k == 0 && !fs.proven) hold_blips_refined(fs, pb, got.c);
  }
}

// Every family for a request with D >= 0 (plan_fastest mirrors D < 0 onto it).
Status plan_unsigned(const MoveRequest& r, FastestParams& out, Peaks<double>& out_pk) noexcept {
  CertMemo certs;
  FastestSearch fs{r, certs};
  const Status st = read_fastest_request(r, fs);
  if (st != Status::ok) return st;
  fs.to = jerk_limited_time_optimal(r.distance, fs.lim.vmax, fs.lim.amax, fs.lim.jmax);
  fs.t_to = piecewise_duration(fs.to);
  shaped_families(fs);
  scurve_families(fs);
  zero_sets(fs);
  // A proven bang-bang move (plan_arcs stopped at it) is the shortest of the problem: the searches
  // after it (bang-coast, the refined chains) are not made. The dips' shortest is recorded all the
  // same: plan_arcs' proof may be of it.
  const bool arcs_won = bang_bang_family(fs);
  fs.proven = fs.chains.proven;
  if (!arcs_won && !fs.proven) bang_coast_family(fs);
  if (fs.dips.have) fs.record_table(FastestFamily::bang_bang, fs.dips.t, fs.dips.pk);
  if (!fs.proven) refined_chains(fs);
  if (!std::isfinite(fs.best.time)) return Status::no_solution;
  fs.best.p.family_time = fs.times;
  out = fs.best.p;
  out_pk = fs.best.pk;
  return Status::ok;
}

}  // namespace

// The move of -D is the move of D mirrored (scaled_fastest by -1: every position, velocity,
// acceleration and jerk negated, times and peaks kept), so D and -D plan alike to the bit. The
// search itself is not symmetric in the sign: planned at -D, rounding steered it to another move
// once (a two-mode case 1.9e-6 s longer; docs/fastest.md, "The sign of D").
Status plan_fastest(const MoveRequest& r, FastestParams& out, Peaks<double>& out_pk) noexcept {
  const bool mirrored = r.distance < 0.0;
  MoveRequest q = r;
  if (mirrored) q.distance = -r.distance;
  const Status st = plan_unsigned(q, out, out_pk);
  if (st == Status::ok && mirrored) out = detail::scaled_fastest(out, -1.0);
  return st;
}

}  // namespace settle::core

#endif  // SETTLE_CORE_FASTEST
