// SPDX-License-Identifier: Apache-2.0
// The cam table's tick path: integer only. Knots sit every 2^L ticks, so an interval's phase j/2^L
// is exact and dividing by the spacing is a shift; the forward differences of the interval
// polynomial, at scales 32 + iL, start from its Taylor coefficients without any rounding.
#include <array>

#include "hermite.hpp"
#include "settle/core/fixed/cam.hpp"
#include "settle/core/fixed/poly.hpp"
#include "settle/core/fixed/qmath.hpp"

namespace settle::core::fixed {

namespace {

// A knot in Q32.32 counts, with v and a brought to counts per interval and per interval^2 (shifts).
Wide widen(const CamKnot& k, const CamFormats& f) noexcept {
  const int l = f.log2_spacing;
  return {shift(k.p, f.p_frac - 32), shift(k.v, f.v_frac - 32 - l), shift(k.a, f.a_frac - 32 - 2 * l)};
}

// Interval polynomial in its phase from the widened knots at both ends.
Coeffs from_ends(const Wide& e0, const Wide& e1, CamOrder order) noexcept {
  Coeffs c{};
  switch (order) {
    case CamOrder::quintic: c = hermite::quintic(e0.p, e0.v, e0.a, e1.p, e1.v, e1.a); break;
    case CamOrder::cubic: c = hermite::cubic(e0.p, e0.v, e1.p, e1.v); break;
    case CamOrder::linear: c = {e0.p, e1.p - e0.p}; break;
  }
  return c;
}

Shifts spacing_shifts(int l) noexcept {
  const auto s = static_cast<std::uint8_t>(l);
  return {0, s, s, s, s, s};
}

// p, v, a at phase j/2^L of an interval polynomial (Taylor coefficients in place).
Wide eval_interval(Coeffs c, int degree, int l, std::uint32_t j) noexcept {
  taylor_shift(c, degree, j << (31 - l), degree < 3 ? degree : 3);
  Wide w{c[0], 0, 0};
  if (degree >= 1) w.v = shift(c[1], l);
  if (degree >= 2) w.a = shift(c[2], 2 * l - 1);
  return w;
}

}  // namespace

Coeffs CamTable::interval(std::size_t k) const noexcept {
  return from_ends(widen(knots_[k], fmt_), widen(knots_[k + 1], fmt_), order_);
}

Sample CamTable::at_tick(std::int32_t n) const noexcept {
  if (n < 0) return {};
  if (n >= end_tick_) return {target_, 0, 0};
  const int l = fmt_.log2_spacing;
  const auto u = static_cast<std::uint32_t>(n);
  return finish(eval_interval(interval(u >> l), degree(), l, u & ((1U << l) - 1U)));
}

Sample CamStepper::next() noexcept {
  const CamTable& t = *table_;
  const std::int32_t n = n_;
  if (n_ < INT32_MAX) ++n_;
  if (n < 0) return {};
  if (n >= t.end_tick_) return {t.target_, 0, 0};
  // With a knot at every tick there is nothing to step.
  if (!t.steppable_ || t.fmt_.log2_spacing == 0) return t.at_tick(n);
  const int l = t.fmt_.log2_spacing;
  const auto u = static_cast<std::uint32_t>(n);
  const std::uint32_t mask = (1U << l) - 1U;
  const Shifts sh = spacing_shifts(l);
  if (!anchored_ || (u & mask) == 0U) {
    // With F_i = 32 + iL the Taylor coefficients in tick units are the phase ones, bit for bit.
    Coeffs c = t.interval(u >> l);
    // At a knot the phase is 0 and the shift adds products by 0: skipped (every anchor but a
    // restart's is at a knot).
    if ((u & mask) != 0U) taylor_shift(c, t.degree(), (u & mask) << (31 - l), t.degree());
    chains_init(c, t.degree(), sh, fd_);
    anchored_ = true;
  }
  const Sample s = t.finish(chains_value(fd_, t.degree(), sh));
  if (((u + 1U) & mask) != 0U) chains_step(fd_, t.degree(), sh);
  return s;
}

}  // namespace settle::core::fixed
