// SPDX-License-Identifier: Apache-2.0
// Cam tables at planning time: sampling the double evaluator, choosing the formats, and checking
// the integer table against the double evaluator (deterministic double arithmetic, build.hpp).
#include <algorithm>
#include <array>
#include <cmath>

#include "build.hpp"
#include "settle/core/fixed/cam.hpp"

namespace settle::core::fixed {

namespace {

// Planning-time view of one sample in counts, counts/tick, counts/tick^2.
struct Real {
  double p, v, a;
};

Real sample_move(const Move<double>& m, const build::Ctx& ctx, std::int64_t tick) noexcept {
  const double t = static_cast<double>(tick) * ctx.dt;
  core::Sample<double> s = m.at(t);
  // At t = 0 take the right-hand limits (a trapezoid starts with its acceleration step).
  if (tick == 0) {
    const core::Sample<double> r = m.at(1e-9 * ctx.dt);
    s.v = r.v;
    s.a = r.a;
  }
  return {s.p * ctx.cpu, s.v * ctx.cpu * ctx.dt, s.a * ctx.cpu * ctx.dt * ctx.dt};
}

// Fraction bits for a table of values up to `peak`: as many as leave |x| < 2^30, at most 32.
int frac_bits(double peak) noexcept {
  if (!(peak > 0.0)) return 32;
  return std::min(32, 30 - build::exponent(peak));
}

std::int32_t quantise(double x, int frac) noexcept {
  return static_cast<std::int32_t>(std::nearbyint(std::ldexp(x, frac)));
}

}  // namespace

Status build_cam_table(const Move<double>& move, const Scale& scale, CamOrder order, std::span<CamKnot> storage,
                       CamTable& out, double tolerance_counts) noexcept {
  build::Ctx ctx{};
  Status st = build::make_ctx(scale, ctx);
  if (st != Status::ok) return st;
  if (order != CamOrder::linear && order != CamOrder::cubic && order != CamOrder::quintic) {
    return Status::unsupported_request;
  }
  const double dist = move.distance() * ctx.cpu;
  if (!std::isfinite(dist) || !(std::fabs(dist) < build::kTwo30)) return Status::distance_does_not_fit;
  const double ticks = std::ceil(move.duration() / ctx.dt);
  if (!(ticks < build::kTwo30)) return Status::duration_does_not_fit;
  const auto end_tick = static_cast<std::int64_t>(ticks);
  // The finest power-of-two spacing whose knots fit (the last knot at or after the end).
  int l = 0;
  while (l < 30 && ((end_tick + (std::int64_t{1} << l) - 1) >> l) + 1 > static_cast<std::int64_t>(storage.size())) ++l;
  const std::int64_t count = ((end_tick + (std::int64_t{1} << l) - 1) >> l) + 1;
  if (storage.size() < 2 || count > static_cast<std::int64_t>(storage.size())) return Status::table_too_small;

  // Formats from the peaks over the knots.
  Real peak{0.0, 0.0, 0.0};
  for (std::int64_t k = 0; k < count; ++k) {
    const Real r = sample_move(move, ctx, k << l);
    peak = {std::max(peak.p, std::fabs(r.p)), std::max(peak.v, std::fabs(r.v)), std::max(peak.a, std::fabs(r.a))};
  }
  CamFormats fmt{static_cast<std::uint8_t>(l), 0, 0, 0};
  const int pf = frac_bits(peak.p), vf = frac_bits(peak.v), af = frac_bits(peak.a);
  if (pf < 0) return Status::distance_does_not_fit;
  if (vf < 0) return Status::velocity_does_not_fit;
  if (af < 0) return Status::acceleration_does_not_fit;
  fmt.p_frac = static_cast<std::uint8_t>(pf);
  fmt.v_frac = static_cast<std::uint8_t>(vf);
  fmt.a_frac = static_cast<std::uint8_t>(af);
  for (std::int64_t k = 0; k < count; ++k) {
    const Real r = sample_move(move, ctx, k << l);
    storage[static_cast<std::size_t>(k)] = {quantise(r.p, pf), quantise(r.v, vf), quantise(r.a, af)};
  }

  CamTable t{};
  t.knots_ = storage.data();
  t.count_ = static_cast<std::size_t>(count);
  t.order_ = order;
  t.fmt_ = fmt;
  t.out_vf_ = static_cast<std::uint8_t>(ctx.vf);
  t.out_af_ = static_cast<std::uint8_t>(ctx.af);
  t.target_ = static_cast<std::int32_t>(std::nearbyint(dist));
  t.end_tick_ = static_cast<std::int32_t>(end_tick);

  // Every interval polynomial must fit Q32.32 through Horner and the Taylor shift, and its
  // difference chains their scales 32 + iL (else the stepper evaluates by random access).
  const int deg = static_cast<int>(order);
  bool steppable = true;
  for (std::int64_t k = 0; k + 1 < count; ++k) {
    const Coeffs c = t.interval(static_cast<std::size_t>(k));
    std::array<double, 6> cd{};
    for (std::size_t i = 0; i < 6; ++i) cd[i] = std::ldexp(static_cast<double>(c[i]), -32);
    const build::Sweep sw = build::sweep(cd, deg, 1.0);
    if (!(sw.inter < build::kTwo30)) return Status::table_too_small;
    const std::array<double, 6>& bmax = sw.t;
    for (int r = 0; r <= 2; ++r) {
      for (int i = 0; i + r <= deg; ++i) {
        const double s = build::chain_sum_bound(bmax, deg, r, i, [&](int m) { return std::ldexp(1.0, -(m - i) * l); });
        if (!(s < 0x1p29)) steppable = false;
      }
    }
  }
  t.steppable_ = steppable;

  // Check against the double evaluator: every tick up to 2^18, four per interval beyond.
  const std::int64_t h = std::int64_t{1} << l;
  const bool every = end_tick <= (std::int64_t{1} << 18) || h <= 4;
  CamCheck chk{};
  auto check = [&](std::int64_t n) {
    const Sample s = t.at_tick(static_cast<std::int32_t>(n));
    const Real r = sample_move(move, ctx, n);
    chk.p = std::max(chk.p, std::fabs(s.p - r.p));
    chk.v = std::max(chk.v, std::fabs(s.v - std::ldexp(r.v, ctx.vf)));
    chk.a = std::max(chk.a, std::fabs(s.a - std::ldexp(r.a, ctx.af)));
  };
  for (std::int64_t k = 0; k + 1 < count; ++k) {
    if (every) {
      for (std::int64_t j = 0; j < h && (k << l) + j < end_tick; ++j) check((k << l) + j);
    } else {
      for (std::int64_t j = h / 8; j < h; j += h / 4) check((k << l) + j);
    }
  }
  t.check_ = chk;
  if (!(chk.p <= tolerance_counts)) return Status::table_too_small;
  out = t;
  return Status::ok;
}

}  // namespace settle::core::fixed
