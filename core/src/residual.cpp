// SPDX-License-Identifier: Apache-2.0
// The residual vibration of a move on a mode (residual.hpp), and the exact integrals of the
// pieces against a mode's exponential that it and the online blends share (mode_integral.hpp).
#include "settle/core/residual.hpp"

#include <array>
#include <cmath>
#include <limits>

#include "mode_integral.hpp"
#include "numeric/complex.hpp"

namespace settle::core {

namespace detail {

using namespace numeric;

namespace {
// 1 / n for n = 0..39 (entry 0 unused), each the double the division 1.0 / n rounds to: the series
// (phi1, phi2, the moments) read them instead of converting and dividing per term (the same terms
// to the bit).
constexpr std::array<double, 40> kInverse = [] {
  std::array<double, 40> inv{};
  for (std::size_t n = 1; n < inv.size(); ++n) inv[n] = 1.0 / static_cast<double>(n);
  return inv;
}();
static_assert(kInverse.size() > 32 + kMaxPieceDegree, "the moments' series reach 1 / (31 + m + 1)");

}  // namespace

Cx phi1(Cx x) noexcept { return phi1(x, cabs_max(x) >= 0.5 ? cexp(x) : Cx{}); }
Cx phi1(Cx x, Cx ex) noexcept {
  if (cabs_max(x) >= 0.5) return (ex - Cx{1.0, 0.0}) / x;
  const PackedFactor px{x};
  Packed term = pack(Cx{1.0, 0.0}), sum = term;
#if SETTLE_PACKED_VECTOR  // unrolled where Packed is a vector (not on the Cortex-M cores: their flash)
#pragma GCC unroll 20
#endif
  for (std::size_t n = 1; n < 20; ++n) {
    term = splat(kInverse[n + 1]) * (term * px);
    sum = sum + term;
  }
  return unpack(sum);
}
Cx phi2(Cx x, Cx ex) noexcept {
  if (cabs_max(x) >= 1.0) return (ex - Cx{1.0, 0.0} - x) / (x * x);
  const PackedFactor px{x};
  Packed term = pack(Cx{0.5, 0.0}), sum = term;
#if SETTLE_PACKED_VECTOR  // unrolled where Packed is a vector (not on the Cortex-M cores: their flash)
#pragma GCC unroll 24
#endif
  for (std::size_t n = 1; n < 24; ++n) {
    term = splat(kInverse[n + 2]) * (term * px);
    sum = sum + term;
  }
  return unpack(sum);
}

namespace {

// J_m(z, S) = int_0^S s^m e^{-z s} ds for m = 0..kMaxPieceDegree, Re z >= 0, 0 <= S <= 1: by the
// power series when |z| S is small, by the upward recurrence otherwise (it then loses at most a
// factor prod m / |z S| <= 4 of accuracy).
void moments(Cx z, double s, std::array<Cx, kMaxPieceDegree + 1>& out) noexcept {
  if (cabs_max(z) * s < 1.5) {
    // J_m = S^{m+1} sum_n c_n / (n + m + 1), c_n = (-z S)^n / n!: the c_n once for every m.
    const Cx mzs = (-s) * z;
    std::array<Cx, 32> c{};
    c[0] = {1.0, 0.0};
    std::size_t nt = 1;
    while (nt < c.size() && cabs_max(c[nt - 1]) > 1e-18) {
      c[nt] = kInverse[nt] * (c[nt - 1] * mzs);
      ++nt;
    }
    double sp = s;  // S^{m+1}
    for (std::size_t m = 0; m <= kMaxPieceDegree; ++m) {
      Cx sum{};
      for (std::size_t k = 0; k < nt; ++k) sum = sum + kInverse[k + m + 1] * c[k];
      out[m] = sp * sum;
      sp *= s;
    }
    return;
  }
  const Cx e = cexp(-s * z);
  out[0] = (Cx{1.0, 0.0} - e) / z;
  double sm = 1.0;
  for (std::size_t m = 1; m <= kMaxPieceDegree; ++m) {
    sm *= s;
    out[m] = (static_cast<double>(m) * out[m - 1] - sm * e) / z;
  }
}

}  // namespace

// A piece's integral without its last factor, len e^{lambda (te - u_c)}: the piece's own sum, given
// its clipped end u_c. It depends on te only through u_c, so a piece that ends before two te (clipped
// alike) has one sum for both (add_piece).
Cx piece_sum(const Piece& pc, Cx lam, double uc) noexcept;

// int over one piece, from its start to u_c = min(end, te), of e^{lambda (te - u)} P(u) du, exactly.
// With u = u_c - L sigma the kernel decays along sigma (Re lambda <= 0): no overflow for long
// pieces or heavy damping.
Cx piece_integral(const Piece& pc, Cx lam, double te) noexcept {
  const double uc = std::min(pc.start + pc.length, te);
  return pc.length * (cexp((te - uc) * lam) * piece_sum(pc, lam, uc));
}

// piece_integral at te1 and te2 for a piece clipped alike at both (u_c its clipped end at either),
// each the same to the bit as alone: the sum is taken once.
void piece_integrals(const Piece& pc, Cx lam, double te1, double te2, double uc, Cx& f1, Cx& f2) noexcept {
  const Cx sum = piece_sum(pc, lam, uc);
  f1 = pc.length * (cexp((te1 - uc) * lam) * sum);
  f2 = pc.length * (cexp((te2 - uc) * lam) * sum);
}

void add_piece(const Piece& pc, Cx lam, double te1, double te2, double body1, double body2, bool both, Cx& acc1,
               Cx& acc2, const ModeMemory* ended) noexcept {
  if (!(pc.length > 0.0)) return;
  const bool in1 = !(pc.start >= body1), in2 = both && !(pc.start >= body2);
  const double end = pc.start + pc.length;
  const double uc1 = std::min(end, te1), uc2 = std::min(end, te2);
  if (in1 && in2 && uc1 == uc2) {
    Cx p1{}, p2{};
    piece_integrals(pc, lam, te1, te2, uc1, p1, p2);
    acc1 = acc1 + p1;
    acc2 = acc2 + p2;
    return;
  }
  if (in1 && ended != nullptr && end <= te1) {
    // Ended by te1: u_c is its end, and its sum the one taken there (piece_integral's own terms).
    acc1 = acc1 + pc.length * (cexp((te1 - uc1) * lam) * Cx{ended->re, ended->im});
  } else if (in1) {
    acc1 = acc1 + piece_integral(pc, lam, te1);
  }
  if (in2) acc2 = acc2 + piece_integral(pc, lam, te2);
}

void add_rest(double distance, double tp, double te, Cx lam, Cx& acc) noexcept {
  if (te > tp) acc = acc + (distance * (te - tp)) * phi1((te - tp) * lam);
}

Cx piece_sum(const Piece& pc, Cx lam, double uc) noexcept {
  constexpr double w = 6.283185307179586476925286766559;
  constexpr double binom[6][6] = {{1, 0, 0, 0, 0, 0},   {1, 1, 0, 0, 0, 0},    {1, 2, 1, 0, 0, 0},
                                  {1, 3, 3, 1, 0, 0},   {1, 4, 6, 4, 1, 0},    {1, 5, 10, 10, 5, 1}};
  const double len = pc.length;
  const double s = (uc - pc.start) / len;
  const Cx nu = -len * lam;
  std::array<Cx, kMaxPieceDegree + 1> jm{};
  moments(nu, s, jm);
  // P(S - sigma) = sum_m b_m sigma^m.
  Cx acc{};
  for (std::size_t m = 0; m <= kMaxPieceDegree; ++m) {
    double b = 0.0, sp = 1.0;
    for (std::size_t k = m; k <= kMaxPieceDegree; ++k) {
      b += pc.c[k] * binom[k][m] * sp;
      sp *= s;
    }
    if (m % 2 == 1) b = -b;
    acc = acc + b * jm[m];
  }
  if (pc.trig) {
    // Im(W e^{-i w sigma}) with W = Z e^{i w S}: (W J0(nu + i w) - conj(W) J0(nu - i w)) / (2i).
    const Cx wz = Cx{pc.zr, pc.zi} * Cx{std::cos(w * s), std::sin(w * s)};
    const Cx j_plus = s * phi1(-s * (nu + Cx{0.0, w}));
    const Cx j_minus = s * phi1(-s * (nu - Cx{0.0, w}));
    acc = acc + (wz * j_plus - conj(wz) * j_minus) / Cx{0.0, 2.0};
  }
  return acc;
}

}  // namespace detail

using namespace numeric;

namespace {

// Q at t1 and, when `two`, at t2 (mode_memory, mode_memory_pair). Q(t) = -int_0^t e^{lambda (t-s)}
// x'(s) ds = -x(t) - lambda int_0^t e^{lambda (t-s)} x(s) ds, and the shaped x is sum_i A_i p(s - t_i):
// each impulse contributes its profile's integral, each sum in the order of the impulses; an
// impulse whose profile is integrated to both times shares the pieces that end before both
// (profile_integrals). One call of the profile per impulse, so that each profile's integral is
// expanded once in the code (the Cortex-M cores' flash).
void memories(const Move<double>& m, double t1, double t2, bool two, Cx lam, ModeMemory& q1, ModeMemory& q2,
              const ModeMemory* ended = nullptr, int n_ended = 0) noexcept {
  const bool on1 = t1 > 0.0, on2 = two && t2 > 0.0;
  Cx acc1{}, acc2{};
  const Shaper<double>& sh = m.shaper();
  for (std::size_t i = 0; i < sh.count; ++i) {
    const double te1 = t1 - sh.time[i], te2 = t2 - sh.time[i];
    const bool in1 = on1 && te1 > 0.0, in2 = on2 && te2 > 0.0;
    if (!in1 && !in2) continue;
    // The first integral at te1 (or te2 alone), the second at te2 when both are wanted.
    Cx fa{}, fb{};
    m.profile().visit([&](const auto& p) {
      detail::profile_integrals(p, lam, in1 ? te1 : te2, te2, in1 && in2, fa, fb, ended, n_ended);
    });
    if (in1) acc1 = acc1 + sh.amp[i] * fa;
    if (in1 && in2) acc2 = acc2 + sh.amp[i] * fb;
    if (!in1) acc2 = acc2 + sh.amp[i] * fa;
  }
  if (on1) {
    const Cx q = Cx{-m.at(t1).p, 0.0} - lam * acc1;
    q1 = {q.re, q.im};
  }
  if (on2) {
    const Cx q = Cx{-m.at(t2).p, 0.0} - lam * acc2;
    q2 = {q.re, q.im};
  }
}

}  // namespace

ModeMemory mode_memory(const Move<double>& m, double t, const Mode& mode) noexcept {
  return detail::mode_memory_ended(m, t, mode, nullptr, 0);
}

ModeMemory detail::mode_memory_ended(const Move<double>& m, double t, const Mode& mode, const ModeMemory* ended,
                                     int n) noexcept {
  if (!(t > 0.0) || mode_status(mode) != Status::ok) return {};
  ModeMemory q{}, unused{};
  memories(m, t, t, false, pole(mode.omega, mode.zeta), q, unused, ended, n);
  return q;
}

int detail::ended_piece_sums(const Move<double>& m, const Mode& mode, ModeMemory* out, int n) noexcept {
  if (mode_status(mode) != Status::ok) return 0;
  const Cx lam = pole(mode.omega, mode.zeta);
  return m.profile().visit([&](const auto& p) {
    int count = 0;
    if constexpr (requires { p.piece_count(); }) {
      count = std::min(p.piece_count(), n);
      for (int i = 0; i < count; ++i) {
        const Piece pc = p.piece(i);
        // The sum add_piece takes for a piece ended by te (u_c = min(end, te) is its end); a piece
        // of no length is passed over there, and its entry never read.
        const Cx sum = pc.length > 0.0 ? piece_sum(pc, lam, pc.start + pc.length) : Cx{};
        out[i] = {sum.re, sum.im};
      }
    }
    return count;
  });
}

void detail::mode_memory_pair(const Move<double>& m, double t1, double t2, const Mode& mode, ModeMemory& q1,
                              ModeMemory& q2) noexcept {
  q1 = {};
  q2 = {};
  if (mode_status(mode) != Status::ok) return;
  memories(m, t1, t2, true, pole(mode.omega, mode.zeta), q1, q2);
}

double residual_amplitude(const Move<double>& m, const Mode& mode) noexcept {
  if (mode_status(mode) != Status::ok) return std::numeric_limits<double>::quiet_NaN();
  const ModeMemory q = mode_memory(m, m.duration(), mode);
  return std::hypot(q.re, q.im) / std::sqrt(1.0 - mode.zeta * mode.zeta);
}

double residual_ratio(const Move<double>& m, const Mode& mode) noexcept {
  const double amp = residual_amplitude(m, mode);
  if (m.distance() == 0.0 && !std::isnan(amp)) return 0.0;
  return amp * std::sqrt(1.0 - mode.zeta * mode.zeta) / std::fabs(m.distance());
}

namespace {

// Laplace transform of the table's acceleration at s, times e^{s T} (T its duration): the move
// starts from rest with a = 0, so A(s) = sum_i j_i (e^{-s t_i} - e^{-s t_{i+1}}) / s^2. Referred
// to the end every exponential has magnitude <= 1 for a stable pole, so long moves on damped
// modes neither overflow nor cancel.
Cx accel_transform_at_end(const double* durations, const double* jerk, std::size_t count, Cx s) noexcept {
  double total = 0.0;
  for (std::size_t i = 0; i < count; ++i) total += durations[i];
  // j_i (e^{s (T - t_i)} - e^{s (T - t_{i+1})}) = j_i e^{s (T - t_{i+1})} (e^{s d_i} - 1)
  Cx acc{};
  double t = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double t1 = t + durations[i];
    if (jerk[i] != 0.0) acc = acc + jerk[i] * (cexp_neg(s, t1 - total) * cexpm1(durations[i] * s));
    t = t1;
  }
  const Cx s2 = s * s;
  const double n2 = s2.re * s2.re + s2.im * s2.im;
  return (1.0 / n2) * (acc * Cx{s2.re, -s2.im});
}

}  // namespace

double jerk_table_residual_amplitude(const double* durations, const double* jerk, std::size_t count,
                                     const Mode& mode) noexcept {
  const double omega = mode.omega, zeta = mode.zeta;
  if (mode_status(omega, zeta) != Status::ok) return std::numeric_limits<double>::quiet_NaN();
  return cabs(accel_transform_at_end(durations, jerk, count, pole(omega, zeta))) / (omega * std::sqrt(1.0 - zeta * zeta));
}

}  // namespace settle::core
