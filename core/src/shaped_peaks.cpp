// SPDX-License-Identifier: Apache-2.0
// True peaks of a shaped move, sum_i A_i p(t - t_i), found exactly: between consecutive breakpoints
// (the profile's piece boundaries shifted by every impulse time, merged on the fly) every delayed
// copy sits inside one piece (piece.hpp), so the shaped motion there is one polynomial plus one
// phasor (detail::PhasorPoly), whose extrema detail::max_abs_derivative finds from the roots of
// its derivatives. A dense scan is kept only for shapes without such a decomposition (a
// pseudo-polynomial with non-integer exponents) or with phasors of different periods.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "extrema.hpp"
#include "settle/core/planner.hpp"

namespace settle::core {

namespace {

// Bound on any registered shape's piece count (fastest's 31 constant-jerk segments at most).
constexpr int kMaxPieces = 32;
constexpr double kTwoPi = 6.283185307179586476925286766559;

struct PeakFlags {
  bool v, a, j;
};

// Adds amp * (the piece from local time u of the piece onwards) to f, in the interval's local time.
void add_piece(detail::PhasorPoly& f, const Piece& pc, double amp, double u) noexcept {
  constexpr int kMax = static_cast<int>(kMaxPieceDegree);
  static_assert(kMax <= detail::PhasorPoly::kDegree);
  const double il = 1.0 / pc.length;
  const double s0 = u * il;
  int n = kMax;  // its degree (cubic for constant-jerk and ramp-cycloid pieces)
  while (n > 0 && pc.c[static_cast<std::size_t>(n)] == 0.0) --n;
  double d[kMax + 1]{};
  for (int k = 0; k <= n; ++k) d[k] = pc.c[static_cast<std::size_t>(k)];
  // Taylor shift: d becomes the coefficients of P(s0 + y) in y.
  for (int i = 0; i < n; ++i) {
    for (int k = n - 1; k >= i; --k) d[k] += s0 * d[k + 1];
  }
  double scale = amp;
  for (int k = 1; k <= n; ++k) {  // b[0], the position, is not needed for v, a, j
    scale *= il;
    f.b[k] += scale * d[k];
  }
  if (pc.trig) {
    const double c = std::cos(kTwoPi * s0), s = std::sin(kTwoPi * s0);
    f.wr += amp * (pc.zr * c - pc.zi * s);
    f.wi += amp * (pc.zr * s + pc.zi * c);
    f.w = kTwoPi * il;
  }
}

void update(Peaks<double>& out, const detail::PhasorPoly& f, double len, PeakFlags want) noexcept {
  if (want.v) out.v = std::max(out.v, detail::max_abs_derivative(f, 1, len));
  if (want.a) out.a = std::max(out.a, detail::max_abs_derivative(f, 2, len));
  if (want.j) out.j = std::max(out.j, detail::max_abs_derivative(f, 3, len));
}

// The exact peaks of sum_i A_i shape(t - t_i), for a shape that decomposes into pieces.
// piece_of(k) returns piece k of count; starts are read once (count + 1 boundaries).
template <typename PieceOf>
void exact_peaks(PieceOf&& piece_of, int count, double duration, const Shaper<double>& s, PeakFlags want,
                 Peaks<double>& out) noexcept {
  double bound[kMaxPieces + 1];
  for (int k = 0; k < count; ++k) bound[k] = piece_of(k).start;
  bound[count] = duration;
  const std::size_t m = s.count;
  std::uint8_t next[kMaxImpulses]{};  // per copy: its first boundary not yet passed
  double t = s.time[0] + bound[0];
  for (std::size_t i = 1; i < m; ++i) t = std::min(t, s.time[i] + bound[0]);
  for (;;) {
    double hi = infinity_v<double>;
    for (std::size_t i = 0; i < m; ++i) {
      while (next[i] <= count && s.time[i] + bound[next[i]] <= t) ++next[i];
      if (next[i] <= count) hi = std::min(hi, s.time[i] + bound[next[i]]);
    }
    if (!(hi < infinity_v<double>)) break;
    const double len = hi - t;
    if (len > 0.0) {
      detail::PhasorPoly f{};
      for (std::size_t i = 0; i < m; ++i) {
        if (next[i] == 0 || next[i] > count) continue;  // not started, or at rest on its target
        const Piece pc = piece_of(next[i] - 1);
        add_piece(f, pc, s.amp[i], t - s.time[i] - pc.start);
      }
      update(out, f, len, want);
    }
    t = hi;
  }
}

// Whether every phasor of the shape has one period (the exact path's precondition).
template <typename PieceOf>
bool one_period(PieceOf&& piece_of, int count) noexcept {
  double len = 0.0;
  for (int k = 0; k < count; ++k) {
    const Piece pc = piece_of(k);
    if (!pc.trig) continue;
    if (len == 0.0) len = pc.length;
    if (std::fabs(pc.length - len) > 1e-12 * len) return false;
  }
  return true;
}

// poly345 and every pseudo-polynomial with integer exponents up to kMaxPieceDegree is a
// polynomial: D [1 - sum_i C_i (1 - s)^gamma_i] expanded in s. False otherwise.
bool pseudo_poly_piece(const PseudoPolyParams& p, Piece& out) noexcept {
  Piece pc{};
  pc.length = p.duration;
  pc.c[0] = p.distance;
  for (std::size_t i = 0; i < p.count; ++i) {
    const double g = p.gammas[i];
    if (!(g == std::floor(g) && g >= 0.0 && g <= static_cast<double>(kMaxPieceDegree))) return false;
    const int n = static_cast<int>(g);
    double binom = 1.0;  // C(n, k) (-1)^k
    for (int k = 0; k <= n; ++k) {
      pc.c[static_cast<std::size_t>(k)] -= p.distance * p.coeffs[i] * binom;
      binom = -binom * static_cast<double>(n - k) / static_cast<double>(k + 1);
    }
  }
  out = pc;
  return true;
}

}  // namespace

Peaks<double> shaped_peaks(const Profile<double>& p, const Shaper<double>& s, const Peaks<double>& unshaped) noexcept {
  if (s.is_identity()) return unshaped;
  Peaks<double> out = unshaped;
  // A Dirac in the profile stays a Dirac after shaping: keep the infinite peaks and flags.
  const PeakFlags want{std::isfinite(unshaped.v), std::isfinite(unshaped.a), std::isfinite(unshaped.j)};
  if (want.v) out.v = 0.0;
  if (want.a) out.a = 0.0;
  if (want.j) out.j = 0.0;
  const bool exact = p.visit([&](const auto& shape) {
    if constexpr (requires { shape.piece_count(); }) {
      const auto piece_of = [&](int k) { return shape.piece(k); };
      const int n = shape.piece_count();
      if (n > kMaxPieces || !one_period(piece_of, n)) return false;
      if (n > 0) exact_peaks(piece_of, n, static_cast<double>(shape.duration()), s, want, out);
      return true;
    } else if constexpr (requires { shape.params().gammas; }) {
      Piece pc{};
      if (!(shape.params().duration > 0.0) || !pseudo_poly_piece(shape.params(), pc)) return false;
      exact_peaks([&](int) { return pc; }, 1, pc.length, s, want, out);
      return true;
    } else {
      return false;
    }
  });
  if (exact) return out;
  // No exact decomposition: scan the shaped move densely.
  const auto at = [&](double t) {
    Sample<double> acc{};
    for (std::size_t i = 0; i < s.count; ++i) {
      const Sample<double> x = p.at(t - s.time[i]);
      acc.v += s.amp[i] * x.v;
      acc.a += s.amp[i] * x.a;
      acc.j += s.amp[i] * x.j;
    }
    return acc;
  };
  const double t1 = p.duration() + s.duration();
  if (want.v) out.v = detail::max_abs([&](double t) { return at(t).v; }, 0.0, t1, 1024);
  if (want.a) out.a = detail::max_abs([&](double t) { return at(t).a; }, 0.0, t1, 1024);
  if (want.j) out.j = detail::max_abs([&](double t) { return at(t).j; }, 0.0, t1, 1024);
  return out;
}

}  // namespace settle::core
