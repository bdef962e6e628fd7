// SPDX-License-Identifier: Apache-2.0
#include "settle/core/planner.hpp"

#include <algorithm>
#include <cmath>

#include "settle/core/limits.hpp"

namespace settle::core {

Status check_limits(const OptionalLimits& l, const Peaks<double>& pk) noexcept {
  if (l.vmax && !(pk.v <= *l.vmax * (1.0 + kLimitSlack))) return Status::velocity_limit_exceeded;
  if (l.amax && !(pk.a <= *l.amax * (1.0 + kLimitSlack))) return Status::acceleration_limit_exceeded;
  if (l.jmax && !(pk.j <= *l.jmax * (1.0 + kLimitSlack))) return Status::jerk_limit_exceeded;
  return Status::ok;
}

LimitTimes shortest_times(double distance, const OptionalLimits& l) noexcept {
  const double d = std::fabs(distance);
  LimitTimes t{};
  if (l.vmax) t.by_vmax = d / *l.vmax;
  if (l.amax) t.by_amax = 2.0 * std::sqrt(d / *l.amax);
  if (l.jmax) t.by_jmax = std::cbrt(32.0 * d / *l.jmax);
  return t;
}

namespace {

// 0 when x is finite (or absent), NaN otherwise: a non-finite number times zero is NaN. Summed,
// one comparison tests every number of a request (plan() is timed in ns: bench_core BM_Plan).
double nonfinite_mark(double x) noexcept { return x * 0.0; }
double nonfinite_mark(const std::optional<double>& x) noexcept { return x ? *x * 0.0 : 0.0; }

Status validate(const MoveRequest& r) noexcept {
  double mark = nonfinite_mark(r.distance) + nonfinite_mark(r.time) + nonfinite_mark(r.limits.vmax) +
                nonfinite_mark(r.limits.amax) + nonfinite_mark(r.limits.jmax) + nonfinite_mark(r.omega()) + nonfinite_mark(r.zeta()) +
                nonfinite_mark(r.vtol);
  if (r.y_fractions) {
    for (double y : *r.y_fractions) mark += nonfinite_mark(y);
  }
  for (std::size_t i = 0; i < std::min(r.gamma_count, kMaxGammas); ++i) mark += nonfinite_mark(r.gammas[i]);
  if (mark != 0.0) return Status::non_finite_input;
  if (r.time && !(*r.time > 0.0)) return Status::non_positive_time;
  for (const auto* l : {&r.limits.vmax, &r.limits.amax, &r.limits.jmax}) {
    if (*l && !(**l > 0.0)) return Status::non_positive_limit;
  }
  // A positive omega satisfies every profile; only without one is it asked whether one is needed.
  if (!(r.has_mode() && r.omega() > 0.0) && needs_mode(r)) return Status::non_positive_omega;
  if (!(r.zeta() >= 0.0 && r.zeta() < 1.0)) return Status::zeta_out_of_range;
  return Status::ok;
}

// A validated request through `shaper` (nullptr: none). `out` is written only once everything
// succeeded, and in place (see Move::assign).
Status plan_shaped(const MoveRequest& r, const Shaper<double>* shaper, Move<double>& out) noexcept {
  Status st = Status::unsupported_request;  // a ProfileKind value no registry line defines
  (void)with_profile(r.profile, [&](auto kind) {
    using P = profile_t<kind.value>;
    using Shape = typename P::template Shape<double>;
    if (r.distance == 0.0) {
      // A trivial move: nothing to do, nothing to shape; still reject an ill-formed request above.
      // Its shape is the profile's own, empty (a zero-length move on 0).
      out.template assign<Shape>(kind.value, Shape{}, nullptr, Peaks<double>{});
      st = Status::ok;
      return;
    }
    // The registered profile's hook: its shape's parameters, then the profile itself. Default-
    // initialised: every Params member has its initialiser, except a jerk table's entries, which
    // the hook writes up to their count (PiecewiseJerkTable).
    typename Shape::Params p;
    Peaks<double> pk{};
    st = P::plan(r, p, pk);
    if (st != Status::ok) return;
    if (shaper == nullptr || shaper->is_identity()) {
      st = check_limits(r.limits, pk);
      if (st == Status::ok) out.template assign<Shape>(kind.value, p, shaper, pk);
      return;
    }
    Profile<double> prof{};
    prof.template emplace<Shape>(kind.value, p);
    pk = shaped_peaks(prof, *shaper, pk);
    st = check_limits(r.limits, pk);
    if (st == Status::ok) out.template assign<Shape>(kind.value, *std::get_if<Shape>(&prof.variant()), shaper, pk);
  });
  return st;
}

// `extra` convolved after `shaper`, in place. Out of line: a plan without an extra shaper (every
// plan the Cortex-M images make) does not carry this frame's copy on its stack.
[[gnu::noinline]] Status compose_after(Shaper<double>& shaper, const Shaper<double>& extra) noexcept {
  const Shaper<double> own = shaper;
  return compose(own, extra, shaper);
}

// A validated request: its own shaper (if any), then `extra` (nullptr or identity: none) after it.
Status plan_with(const MoveRequest& r, const Shaper<double>* extra, Move<double>& out) noexcept {
  const bool has_extra = extra != nullptr && !extra->is_identity();
  if (r.shaper == ShaperKind::none && !has_extra) return plan_shaped(r, nullptr, out);
  Shaper<double> shaper{};
  Status st = Status::ok;
  if (r.shaper != ShaperKind::none) {
    st = design_shaper(r.shaper, r.omega(), r.zeta(), r.vtol, shaper);
    if (st != Status::ok) return st;
  }
  if (has_extra) {
    st = compose_after(shaper, *extra);
    if (st != Status::ok) return st;
  }
  return plan_shaped(r, &shaper, out);
}

Status checked(const MoveRequest& r) noexcept {
  if (!is_registered(r.profile)) return Status::unsupported_request;
  return validate(r);
}

// Whether the request carries parameter p (a value that differs from "not given").
bool carries(const MoveRequest& r, Param p) noexcept {
  switch (p) {
    case Param::time: return r.time.has_value();
    case Param::vmax: return r.limits.vmax.has_value();
    case Param::amax: return r.limits.amax.has_value();
    case Param::jmax: return r.limits.jmax.has_value();
    case Param::omega: return r.has_mode();
    case Param::zeta: return r.has_mode() && r.zeta() != 0.0;
    case Param::modes: return r.mode_count > 1;
    case Param::gammas: return r.gamma_count > 0;
    case Param::y: return r.y_fractions.has_value();
    case Param::robust: return r.robust.has_value();
    case Param::vtol: return r.vtol != MoveRequest{}.vtol;
  }
  return false;
}

}  // namespace

ParamSet used_params(const MoveRequest& r) noexcept {
  ParamSet own = profile_params(r.profile);
  if (const ParamOverride o = profile_overrides(r.profile); carries(r, o.given)) own = own - o.unused;
  return own | shaper_params(r.shaper);
}

bool needs_mode(const MoveRequest& r) noexcept { return used_params(r).contains(Param::omega); }

Status plan(const MoveRequest& r, Move<double>& out) noexcept {
  const Status st = checked(r);
  return st == Status::ok ? plan_with(r, nullptr, out) : st;
}

Status plan(const MoveRequest& r, const Shaper<double>& extra, Move<double>& out) noexcept {
  const Status st = checked(r);
  return st == Status::ok ? plan_with(r, &extra, out) : st;
}

}  // namespace settle::core
