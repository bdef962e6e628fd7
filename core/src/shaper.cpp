#include "settle/core/shaper.hpp"

#include <algorithm>
#include <cmath>

#include "settle/core/small_solve.hpp"

namespace settle::core {

namespace {

constexpr double pi = 3.14159265358979323846264338327950;

bool valid_mode(double omega, double zeta, Status& st) noexcept {
  if (!std::isfinite(omega) || !std::isfinite(zeta)) {
    st = Status::non_finite_input;
    return false;
  }
  if (!(omega > 0.0)) {
    st = Status::non_positive_omega;
    return false;
  }
  if (!(zeta >= 0.0 && zeta < 1.0)) {
    st = Status::zeta_out_of_range;
    return false;
  }
  return true;
}

// Impulses at multiples of half the damped period with binomial weights in K: ZV (order 1),
// ZVD (2), ZVDD (3). Each extra order adds a zero derivative of V with respect to omega.
Shaper<double> binomial_shaper(int order, double omega, double zeta) noexcept {
  const double beta = std::sqrt(1.0 - zeta * zeta);
  const double k = std::exp(-zeta * pi / beta);
  const double half = pi / (omega * beta);
  Shaper<double> s{};
  s.count = static_cast<std::size_t>(order + 1);
  double binom = 1.0, kp = 1.0, sum = 0.0;
  for (int i = 0; i <= order; ++i) {
    s.amp[static_cast<std::size_t>(i)] = binom * kp;
    s.time[static_cast<std::size_t>(i)] = i * half;
    sum += binom * kp;
    binom = binom * (order - i) / (i + 1);
    kp *= k;
  }
  for (std::size_t i = 0; i < s.count; ++i) s.amp[i] /= sum;
  return s;
}

// C and S sums of the residual-vibration formula at frequency w (nominal frequency 1), and their
// derivatives with respect to w.
struct CS {
  double c, s, dc, ds;
};
CS cs_sums(const double* a, const double* t, std::size_t n, double w, double zeta) noexcept {
  const double beta = std::sqrt(1.0 - zeta * zeta);
  CS r{0.0, 0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < n; ++i) {
    const double e = a[i] * std::exp(zeta * w * t[i]);
    const double th = w * beta * t[i];
    const double co = std::cos(th), si = std::sin(th);
    r.c += e * co;
    r.s += e * si;
    r.dc += e * t[i] * (zeta * co - beta * si);
    r.ds += e * t[i] * (zeta * si + beta * co);
  }
  return r;
}

// Extra-insensitive shaper, three impulses, for nominal frequency 1. Unknowns
// x = (A1, A2, A3, t2, t3, w1, w2); conditions: sum A = 1; V(1) = vtol; dV/dw(1) = 0; zero residual
// (C = S = 0) at two frequencies w1 < 1 < w2. With zeta = 0 the solution is the classic symmetric
// EI ((1+V)/4, (1-V)/2, (1+V)/4 at 0, T/2, T); with damping it is solved by Newton's method.
void ei_residuals(const std::array<double, 7>& x, double zeta, double vtol, std::array<double, 7>& f) noexcept {
  const double a[3] = {x[0], x[1], x[2]};
  const double t[3] = {0.0, x[3], x[4]};
  const CS m = cs_sums(a, t, 3, 1.0, zeta);
  const double decay = std::exp(-zeta * t[2]);
  f[0] = a[0] + a[1] + a[2] - 1.0;
  f[1] = decay * std::sqrt(m.c * m.c + m.s * m.s) - vtol;
  f[2] = -zeta * t[2] * (m.c * m.c + m.s * m.s) + m.c * m.dc + m.s * m.ds;
  const CS z1 = cs_sums(a, t, 3, x[5], zeta);
  const CS z2 = cs_sums(a, t, 3, x[6], zeta);
  f[3] = z1.c;
  f[4] = z1.s;
  f[5] = z2.c;
  f[6] = z2.s;
}

bool ei_newton(std::array<double, 7>& x, double zeta, double vtol) noexcept {
  std::array<double, 7> f{}, fh{};
  for (int it = 0; it < 60; ++it) {
    ei_residuals(x, zeta, vtol, f);
    double norm = 0.0;
    for (double v : f) norm = std::max(norm, std::fabs(v));
    if (norm < 1e-14) return true;
    std::array<std::array<double, 7>, 7> jac{};
    for (std::size_t c = 0; c < 7; ++c) {
      std::array<double, 7> xh = x;
      const double h = 1e-7 * std::max(1.0, std::fabs(x[c]));
      xh[c] += h;
      ei_residuals(xh, zeta, vtol, fh);
      for (std::size_t r = 0; r < 7; ++r) jac[r][c] = (fh[r] - f[r]) / h;
    }
    std::array<double, 7> step = f;
    if (!solve_in_place(jac, step, 7, 1e-15)) return false;
    for (std::size_t c = 0; c < 7; ++c) x[c] -= step[c];
  }
  ei_residuals(x, zeta, vtol, f);
  double norm = 0.0;
  for (double v : f) norm = std::max(norm, std::fabs(v));
  return norm < 1e-11;
}

Status ei_shaper(double omega, double zeta, double vtol, Shaper<double>& out) noexcept {
  // Start from the exact undamped solution and follow it in zeta (continuation) so that Newton
  // stays in the basin of the right branch even for heavy damping.
  const double x1 = std::acos(-(1.0 - vtol) / (1.0 + vtol));
  std::array<double, 7> x{(1.0 + vtol) / 4.0, (1.0 - vtol) / 2.0, (1.0 + vtol) / 4.0, pi, 2.0 * pi,
                          x1 / pi, (2.0 * pi - x1) / pi};
  const int steps = std::max(1, static_cast<int>(std::ceil(zeta / 0.02)));
  for (int k = 1; k <= steps; ++k) {
    const double z = zeta * k / steps;
    if (!ei_newton(x, z, vtol)) return Status::no_solution;
  }
  if (zeta == 0.0 && !ei_newton(x, 0.0, vtol)) return Status::no_solution;
  if (!(x[3] > 0.0 && x[4] > x[3] && x[0] > 0.0 && x[1] > 0.0 && x[2] > 0.0)) return Status::no_solution;
  Shaper<double> s{};
  s.count = 3;
  s.amp = {x[0], x[1], x[2]};
  s.time = {0.0, x[3] / omega, x[4] / omega};
  out = s;
  return Status::ok;
}

}  // namespace

Status design_shaper(ShaperKind kind, double omega, double zeta, double vtol, Shaper<double>& out) noexcept {
  if (kind == ShaperKind::none) {
    out = Shaper<double>{};
    return Status::ok;
  }
  if (kind == ShaperKind::custom) return Status::unsupported_request;  // use custom_shaper()
  Status st = Status::ok;
  if (!valid_mode(omega, zeta, st)) return st;
  switch (kind) {
    case ShaperKind::zv: out = binomial_shaper(1, omega, zeta); return Status::ok;
    case ShaperKind::zvd: out = binomial_shaper(2, omega, zeta); return Status::ok;
    case ShaperKind::zvdd: out = binomial_shaper(3, omega, zeta); return Status::ok;
    case ShaperKind::ei:
      if (!std::isfinite(vtol)) return Status::non_finite_input;
      if (!(vtol > 0.0 && vtol < 0.5)) return Status::vtol_out_of_range;
      return ei_shaper(omega, zeta, vtol, out);
    default: return Status::unsupported_request;
  }
}

Status custom_shaper(const double* amp, const double* time, std::size_t n, Shaper<double>& out) noexcept {
  if (n == 0) return Status::bad_impulse;
  if (n > kMaxImpulses) return Status::too_many_impulses;
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(amp[i]) || !std::isfinite(time[i])) return Status::non_finite_input;
    if (time[i] < 0.0) return Status::bad_impulse;
    sum += amp[i];
  }
  if (std::fabs(sum - 1.0) > 1e-9) return Status::shaper_gain_not_unity;
  Shaper<double> s{};
  s.count = n;
  for (std::size_t i = 0; i < n; ++i) {
    s.amp[i] = amp[i];
    s.time[i] = time[i];
  }
  // insertion sort by time: n <= 32
  for (std::size_t i = 1; i < n; ++i) {
    for (std::size_t k = i; k > 0 && s.time[k] < s.time[k - 1]; --k) {
      std::swap(s.time[k], s.time[k - 1]);
      std::swap(s.amp[k], s.amp[k - 1]);
    }
  }
  out = s;
  return Status::ok;
}

Status compose(const Shaper<double>& a, const Shaper<double>& b, Shaper<double>& out) noexcept {
  std::array<double, kMaxImpulses> amp{}, time{};
  std::size_t n = 0;
  const double scale = std::max({1e-300, a.duration(), b.duration()});
  for (std::size_t i = 0; i < a.count; ++i) {
    for (std::size_t k = 0; k < b.count; ++k) {
      const double t = a.time[i] + b.time[k];
      const double w = a.amp[i] * b.amp[k];
      std::size_t m = 0;
      while (m < n && std::fabs(time[m] - t) > 1e-12 * scale) ++m;
      if (m < n) {
        amp[m] += w;
        continue;
      }
      if (n == kMaxImpulses) return Status::too_many_impulses;
      time[n] = t;
      amp[n] = w;
      ++n;
    }
  }
  // The product of two unit-gain shapers has unit gain up to rounding; renormalise exactly.
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) sum += amp[i];
  for (std::size_t i = 0; i < n; ++i) amp[i] /= sum;
  return custom_shaper(amp.data(), time.data(), n, out);
}

double shaper_residual(const Shaper<double>& s, double omega, double zeta) noexcept {
  const double beta = std::sqrt(1.0 - zeta * zeta);
  double c = 0.0, si = 0.0;
  const double tn = s.duration();
  for (std::size_t i = 0; i < s.count; ++i) {
    // e^{zeta w (t_i - t_N)} folded in per impulse so heavy damping cannot overflow.
    const double e = s.amp[i] * std::exp(zeta * omega * (s.time[i] - tn));
    c += e * std::cos(omega * beta * s.time[i]);
    si += e * std::sin(omega * beta * s.time[i]);
  }
  return std::sqrt(c * c + si * si);
}

const char* to_string(ShaperKind k) noexcept {
  switch (k) {
    case ShaperKind::none: return "none";
    case ShaperKind::zv: return "zv";
    case ShaperKind::zvd: return "zvd";
    case ShaperKind::zvdd: return "zvdd";
    case ShaperKind::ei: return "ei";
    case ShaperKind::custom: return "custom";
  }
  return "unknown";
}

}  // namespace settle::core
