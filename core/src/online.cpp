// SPDX-License-Identifier: Apache-2.0
#include "settle/core/online.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "settle/core/piece.hpp"
#include "mode_integral.hpp"
#include "numeric/complex.hpp"

namespace settle::core {

namespace {

using namespace numeric;
using detail::phi1;
using detail::phi2;
using detail::profile_integral;

bool finite(const Sample<double>& s) noexcept {
  return std::isfinite(s.p) && std::isfinite(s.v) && std::isfinite(s.a);
}

constexpr std::size_t kMaxRows = 3 + 2 * kMaxOnlineModes;

// A command's memory this small (relative to its positions) is its rounding: it ends at rest. The
// residual amplitude of a mode at rest with memory Q is |Q| / sqrt(1 - zeta^2). The level every
// planned move is guaranteed at rest to (residual.hpp): at `fastest`'s own acceptance level a move
// it planned could count as ringing and leave a halt no finish (soak draw 726).
constexpr double kRestMemory = kAtRestResidual;

double position_scale(double origin, double end) noexcept {
  return std::fmax(std::fabs(end - origin), std::fmax(std::fabs(origin), std::fabs(end)));
}

struct Solved {
  std::array<double, kBlendSegments> jerk{};
};

// The time-optimal stop of the velocity alone, from (v0, a0) to v = a = 0 under |a| <= amax,
// |j| <= jmax (position free): jerk -J, 0, +J in the direction that cancels the velocity the
// state would reach if its acceleration were taken out at once. Up to three (duration, jerk)
// phases; the blend uses it as its reference (below).
struct Brake {
  std::array<double, 3> dur{}, jerk{};
};
Brake velocity_stop(double v0, double a0, double amax, double jmax) noexcept {
  Brake b{};
  const double v_nat = v0 + a0 * std::fabs(a0) / (2.0 * jmax);
  // Mirror so that the velocity to cancel is positive: the acceleration then goes negative.
  const double sg = v_nat < 0.0 ? -1.0 : 1.0;
  const double v = sg * v0, a = sg * a0;
  if (v_nat == 0.0) {
    b.dur[0] = std::fabs(a0) / jmax;
    b.jerk[0] = a0 > 0.0 ? -jmax : jmax;
    return b;
  }
  double ap = -std::sqrt(0.5 * a * a + jmax * v);  // peak deceleration without a plateau
  double plateau = 0.0;
  if (ap < -amax) {
    ap = -amax;
    const double dv = v + (a * a - amax * amax) / (2.0 * jmax) - amax * amax / (2.0 * jmax);
    plateau = std::max(dv / amax, 0.0);
  }
  b.dur = {(a - ap) / jmax, plateau, -ap / jmax};
  b.jerk = {-sg * jmax, 0.0, sg * jmax};
  return b;
}

// A brake's jerk averaged over each blend segment of length h (zero past its end): its
// acceleration at every segment boundary is the brake's own.
// Only the segments that can overlap a phase are visited: those before it end at or before its
// start (s1 <= t0: no overlap), and once a segment starts at or after its end (s0 >= t1) so do the
// later ones. The next phase starts two segments before where this one stopped (a segment's
// s0 + h and the next one's s0 may differ by a rounding); a NaN end visits every segment, as before.
// Returns how many segments were visited: those after them are +0.
std::size_t sample_brake(const Brake& b, double h, std::array<double, kBlendSegments>& out) noexcept {
  out = {};
  double t0 = 0.0;
  std::size_t first = 0, visited = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    const double t1 = t0 + b.dur[i];
    std::size_t k = first;
    for (; k < kBlendSegments; ++k) {
      const double s0 = static_cast<double>(k) * h, s1 = s0 + h;
      if (s0 >= t1) break;
      const double overlap = std::min(s1, t1) - std::max(s0, t0);
      if (overlap > 0.0) out[k] += b.jerk[i] * overlap / h;
    }
    visited = std::max(visited, k);
    if (k < kBlendSegments && k > first + 2) first = k - 2;
    t0 = t1;
  }
  return visited;
}

// The end conditions of a blend of duration T, linear in its jerks: mat j = rhs.
// build_system sets rows [0, rows) of mat and rhs, all a solve reads: they are not zeroed first.
struct System {
  std::array<std::array<double, kBlendSegments>, kMaxRows> mat;  // NOLINT
  std::array<double, kMaxRows> rhs;                              // NOLINT
  std::size_t rows{0};
};

// N - k - 1/2 for each segment k (exact), read instead of converted per duration.
constexpr std::array<double, kBlendSegments> kSegmentsAfter = [] {
  std::array<double, kBlendSegments> c{};
  for (std::size_t k = 0; k < kBlendSegments; ++k) c[k] = static_cast<double>(kBlendSegments - k) - 0.5;
  return c;
}();

// 1/6 + m/2 + m^2/2 for m = N - 1 - k, as the position row always summed it (no contraction:
// -ffp-contract=off), read instead of computed per duration.
constexpr std::array<double, kBlendSegments> kPositionWeights = [] {
  std::array<double, kBlendSegments> c{};
  for (std::size_t k = 0; k < kBlendSegments; ++k) {
    const double m = static_cast<double>(kBlendSegments - 1 - k);
    c[k] = 1.0 / 6.0 + 0.5 * m + 0.5 * m * m;
  }
  return c;
}();

// a = v = 0 at the end, p = target for a retarget, and per mode the blend's own contribution
// cancelling the memory it starts with (docs/online.md, "conditions").
void build_system(const OnlineRequest& r, double t_total, System& sys) noexcept {
  constexpr std::size_t n = kBlendSegments;
  const double h = t_total / static_cast<double>(n);
  const double p0 = r.start.p, v0 = r.start.v, a0 = r.start.a;
  auto& mat = sys.mat;
  auto& rhs = sys.rhs;
  std::size_t rows = 0;
  // a(T) = a0 + h sum j_k = 0
  for (std::size_t k = 0; k < n; ++k) mat[rows][k] = h;
  rhs[rows++] = -a0;
  // v(T) = v0 + a0 T + sum j_k h^2 (N - k - 1/2) = 0
  for (std::size_t k = 0; k < n; ++k) mat[rows][k] = h * h * kSegmentsAfter[k];
  rhs[rows++] = -v0 - a0 * t_total;
  if (r.target) {
    // p(T) = p0 + v0 T + a0 T^2 / 2 + sum j_k h^3 (1/6 + m/2 + m^2/2), m = N - 1 - k
    for (std::size_t k = 0; k < n; ++k) mat[rows][k] = h * h * h * kPositionWeights[k];
    rhs[rows++] = *r.target - p0 - v0 * t_total - 0.5 * a0 * t_total * t_total;
  }
  for (std::size_t i = 0; i < r.mode_count; ++i) {
    const Cx lam = pole(r.modes[i].omega, r.modes[i].zeta);
    const Cx x = h * lam;
    const Cx e1 = cexp(x);
    const Cx f1 = h * phi1(x, e1);       // int_0^h e^{lambda w} dw
    const Cx f2 = (h * h) * phi2(x, e1);  // int_0^h e^{lambda w} (h - w) dw
    // Column k (m = N - 1 - k segments after it): E^m f2 + h S_m, S_m = int_0^{m h} e^{lambda w} dw.
    // (Packed: two-double vectors where the host has them, the same products and sums, complex.hpp.)
    const PackedFactor pe{e1}, pf2{f2};
    const Packed pf1 = pack(f1);
    const auto ph = splat(h);  // a Packed, or the double itself
    Packed em = pack(Cx{1.0, 0.0}), sm = pack(Cx{});
    for (std::size_t m = 0; m < n; ++m) {
      const Cx c = unpack(em * pf2 + ph * sm);
      const std::size_t k = n - 1 - m;
      mat[rows][k] = c.re;
      mat[rows + 1][k] = c.im;
      sm = sm * pe + pf1;
      em = em * pe;
    }
    // int_0^T e^{lambda (T - u)} a(u) du = e^{lambda T} (lambda Q - v0)
    const Cx q{r.memory[i].re, r.memory[i].im};
    const Cx b = unpack(em) * (lam * q - Cx{v0, 0.0}) - a0 * unpack(sm);
    rhs[rows] = b.re;
    rhs[rows + 1] = b.im;
    rows += 2;
  }
  sys.rows = rows;
}

// Pinning stops when the least-norm jerks overshoot the limit more than this many times: the
// duration is far too short, and more passes would only cost time.
constexpr double kPinOvershoot = 2.0;
using Gram = std::array<std::array<double, kMaxRows>, kMaxRows>;

// Code that spends size for speed (short loops unrolled, copies for constant lengths): not on the
// Cortex-M cores (their flash).
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
#define SETTLE_UNROLL_SMALL 0
#else
#define SETTLE_UNROLL_SMALL 1
#endif

// g = L L^T for the symmetric positive definite Gram matrix (lower triangle of `l`), read from
// g's lower triangle alone (the solve keeps no other). False when a
// pivot is not positive; a nearly singular one is let through, as partial pivoting let it through
// before: the caller rejects a solution that misses its equations (a retarget over a huge distance
// has such a Gram matrix and a valid blend).
// (Fixed > 0: n is Fixed, a constant; see factor below.)
template <std::size_t Fixed = 0>
bool cholesky(const Gram& g, std::size_t rows, Gram& l) noexcept {
  const std::size_t n = Fixed > 0 ? Fixed : rows;
#if SETTLE_UNROLL_SMALL
#pragma GCC unroll 8
#endif
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < i; ++c) {
      double s = g[i][c];
      for (std::size_t k = 0; k < c; ++k) s -= l[i][k] * l[c][k];
      l[i][c] = s / l[c][c];
    }
    double s = g[i][i];
    for (std::size_t k = 0; k < i; ++k) s -= l[i][k] * l[i][k];
    if (!(s > 0.0 && s <= std::numeric_limits<double>::max())) return false;
    l[i][i] = std::sqrt(s);
  }
  return true;
}

// Solves L L^T y = b in place.
template <std::size_t Fixed = 0>
void cholesky_solve(const Gram& l, std::size_t rows, std::array<double, kMaxRows>& b) noexcept {
  const std::size_t n = Fixed > 0 ? Fixed : rows;
  for (std::size_t i = 0; i < n; ++i) {
    double s = b[i];
    for (std::size_t k = 0; k < i; ++k) s -= l[i][k] * b[k];
    b[i] = s / l[i][i];
  }
  for (std::size_t i = n; i-- > 0;) {
    double s = b[i];
    for (std::size_t k = i + 1; k < n; ++k) s -= l[k][i] * b[k];
    b[i] = s / l[i][i];
  }
}

// cholesky and cholesky_solve for the sizes the searches meet most (a halt or a retarget with one
// or two modes: 4 to 7 rows) with the size a constant, so that the compiler unrolls their short
// loops: the same operations in the same order, the same bits. Not on the Cortex-M cores, whose
// flash the copies would cost and whose soft double gains little from them.
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
bool factor(const Gram& g, std::size_t n, Gram& l) noexcept { return cholesky(g, n, l); }
void factor_solve(const Gram& l, std::size_t n, std::array<double, kMaxRows>& b) noexcept { cholesky_solve(l, n, b); }
#else
bool factor(const Gram& g, std::size_t n, Gram& l) noexcept {
  switch (n) {
    case 4: return cholesky<4>(g, n, l);
    case 5: return cholesky<5>(g, n, l);
    case 6: return cholesky<6>(g, n, l);
    case 7: return cholesky<7>(g, n, l);
    default: return cholesky(g, n, l);
  }
}
void factor_solve(const Gram& l, std::size_t n, std::array<double, kMaxRows>& b) noexcept {
  switch (n) {
    case 4: cholesky_solve<4>(l, n, b); return;
    case 5: cholesky_solve<5>(l, n, b); return;
    case 6: cholesky_solve<6>(l, n, b); return;
    case 7: cholesky_solve<7>(l, n, b); return;
    default: cholesky_solve(l, n, b); return;
  }
}
#endif

using Rows = std::array<std::array<double, kBlendSegments>, kMaxRows>;

// out_i = sum_k m_ik v_k for rows [0, rows), each sum over k in order; two rows at a time (two
// independent sums share the loads of v and overlap their additions). Only the first Len terms are
// summed: the caller's v is zero past them.
template <std::size_t Len = kBlendSegments>
void row_dots(const Rows& m, std::size_t rows, const std::array<double, kBlendSegments>& v,
              std::array<double, kMaxRows>& out) noexcept {
  std::size_t i = 0;
  for (; i + 1 < rows; i += 2) {
    double s0 = 0.0, s1 = 0.0;
    for (std::size_t k = 0; k < Len; ++k) {
      s0 += m[i][k] * v[k];
      s1 += m[i + 1][k] * v[k];
    }
    out[i] = s0;
    out[i + 1] = s1;
  }
  if (i < rows) {
    double s0 = 0.0;
    for (std::size_t k = 0; k < Len; ++k) s0 += m[i][k] * v[k];
    out[i] = s0;
  }
}

// row_dots of a reference that is +0 from segment `len` on (sample_brake's count): the terms of
// those segments are left out, to a multiple of 4 segments. Each left out would add m_ik * 0 = +-0
// to a sum that started at +0 and so is never -0: no change (an m_ik not finite, whose product
// would be NaN, makes its row's norm not finite, and the solve fails on that before it reads the
// sum). Not on the Cortex-M cores (the copies' flash).
void reference_dots(const Rows& m, std::size_t rows, const std::array<double, kBlendSegments>& ref, std::size_t len,
                    std::array<double, kMaxRows>& out) noexcept {
#if SETTLE_UNROLL_SMALL
  static_assert(kBlendSegments == 24);
  switch ((len + 3) / 4) {
    case 6: row_dots<24>(m, rows, ref, out); return;
    case 5: row_dots<20>(m, rows, ref, out); return;
    case 4: row_dots<16>(m, rows, ref, out); return;
    case 3: row_dots<12>(m, rows, ref, out); return;
    case 2: row_dots<8>(m, rows, ref, out); return;
    default: row_dots<4>(m, rows, ref, out); return;
  }
#else
  static_cast<void>(len);
  row_dots(m, rows, ref, out);
#endif
}

// The blend's jerks j = j_ref + dj, dj of least weighted norm sum dj_k^2 / w_k (sw = sqrt(w)),
// meeting the system. Then, up to `pins` times, every jerk beyond +-jmax is pinned to it (taken
// out of the unknowns, its share moved to the right side) and the rest solved again: a few such
// passes turn the smooth least-norm correction towards the bang-bang jerk a short blend needs. The
// Gram matrix is downdated, not rebuilt. False when the system is singular to working precision,
// the solution misses it, or a jerk is left beyond jmax (1 + kLimitSlack), which the limit check
// (blend_within) would refuse.
//
// Every sum is taken in the order it always was (over k for a row's products, over i for a
// column's), so that the result is the same to the bit: loops run over the other index inside
// only where that keeps each sum's own order (several sums advance together), and the velocity
// peaks are checked as Blend::peaks finds them (blend_within). With unit weights
// (`unit`: every sw_k is 1, then 1 or 0 once pinned) the products by sw_k are exact and skipped:
// x sw sw = x sw = x for sw = 1, and x sw sw = x sw for sw = 0.
bool solve_for(const System& sys, std::array<double, kBlendSegments> ref, std::array<double, kBlendSegments> sw,
               std::size_t ref_len, bool unit, double jmax, int pins, Solved& out) noexcept {
  constexpr std::size_t n = kBlendSegments;
  const std::size_t rows = sys.rows;
  // The reference's share of each condition is known: the unknowns are the deviation from it.
  // (Without a reference, the share is +0 and the right side the system's own, to the bit.)
  std::array<double, kMaxRows> rhs{};
  if (ref_len > 0) reference_dots(sys.mat, rows, ref, ref_len, rhs);
  for (std::size_t i = 0; i < rows; ++i) rhs[i] = sys.rhs[i] - rhs[i];
  // Unknowns x_k = dj_k / sqrt(w_k): the weighted problem becomes a minimum-norm one. Then rows to
  // unit length, so that the Gram matrix is as well conditioned as the geometry allows: each solve
  // scales its own copy of the system's rows.
  Rows mat;  // NOLINT: rows [0, rows) are set here
  for (std::size_t i = 0; i < rows; ++i) {
    const auto& row = sys.mat[i];
    double nn = 0.0;
    if (unit) {
      for (std::size_t k = 0; k < n; ++k) nn += row[k] * row[k];
    } else {
      for (std::size_t k = 0; k < n; ++k) nn += row[k] * row[k] * sw[k] * sw[k];
    }
    nn = std::sqrt(nn);
    if (!(nn > 0.0) || !std::isfinite(nn)) return false;
    for (std::size_t k = 0; k < n; ++k) mat[i][k] = row[k] / nn;  // unweighted column, row-scaled
    rhs[i] /= nn;
  }
  Gram gram;  // NOLINT: its lower triangle in [0, rows)^2 is set here
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t l = 0; l <= i; ++l) {
      double s = 0.0;
      if (unit) {
        for (std::size_t k = 0; k < n; ++k) s += mat[i][k] * mat[l][k];
      } else {
        for (std::size_t k = 0; k < n; ++k) s += mat[i][k] * mat[l][k] * sw[k] * sw[k];
      }
      gram[i][l] = s;  // the lower triangle: all that cholesky reads
    }
  }
  std::array<double, n> jerk;  // NOLINT: every pass sets all of it
  for (int pin = 0;; ++pin) {
    std::array<double, n> x;  // NOLINT: the first pass sets it
    std::array<double, kMaxRows> res = rhs;
    double rhs_norm = 0.0;
    for (std::size_t i = 0; i < rows; ++i) rhs_norm = std::max(rhs_norm, std::fabs(rhs[i]));
    // Minimum norm: x = W M^T (M W M^T)^{-1} b, then, only if it misses its equations, one step of
    // iterative refinement with the same factor (docs/online.md, "Refinement only where needed").
    Gram chol;  // NOLINT: cholesky sets the lower triangle it reads
    if (!factor(gram, rows, chol)) return false;
    for (int pass = 0;; ++pass) {
      std::array<double, kMaxRows> y = res;
      factor_solve(chol, rows, y);
      // Column k's sum over i, for every k at once.
      std::array<double, n> s;  // NOLINT: set by the first row
      for (std::size_t k = 0; k < n; ++k) s[k] = mat[0][k] * y[0];
      for (std::size_t i = 1; i < rows; ++i) {
        const double yi = y[i];
        for (std::size_t k = 0; k < n; ++k) s[k] += mat[i][k] * yi;
      }
      if (pass == 0 && unit) {
        for (std::size_t k = 0; k < n; ++k) x[k] = s[k] * sw[k];
      } else if (pass == 0) {
        for (std::size_t k = 0; k < n; ++k) x[k] = s[k] * sw[k] * sw[k];
      } else if (unit) {
        for (std::size_t k = 0; k < n; ++k) x[k] += s[k] * sw[k];
      } else {
        for (std::size_t k = 0; k < n; ++k) x[k] += s[k] * sw[k] * sw[k];
      }
      double worst = 0.0;
      row_dots(mat, rows, x, res);
      for (std::size_t i = 0; i < rows; ++i) {
        res[i] = rhs[i] - res[i];
        worst = std::max(worst, std::fabs(res[i]));
      }
      // The test is worst <= 1e-12 max(rhs_norm, xn): the largest x (relative to its weight) is
      // needed only when the right side alone does not pass it (a NaN xn is ignored either way).
      if (worst <= 1e-12 * rhs_norm) break;
      double xn = 0.0;
      if (unit) {
        for (std::size_t k = 0; k < n; ++k) xn = std::max(xn, std::fabs(x[k]));
      } else {
        for (std::size_t k = 0; k < n; ++k) xn = std::max(xn, std::fabs(x[k]) / (sw[k] > 0.0 ? sw[k] : 1.0));
      }
      if (worst <= 1e-12 * std::max(rhs_norm, xn)) break;
      if (pass == 1) return false;
    }
    double jpk = 0.0;
    bool finite = true;
#if SETTLE_PACKED_VECTOR
    // Two segments per vector (x86-64): each jerk the same sum, their largest |j| the same maximum
    // (the order of a maximum of finite values does not matter, and jpk is read only when every
    // jerk is finite); j - j is +0 for a finite jerk and NaN otherwise, and a sum of them stays +0
    // only when every jerk is finite.
    static_assert(n % 2 == 0);
    {
      const __m128d sign = _mm_set1_pd(-0.0);
      __m128d peak = _mm_setzero_pd(), bad = _mm_setzero_pd();
      for (std::size_t k = 0; k < n; k += 2) {
        const __m128d j = _mm_add_pd(_mm_loadu_pd(&ref[k]), _mm_loadu_pd(&x[k]));
        _mm_storeu_pd(&jerk[k], j);
        peak = _mm_max_pd(_mm_andnot_pd(sign, j), peak);
        bad = _mm_add_pd(bad, _mm_sub_pd(j, j));
      }
      jpk = std::max(_mm_cvtsd_f64(peak), _mm_cvtsd_f64(_mm_unpackhi_pd(peak, peak)));
      finite = _mm_movemask_pd(_mm_cmpeq_pd(bad, _mm_setzero_pd())) == 3;
    }
#else
    // std::max, not fmax: the same for these (never -0, a NaN second argument ignored), and inline.
    for (std::size_t k = 0; k < n; ++k) {
      jerk[k] = ref[k] + x[k];
      jpk = std::max(jpk, std::fabs(jerk[k]));
      finite &= std::isfinite(jerk[k]);
    }
#endif
    // A jerk that is not finite fails the solve, whether found before or after any pinning.
    if (!finite) return false;
    if (jpk > kPinOvershoot * jmax) pins = pin;
    // No pass left to pin it: a jerk beyond the limit's slack fails blend_within whatever follows
    // (it fails on that jerk or sooner), so the solve fails now, with the same outcome.
    if (pin >= pins) {
      if (jpk > jmax * (1.0 + kLimitSlack)) return false;
      break;
    }
    // Nothing beyond jmax (the jerks are finite): nothing to pin.
    if (!(jpk > jmax)) break;
    // The jerks to pin (a weight left, beyond jmax), one bit per segment: on x86-64 two segments
    // per SSE2 comparison (the same comparisons).
    std::uint32_t over = 0;
#if SETTLE_PACKED_VECTOR
    {
      const __m128d sign = _mm_set1_pd(-0.0), lim = _mm_set1_pd(jmax), zero = _mm_setzero_pd();
      for (std::size_t k = 0; k < n; k += 2) {
        const __m128d o = _mm_and_pd(_mm_cmpgt_pd(_mm_loadu_pd(&sw[k]), zero),
                                     _mm_cmpgt_pd(_mm_andnot_pd(sign, _mm_loadu_pd(&jerk[k])), lim));
        over |= static_cast<std::uint32_t>(_mm_movemask_pd(o)) << k;
      }
    }
#else
    for (std::size_t k = 0; k < n; ++k) {
      if (sw[k] > 0.0 && std::fabs(jerk[k]) > jmax) over |= std::uint32_t{1} << k;
    }
#endif
    if (over == 0) break;
    for (; over != 0; over &= over - 1) {
      const auto k = static_cast<std::size_t>(std::countr_zero(over));
      // Pin j_k to the limit: its share of every condition goes to the right side, its column
      // leaves the Gram matrix.
      const double to = std::copysign(jmax, jerk[k]), d = to - ref[k], w = sw[k];
      std::array<double, kMaxRows> col;  // NOLINT: rows [0, rows) are set here
      for (std::size_t i = 0; i < rows; ++i) col[i] = mat[i][k];
      for (std::size_t i = 0; i < rows; ++i) rhs[i] -= col[i] * d;
      if (unit) {
        for (std::size_t i = 0; i < rows; ++i) {
          for (std::size_t l = 0; l <= i; ++l) gram[i][l] -= col[i] * col[l];
        }
      } else {
        for (std::size_t i = 0; i < rows; ++i) {
          for (std::size_t l = 0; l <= i; ++l) gram[i][l] -= col[i] * col[l] * w * w;
        }
      }
      ref[k] = to;
      sw[k] = 0.0;
    }
  }
  out.jerk = jerk;
  return true;
}

}  // namespace

namespace {
// A blend seen from its start: its pieces less the start's position, at rest on end - start past
// its end (profile_integral's view of a profile).
struct BlendShape {
  const Blend* b;
  double p0;
  [[nodiscard]] double duration() const noexcept { return b->duration(); }
  [[nodiscard]] double distance() const noexcept { return b->end_position() - p0; }
  [[nodiscard]] int piece_count() const noexcept { return b->piece_count(); }
  [[nodiscard]] Piece piece(int i) const noexcept {
    Piece pc = b->piece(i);
    pc.c[0] -= p0;
    return pc;
  }
};
}  // namespace

ModeMemory mode_memory(const Blend& b, const ModeMemory& at_start, double u, const Mode& mode) noexcept {
  if (!(u > 0.0) || mode_status(mode) != Status::ok) return at_start;
  // Q(u) = e^{lambda u} Q(0) - int_0^u e^{lambda (u - w)} b'(w) dw, and with c(w) = b(w) - b(0) the
  // integral is c(u) + lambda int_0^u e^{lambda (u - w)} c(w) dw (by parts; c(0) = 0).
  const Cx lam = pole(mode.omega, mode.zeta);
  const BlendShape shape{&b, b.start().p};
  const Cx f = profile_integral(shape, lam, u);
  const Cx q = cexp(u * lam) * Cx{at_start.re, at_start.im} - Cx{b.at(u).p - shape.p0, 0.0} - lam * f;
  return {q.re, q.im};
}

namespace {
// The running command's remainder: from `origin` to rest on `end` in `remaining` s; at rest when
// every mode's memory at its end (`end_memory(i)`) is rounding.
template <typename EndMemory>
OnlineRunning running_of(double end, double origin, double remaining, std::size_t modes, EndMemory&& end_memory) noexcept {
  OnlineRunning run{origin, end, std::fmax(remaining, 0.0), true};
  const double tol = kRestMemory * position_scale(origin, end);
  for (std::size_t i = 0; i < modes; ++i) {
    const ModeMemory q = end_memory(i);
    run.at_rest = run.at_rest && std::hypot(q.re, q.im) <= tol;
  }
  return run;
}
}  // namespace

Status online_request(const Blend& b, const OnlineRequest& planned, double u, std::optional<double> target,
                      OnlineRequest& out) noexcept {
  if (!std::isfinite(u) || (target && !std::isfinite(*target))) return Status::non_finite_input;
  if (planned.mode_count > kMaxOnlineModes) return Status::unsupported_request;
  OnlineRequest r = planned;
  r.start = b.at(std::max(u, 0.0));
  r.start.j = 0.0;
  r.target = target;
  for (std::size_t i = 0; i < r.mode_count; ++i) r.memory[i] = mode_memory(b, planned.memory[i], u, r.modes[i]);
  r.running = running_of(b.end_position(), b.start().p, b.duration() - std::max(u, 0.0), r.mode_count,
                         [&](std::size_t i) { return mode_memory(b, planned.memory[i], b.duration(), r.modes[i]); });
  out = r;
  return Status::ok;
}

Status online_limits(const OptionalLimits& limits, const Peaks<double>& pk, const Mode* modes, std::size_t mode_count,
                     OnlineLimits& out) noexcept {
  OnlineLimits l = limits.value_or({pk.v, pk.a, pk.j});
  if (!std::isfinite(l.vmax) || !std::isfinite(l.amax)) return Status::unsupported_request;
  if (!std::isfinite(l.jmax)) {
    double w = 0.0;
    for (std::size_t i = 0; i < mode_count; ++i) w = std::fmax(w, modes[i].omega);
    l.jmax = l.amax * (w > 0.0 ? w : 1.0);
  }
  if (!(l.vmax > 0.0 && l.amax > 0.0 && l.jmax > 0.0)) return Status::non_positive_limit;
  out = l;
  return Status::ok;
}

namespace {
// The request of a change of move m at t (both online_request overloads): each mode's memory at
// the switch, and at the move's end from `at_end` (end_memory's) or, without it, integrated
// together with the one at the switch (one pass).
Status move_request(const Move<double>& m, double t, const Mode* modes, std::size_t mode_count,
                    const OnlineLimits& limits, std::optional<double> target, const EndMemory* at_end,
                    OnlineRequest& out) noexcept {
  if (!std::isfinite(t) || (target && !std::isfinite(*target))) return Status::non_finite_input;
  if (mode_count > kMaxOnlineModes) return Status::unsupported_request;
  OnlineRequest r{};
  r.start = m.at(std::max(t, 0.0));
  r.start.j = 0.0;
  r.limits = limits;
  r.target = target;
  r.mode_count = mode_count;
  std::array<ModeMemory, kMaxOnlineModes> end{};
  for (std::size_t i = 0; i < mode_count; ++i) {
    if (const Status st = mode_status(modes[i]); st != Status::ok) return st;
    r.modes[i] = modes[i];
    if (at_end != nullptr) {
      // The pieces that have ended by t read their sums from at_end (taken for this very mode).
      const EndMemory::Pieces& pc = at_end->pieces[i];
      const bool same = pc.mode.omega == modes[i].omega && pc.mode.zeta == modes[i].zeta;
      r.memory[i] = detail::mode_memory_ended(m, t, modes[i], pc.sum.data(), same ? pc.count : 0);
      end[i] = (*at_end)[i];
    } else {
      detail::mode_memory_pair(m, t, m.duration(), modes[i], r.memory[i], end[i]);
    }
  }
  r.running = running_of(m.distance(), 0.0, m.duration() - std::max(t, 0.0), mode_count,
                         [&](std::size_t i) { return end[i]; });
  out = r;
  return Status::ok;
}
}  // namespace

Status online_request(const Move<double>& m, double t, const Mode* modes, std::size_t mode_count,
                      const OnlineLimits& limits, std::optional<double> target, OnlineRequest& out) noexcept {
  return move_request(m, t, modes, mode_count, limits, target, nullptr, out);
}

Status end_memory(const Move<double>& m, const Mode* modes, std::size_t mode_count, EndMemory& out) noexcept {
  if (mode_count > kMaxOnlineModes) return Status::unsupported_request;
  EndMemory e{};
  for (std::size_t i = 0; i < mode_count; ++i) {
    if (const Status st = mode_status(modes[i]); st != Status::ok) return st;
    e[i] = mode_memory(m, m.duration(), modes[i]);
    e.pieces[i].mode = modes[i];
    e.pieces[i].count = detail::ended_piece_sums(m, modes[i], e.pieces[i].sum.data(), static_cast<int>(kEndMemoryPieces));
  }
  out = e;
  return Status::ok;
}

Status online_request(const Move<double>& m, const EndMemory& at_end, double t, const Mode* modes,
                      std::size_t mode_count, const OnlineLimits& limits, std::optional<double> target,
                      OnlineRequest& out) noexcept {
  return move_request(m, t, modes, mode_count, limits, target, &at_end, out);
}

namespace {

// The request's own checks, before any solve: finite, positive limits, modes in range, a switch
// state within the limits. at_rest: nothing to do (no motion, every memory rounding).
Status check_request(const OnlineRequest& r, bool& at_rest) noexcept {
  const OnlineLimits& l = r.limits;
  if (!finite(r.start) || !std::isfinite(l.vmax) || !std::isfinite(l.amax) || !std::isfinite(l.jmax) ||
      (r.target && !std::isfinite(*r.target))) {
    return Status::non_finite_input;
  }
  if (!(l.vmax > 0.0 && l.amax > 0.0 && l.jmax > 0.0)) return Status::non_positive_limit;
  if (r.mode_count > kMaxOnlineModes) return Status::unsupported_request;
  at_rest = r.start.v == 0.0 && r.start.a == 0.0 && (!r.target || *r.target == r.start.p);
  for (std::size_t i = 0; i < r.mode_count; ++i) {
    if (!std::isfinite(r.memory[i].re) || !std::isfinite(r.memory[i].im)) return Status::non_finite_input;
    if (const Status st = mode_status(r.modes[i]); st != Status::ok) return st;
    // A memory this small is rounding of an exactly cancelled one (a finished zero-residual move).
    at_rest = at_rest && std::hypot(r.memory[i].re, r.memory[i].im) <= 1e-13 * std::fabs(r.start.p);
  }
  // The switch state must itself be within the limits: no blend can undo an excess it starts with.
  if (std::fabs(r.start.v) > l.vmax * (1.0 + kLimitSlack)) return Status::velocity_limit_exceeded;
  if (std::fabs(r.start.a) > l.amax * (1.0 + kLimitSlack)) return Status::acceleration_limit_exceeded;
  // Nor one that must overshoot vmax: taking an acceleration a0 out at jmax adds a0^2 / (2 jmax) to
  // the velocity first (a trapezoid's acceleration steps make such states).
  if (r.start.v * r.start.a > 0.0 &&
      std::fabs(r.start.v) + r.start.a * r.start.a / (2.0 * l.jmax) > l.vmax * (1.0 + kLimitSlack)) {
    return Status::velocity_limit_exceeded;
  }
  return Status::ok;
}

// A duration no blend can beat (lower) and a first guess above it.
void duration_bounds(const OnlineRequest& r, double& lower, double& guess) noexcept {
  const OnlineLimits& l = r.limits;
  // A duration no blend can beat: the time-optimal stop of the velocity alone (every blend ends
  // with v = a = 0), and for a retarget the distance at vmax.
  const Brake exact = velocity_stop(r.start.v, r.start.a, l.amax, l.jmax);
  lower = exact.dur[0] + exact.dur[1] + exact.dur[2];
  // A first guess of the right order: that stop plus half the slowest mode's damped period (what
  // a shaper adds), and for a retarget a rest-to-rest move over the distance.
  double half_period = 0.0;
  for (std::size_t i = 0; i < r.mode_count; ++i) {
    half_period = std::max(half_period, 3.14159265358979323846 / pole(r.modes[i].omega, r.modes[i].zeta).im);
  }
  guess = lower + half_period;
  if (r.target) {
    const double d = std::fabs(*r.target - r.start.p);
    lower = std::max(lower, d / l.vmax);
    guess = std::max({guess, 2.0 * std::sqrt(d / l.amax) + half_period, d / l.vmax + l.vmax / l.amax + half_period,
                      2.0 * std::cbrt(d / l.jmax) + half_period});
  }
  if (!(guess > lower)) guess = lower > 0.0 ? 1.25 * lower : 1e-3;
}

// The five blends tried at each duration (listed in the constructor), and the one that worked last.
struct BlendFamily {
  const OnlineRequest* r{nullptr};
  Brake full{}, soft{}, sharp{};
  std::array<double, kBlendSegments> uniform{}, front{};  // square roots of the weights
  int last{0};
  int tries{0};
  explicit BlendFamily(const OnlineRequest& req) noexcept;
  // Whether a blend of duration t meets the request within the limits; its jerks go to sol (which
  // holds anything when it does not).
  bool feasible(double t, Solved& sol) noexcept;
};

BlendFamily::BlendFamily(const OnlineRequest& req) noexcept : r{&req} {
  const OnlineLimits& l = req.limits;
  full = velocity_stop(req.start.v, req.start.a, 0.995 * l.amax, 0.995 * l.jmax);
  // Five blends per duration, the first within the limits wins (docs/online.md):
  //  0. the time-optimal velocity stop at 99.5 % of the limits, corrected where it leaves jerk headroom
  //     (weights (1 - |j_ref| / jmax)^2): the fastest when vmax or amax is tight;
  //  1. the same stop at 85 % of amax and jmax, corrected by the least uniform jerk;
  //  2. the smoothest blend (least uniform jerk, no reference), good for retargets;
  //  3. the least front-loaded jerk (weights falling as (1 - u/T)^3);
  //  4. the velocity stop at the full jerk limit and 90 % of amax, corrected where it leaves jerk
  //     headroom: from a state whose acceleration must be taken out at the full jerk limit not to
  //     pass vmax (near the peak of an S-curve planned at exactly these limits), the one that can.
  soft = velocity_stop(req.start.v, req.start.a, 0.85 * l.amax, 0.85 * l.jmax);
  sharp = velocity_stop(req.start.v, req.start.a, 0.6 * l.amax, l.jmax);
  for (std::size_t k = 0; k < kBlendSegments; ++k) {
    uniform[k] = 1.0;
    const double x = 1.0 - (static_cast<double>(k) + 0.5) / static_cast<double>(kBlendSegments);
    front[k] = x * std::sqrt(x);
  }
}

constexpr int kBlendKinds = 5;
// Passes that pin jerks at the limit (solve_for) while the duration is bisected; none while it
// grows (five blends per duration there: pinning would multiply the cost where it gains nothing).
constexpr int kPinPasses = 6;

bool BlendFamily::feasible(double t, Solved& sol) noexcept {
  const OnlineLimits& l = r->limits;
  static constexpr std::array<double, kBlendSegments> none{};
  const double h = t / static_cast<double>(kBlendSegments);
  System sys;
  build_system(*r, t, sys);
  std::array<double, kBlendSegments> ref, w;  // NOLINT: set before they are read (sample_brake sets all of ref)
  // The blend that worked last is tried first: neighbouring durations usually agree.
  for (int i = 0; i < tries; ++i) {
    const int c = (i + last) % kBlendKinds;
    const bool braking = c == 0 || c == 1 || c == 4;  // (sample_brake sets all of ref)
    std::size_t ref_len = 0;  // segments of the reference up to its trailing +0s (none: no reference)
    if (c == 0 || c == 4) {
      ref_len = sample_brake(c == 0 ? full : sharp, h, ref);
      for (std::size_t k = 0; k < kBlendSegments; ++k) w[k] = 1.0 - std::fabs(ref[k]) / l.jmax;
    } else if (c == 1) {
      ref_len = sample_brake(soft, h, ref);
    }
    const int pins = tries > 1 ? 0 : kPinPasses;
    const bool unit = c == 1 || c == 2;
    if (!solve_for(sys, braking ? ref : none, c == 0 || c == 4 ? w : c == 3 ? front : uniform, ref_len, unit, l.jmax,
                   pins, sol)) {
      continue;
    }
    if (!blend_within(r->start, h, sol.jerk, l)) continue;
    last = c;
    return true;
  }
  return false;
}

// The fastest blend of the family that meets the request within the limits (docs/online.md).
// No blend longer than `cap` is of use (a halt that can finish its command at rest sooner): the
// search stops there (no_solution) instead of growing on. No blend of `lose` or longer is of use
// either (a blend to the end that a shorter fastest blend beats): the search gives up
// (no_solution) as soon as a duration it rejects reaches it, since what it would find is longer.
// `tried` counts the durations tried.
Status plan_blend(const OnlineRequest& r, Blend& out, int& tried, double cap = HUGE_VAL,
                  double lose = HUGE_VAL) noexcept {
  bool at_rest = false;
  const Status st = check_request(r, at_rest);
  if (st != Status::ok) return st;
  if (at_rest) {
    out = Blend{r.start, 0.0, {}};
    return Status::ok;
  }
  double lower = 0.0, guess = 0.0;
  duration_bounds(r, lower, guess);
  Solved sol{};
  BlendFamily fam{r};
  fam.tries = kBlendKinds;
  const auto feasible = [&](double t) {
    ++tried;
    return fam.feasible(t, sol);
  };
  // Bracket: grow until feasible, then bisect down towards the first feasible duration.
  double lo = lower, hi = std::min(guess, cap);
  int grow = 0;
  while (!feasible(hi)) {
    if (!(hi < cap) || ++grow > 60) return Status::no_solution;
    lo = hi;
    if (lo >= lose) return Status::no_solution;
    hi = std::min(hi * 1.5, cap);
  }
  // Bisection on the blend that made the bracket (`last`) alone: a quarter of the solves, and the
  // duration found is that blend's shortest to within 0.5 %.
  Solved best = sol;
  fam.tries = 1;
  for (int it = 0; it < 40 && hi - lo > 5e-3 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid > lo && feasible(mid)) {
      hi = mid;
      best = sol;
    } else {
      lo = mid;
      if (lo >= lose) return Status::no_solution;  // hi > lo: no shorter than `lose` either
    }
  }
  out = Blend{r.start, hi / static_cast<double>(kBlendSegments), best.jerk};
  return Status::ok;
}

}  // namespace

Status plan_online(const OnlineRequest& r, OnlinePlan& out) noexcept {
  // A halt of a command that ends at rest takes a blend only if it comes to rest sooner than the
  // command (else finishing it is the halt): the search need not look beyond the command's
  // remaining time, less 1e-6 of it (a blend that merely retraces the command's own final stop
  // gains nothing, and at that boundary rounding and the limits' 1e-9 slack alone would decide,
  // differently on each of several path axes).
  const bool halt = !r.target && r.running;
  const double cap = halt && r.running->at_rest && std::isfinite(r.running->remaining)
                         ? std::fmax(r.running->remaining, 0.0) * (1.0 - 1e-6)
                         : HUGE_VAL;
  Blend fastest{};
  int tried = 0;
  const Status st = plan_blend(r, fastest, tried, cap);
  if (r.target || !r.running) {
    if (st != Status::ok) return st;
    OnlinePlan p{};
    p.blend = fastest;
    p.rest_after = fastest.duration();
    p.durations_tried = tried;
    out = p;
    return Status::ok;
  }
  // A halt of a command that would run on to `end`, at rest there after `remaining`.
  // Refusals of the request itself stand; "no blend of the family fits" leaves the other choices.
  if (st != Status::ok && st != Status::no_solution) return st;
  const OnlineRunning& run = *r.running;
  if (!std::isfinite(run.origin) || !std::isfinite(run.end) || !std::isfinite(run.remaining)) {
    return Status::non_finite_input;
  }
  const double remaining = std::fmax(run.remaining, 0.0);
  const double dir = run.end > run.origin ? 1.0 : run.end < run.origin ? -1.0 : 0.0;
  const double tol_p = 1e-12 * position_scale(run.origin, run.end);
  const auto beyond = [&](const Blend& b) { return dir * (b.end_position() - run.end) > tol_p; };
  const auto later = [&](double rest) { return rest > remaining * (1.0 + 1e-12) + 1e-15; };
  OnlinePlan p{};
  p.durations_tried = tried;
  if (st == Status::ok) {
    p.fastest_passes_target = beyond(fastest);
    p.fastest_ends_later = later(fastest.duration());
    if (!p.fastest_passes_target && !p.fastest_ends_later) {
      p.blend = fastest;
      p.rest_after = fastest.duration();
      out = p;
      return Status::ok;
    }
  } else {
    // None within the command's remaining time, or none at all.
    p.fastest_ends_later = true;
    p.fastest_passes_target = !(cap < HUGE_VAL);
  }
  // A blend that ends on the command's end: it cannot pass it, and may come to rest sooner than
  // the command would.
  OnlineRequest rt = r;
  rt.target = run.end;
  rt.running.reset();
  Blend to{};
  // The command leaves a mode ringing (no finish) and the fastest blend stops short: it wins a tie
  // with the blend to the end (below), so that blend's search gives up once it is sure to find
  // nothing shorter (the same choice and blend as a whole search, fewer durations).
  const double lose = !run.at_rest && st == Status::ok && !p.fastest_passes_target ? fastest.duration() : HUGE_VAL;
  const bool have_to = plan_blend(rt, to, p.durations_tried, cap, lose) == Status::ok;
  if (run.at_rest) {
    // Finishing the command is a zero-residual halt on its end at its end: the better of that and
    // the blend to the end.
    if (have_to && to.duration() < remaining) {
      p.choice = OnlineChoice::to_target;
      p.blend = to;
      p.rest_after = to.duration();
    } else {
      p.choice = OnlineChoice::finish;
      p.rest_after = remaining;
    }
    out = p;
    return Status::ok;
  }
  // The command itself leaves a mode ringing: no finish. The sooner at rest of the fastest blend
  // (when it stops short) and the blend to the end.
  const bool fastest_ok = st == Status::ok && !p.fastest_passes_target;
  if (!fastest_ok && !have_to) return Status::halt_passes_target;
  if (fastest_ok && (!have_to || fastest.duration() <= to.duration())) {
    p.blend = fastest;
  } else {
    p.choice = OnlineChoice::to_target;
    p.blend = to;
  }
  p.rest_after = p.blend.duration();
  p.ends_later = later(p.rest_after);
  out = p;
  return Status::ok;
}

Status plan_online(const OnlineRequest& r, Blend& out) noexcept {
  OnlinePlan p{};
  const Status st = plan_online(r, p);
  if (st != Status::ok) return st;
  if (p.choice == OnlineChoice::finish) return Status::halt_finishes_command;
  out = p.blend;
  return Status::ok;
}

std::size_t design_modes(const MoveRequest& req, std::array<Mode, kMaxOnlineModes>& out,
                         const Mode* fallback) noexcept {
  std::size_t n = 0;
  if (req.has_mode()) {
    for (std::size_t i = 0; i < req.mode_count && i < kMaxModes && n < kMaxOnlineModes; ++i) out[n++] = req.modes[i];
  } else if (fallback != nullptr) {
    out[n++] = *fallback;
  }
  return n;
}

}  // namespace settle::core
