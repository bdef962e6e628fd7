// SPDX-License-Identifier: Apache-2.0
#include "settle/core/multi_axis.hpp"

#include <algorithm>
#include <cmath>
#include <variant>

#include "extrema.hpp"
#include "fastest_scale.hpp"
#include "settle/core/limits.hpp"
#include "settle/core/planner.hpp"
#include "settle/core/profiles/registry.hpp"

namespace settle::core {

namespace {

// The path limit min_i(limit_i / |D_i|) over the moving axes that give that limit (absent when
// none does). A non-finite or non-positive axis limit passes through, for plan() to refuse.
std::optional<double> path_limit(const MultiAxisRequest& r, std::optional<double> OptionalLimits::*limit,
                                 std::size_t& culprit) noexcept {
  std::optional<double> out;
  for (std::size_t i = 0; i < r.count; ++i) {
    const AxisSpec& a = r.axes[i];
    const std::optional<double>& l = a.limits.*limit;
    if (!l || a.distance == 0.0) continue;
    const double v = *l / std::fabs(a.distance);
    if (!out || !(v >= *out)) {  // a NaN wins, so that it is reported
      out = v;
      culprit = i;
    }
  }
  return out;
}

// Every path limit, and the axis that set each (kMaxAxes: none did).
struct PathLimits {
  OptionalLimits limits;
  std::size_t who_v{kMaxAxes}, who_a{kMaxAxes}, who_j{kMaxAxes};
};
PathLimits path_limits(const MultiAxisRequest& r) noexcept {
  PathLimits out{};
  out.limits.vmax = path_limit(r, &OptionalLimits::vmax, out.who_v);
  out.limits.amax = path_limit(r, &OptionalLimits::amax, out.who_a);
  out.limits.jmax = path_limit(r, &OptionalLimits::jmax, out.who_j);
  return out;
}

// Whether the profile designs for the request's further modes as well as its first one.
bool reads_further_modes(ProfileKind k) noexcept {
#if SETTLE_CORE_FASTEST
  return k == ProfileKind::fastest;
#else
  (void)k;
  return false;
#endif
}

// The modes the request's own plan does not cancel: one shaper each, of the request's kind (ZV when
// it has none), composed.
Status extra_shaper(const MoveRequest& r, const Mode* modes, std::size_t n, Shaper<double>& out) noexcept {
  const ShaperKind kind = r.shaper != ShaperKind::none ? r.shaper : ShaperKind::zv;
  Shaper<double> acc{};
  for (std::size_t k = 0; k < n; ++k) {
    Shaper<double> one{}, prev = acc;
    Status st = design_shaper(kind, modes[k].omega, modes[k].zeta, r.vtol, one);
    if (st == Status::ok) st = compose(prev, one, acc);
    if (st != Status::ok) return st;
  }
  out = acc;
  return Status::ok;
}

// Time sync: axis `q`'s own mode, when the profile and the shaper do not design for it, gets a
// shaper of its own the same way.
Status own_extra_shaper(const MoveRequest& q, Shaper<double>& out) noexcept {
  out = Shaper<double>{};
  if (!q.has_mode() || needs_mode(q)) return Status::ok;
  return extra_shaper(q, q.modes.data(), 1, out);
}

// The path s(t) from 0 to `scale` (1: the path itself; D_i: axis i's command D_i s(t), the same
// move scaled, planned under the path limits times |scale|).
Status plan_path(const MultiAxisRequest& r, Move<double>& out, std::array<Mode, kMaxAxes>& modes, std::size_t& nm,
                 std::size_t& culprit, double scale = 1.0) noexcept {
  MoveRequest p = r.base;
  p.mode_count = 0;
  bool moving = false;
  // The distinct modes of the moving axes, in axis order.
  nm = 0;
  for (std::size_t i = 0; i < r.count; ++i) {
    const AxisSpec& a = r.axes[i];
    if (!std::isfinite(a.distance)) {
      culprit = i;
      return Status::non_finite_input;
    }
    if (a.distance == 0.0) continue;
    moving = true;
    if (!a.omega) continue;
    if (const Status st = mode_status(*a.omega, a.zeta); st != Status::ok) {
      culprit = i;
      return st;
    }
    bool known = false;
    for (std::size_t k = 0; k < nm; ++k) known = known || (modes[k].omega == *a.omega && modes[k].zeta == a.zeta);
    if (!known) modes[nm++] = {*a.omega, a.zeta};
  }
  p.distance = moving ? scale : 0.0;
  const PathLimits lim = path_limits(r);
  p.limits = lim.limits.scaled(std::fabs(scale));
  // The first mode is the request's own: its shaper's and, when the profile designs for a mode,
  // the profile's; `fastest` takes the further ones too.
  std::size_t covered = 0;
  if (nm > 0) {
    p.set_mode(modes[0].omega, modes[0].zeta);
    if (needs_mode(p)) covered = 1;
    if (reads_further_modes(p.profile)) {
      for (; covered < nm && p.add_mode(modes[covered]); ++covered) {
      }
    }
  }
  Shaper<double> extra{};
  if (const Status st = extra_shaper(r.base, modes.data() + covered, nm - covered, extra); st != Status::ok) {
    culprit = kMaxAxes;
    return st;
  }
  Move<double> path{};
  const Status st = plan(p, extra, path);
  if (st != Status::ok) {
    // The axis whose limit set the path limit the status is about.
    auto bad = [](const std::optional<double>& l) { return l && !(*l > 0.0 && std::isfinite(*l)); };
    switch (st) {
      case Status::velocity_limit_exceeded:
      case Status::time_too_short_for_vmax: culprit = lim.who_v; break;
      case Status::acceleration_limit_exceeded: culprit = lim.who_a; break;
      case Status::jerk_limit_exceeded: culprit = lim.who_j; break;
      case Status::non_positive_limit:
      case Status::non_finite_input:
        culprit = bad(p.limits.vmax)   ? lim.who_v
                  : bad(p.limits.amax) ? lim.who_a
                  : bad(p.limits.jmax) ? lim.who_j
                                       : kMaxAxes;
        break;
      default: culprit = kMaxAxes;
    }
    return st;
  }
  out = path;
  return Status::ok;
}

}  // namespace

MoveRequest axis_request(const MultiAxisRequest& r, std::size_t i) noexcept {
  MoveRequest q = r.base;
  const AxisSpec& a = r.axes[i];
  q.distance = a.distance;
  q.limits = a.limits;
  q.mode_count = 0;
  if (a.omega) q.set_mode(*a.omega, a.zeta);
  return q;
}

Status plan_axes(const MultiAxisRequest& r, MultiAxisPlan& out, std::size_t& culprit) noexcept {
  culprit = kMaxAxes;
  if (r.count == 0 || r.count > kMaxAxes) return Status::bad_shape_parameter;
  MultiAxisPlan res{};
  res.sync_ = r.sync;
  res.count_ = r.count;
  for (std::size_t i = 0; i < r.count; ++i) res.distance_[i] = r.axes[i].distance;
  if (r.sync == SyncMode::path) {
    std::size_t nm = 0;
    const Status st = plan_path(r, res.path_, res.path_modes_, nm, culprit);
    if (st != Status::ok) return st;
    res.path_mode_count_ = nm;
    res.duration_ = res.path_.duration();
    const Peaks<double>& pk = res.path_.peaks();
    for (std::size_t i = 0; i < r.count; ++i) {
      const double d = std::fabs(r.axes[i].distance);
      res.peaks_[i] = d == 0.0 ? Peaks<double>{} : Peaks<double>{d * pk.v, d * pk.a, d * pk.j, pk.velocity_step,
                                                                   pk.acceleration_step};
    }
    out = res;
    return Status::ok;
  }
  // Time sync: every axis's shortest move first, then each stretched to the slowest one's duration.
  // A move time given in the request is every axis's shortest; the shaper delays still differ.
  double t_common = 0.0;
  for (std::size_t i = 0; i < r.count; ++i) {
    const MoveRequest q = axis_request(r, i);
    Shaper<double> extra{};
    Status st = own_extra_shaper(q, extra);
    if (st == Status::ok) st = plan(q, extra, res.moves_[i]);
    if (st != Status::ok) {
      culprit = i;
      return st;
    }
    t_common = std::max(t_common, res.moves_[i].duration());
  }
  for (std::size_t i = 0; i < r.count; ++i) {
    Move<double>& m = res.moves_[i];
    if (m.distance() == 0.0 || m.duration() == t_common) continue;
    MoveRequest q = axis_request(r, i);
    q.time = t_common - m.shaper().duration();  // the unshaped profile's time; the shaper is the axis's own
    Shaper<double> extra{};
    Status st = own_extra_shaper(q, extra);
    if (st == Status::ok) st = plan(q, extra, m);
    if (st != Status::ok) {
      culprit = i;
      return st;
    }
  }
  res.duration_ = 0.0;
  for (std::size_t i = 0; i < r.count; ++i) {
    res.duration_ = std::max(res.duration_, res.moves_[i].duration());
    res.peaks_[i] = res.moves_[i].peaks();
  }
  out = res;
  return Status::ok;
}

Status axis_command(const MultiAxisRequest& r, const MultiAxisPlan& plan, std::size_t axis,
                    Move<double>& out) noexcept {
  if (axis >= plan.count() || axis >= r.count) return Status::bad_shape_parameter;
  if (plan.sync() == SyncMode::time) {
    out = plan.axis_move(axis);
    return Status::ok;
  }
  const double d = r.axes[axis].distance;
  if (d == 0.0) {
    out = Move<double>{};
    return Status::ok;
  }
#if SETTLE_CORE_FASTEST
  // `fastest`: the plan's unit path scaled by D_i, the same move on every axis to rounding. Planned
  // at each axis's own scale, the bang-bang chain's refinement decides on ulp-level differences and
  // the axes' commands agree only to about 1e-8 (a path halt could then not be planned once:
  // path_change). The peaks are the plan's for the axis (the path's times |D_i|).
  const Move<double>& path = plan.path();
  if (const auto* f = std::get_if<Fastest<double>>(&path.profile().variant());
      f != nullptr && path.profile().kind() == ProfileKind::fastest) {
    out.assign<Fastest<double>>(ProfileKind::fastest, detail::scaled_fastest(f->params(), d), &path.shaper(),
                                plan.peaks(axis));
    return Status::ok;
  }
#endif
  std::array<Mode, kMaxAxes> modes{};
  std::size_t nm = 0, culprit = kMaxAxes;
  return plan_path(r, out, modes, nm, culprit, d);
}

Status axis_online(const MultiAxisRequest& r, const MultiAxisPlan& plan, std::size_t axis, AxisOnline& out,
                   const Mode* fallback) noexcept {
  if (axis >= plan.count() || axis >= r.count) return Status::bad_shape_parameter;
  AxisOnline o{};
  OptionalLimits limits;
  if (plan.sync() == SyncMode::path) {
    if (plan.path_mode_count() > kMaxOnlineModes) return Status::unsupported_request;
    for (; o.mode_count < plan.path_mode_count(); ++o.mode_count) o.modes[o.mode_count] = plan.path_mode(o.mode_count);
    limits = path_limits(r).limits.scaled(std::fabs(r.axes[axis].distance));
  } else {
    const AxisSpec& a = r.axes[axis];
    if (a.omega) o.modes[o.mode_count++] = {*a.omega, a.zeta};
    limits = a.limits;
  }
  if (o.mode_count == 0 && fallback != nullptr) o.modes[o.mode_count++] = *fallback;
  if (r.axes[axis].distance == 0.0) return Status::non_positive_limit;
  const Status st = online_limits(limits, plan.peaks(axis), o.modes.data(), o.mode_count, o.limits);
  if (st != Status::ok) return st;
  out = o;
  return Status::ok;
}

std::size_t path_reference(const double* distance, std::size_t n) noexcept {
  for (std::size_t i = 0; i < n; ++i) {
    if (distance[i] != 0.0) return i;
  }
  return n;
}

namespace {

// |x - ratio x_ref| within 1e-9 of `scale` (axis i's own: its distance, its limit).
bool scaled_copy(double x, double x_ref, double ratio, double scale) noexcept {
  return std::fabs(x - ratio * x_ref) <= 1e-9 * scale;
}

}  // namespace

bool path_change(const OnlineRequest* const* requests, const double* distance, std::size_t n) noexcept {
  const std::size_t ref = path_reference(distance, n);
  if (ref == n || requests[ref] == nullptr) return false;
  const OnlineRequest& r = *requests[ref];
  for (std::size_t i = 0; i < n; ++i) {
    if (distance[i] == 0.0 || i == ref) continue;
    if (requests[i] == nullptr) return false;
    const OnlineRequest& q = *requests[i];
    const double k = distance[i] / distance[ref], d = std::fabs(distance[i]), ak = std::fabs(k);
    bool same = q.mode_count == r.mode_count && q.target.has_value() == r.target.has_value() &&
                q.running.has_value() == r.running.has_value();
    for (std::size_t m = 0; same && m < q.mode_count; ++m) {
      same = q.modes[m].omega == r.modes[m].omega && q.modes[m].zeta == r.modes[m].zeta;
    }
    same = same && ak * r.limits.vmax <= q.limits.vmax * (1.0 + kLimitSlack) &&
           ak * r.limits.amax <= q.limits.amax * (1.0 + kLimitSlack) &&
           ak * r.limits.jmax <= q.limits.jmax * (1.0 + kLimitSlack);
    same = same && scaled_copy(q.start.p, r.start.p, k, d) && scaled_copy(q.start.v, r.start.v, k, q.limits.vmax) &&
           scaled_copy(q.start.a, r.start.a, k, q.limits.amax);
    // On the line: target_i = lambda D_i, to rounding.
    if (same && q.target) same = std::fabs(*q.target - k * *r.target) <= 1e-12 * d;
    if (same && q.running) {
      const OnlineRunning &a = *q.running, &b = *r.running;
      same = a.at_rest == b.at_rest && scaled_copy(a.origin, b.origin, k, d) && scaled_copy(a.end, b.end, k, d) &&
             scaled_copy(a.remaining, b.remaining, 1.0, std::fmax(b.remaining, 1.0));
    }
    if (!same) return false;
  }
  return true;
}

OnlinePlan scaled_online(const OnlinePlan& ref, double ratio, const Sample<double>& start) noexcept {
  OnlinePlan out = ref;
  if (ref.choice == OnlineChoice::finish) return out;
  std::array<double, kBlendSegments> jerk{};
  for (std::size_t k = 0; k < kBlendSegments; ++k) jerk[k] = ratio * ref.blend.jerk(k);
  out.blend = Blend{start, ref.blend.segment_length(), jerk};
  return out;
}

Status plan_path_online(const OnlineRequest* const* requests, const double* distance, std::size_t n,
                        OnlinePlan* out, std::size_t& culprit) noexcept {
  const std::size_t ref = path_reference(distance, n);
  culprit = ref;
  if (!path_change(requests, distance, n)) return Status::bad_shape_parameter;
  OnlinePlan plan{};
  if (const Status st = plan_online(*requests[ref], plan); st != Status::ok) return st;
  for (std::size_t i = 0; i < n; ++i) {
    if (distance[i] == 0.0) continue;
    out[i] = i == ref ? plan : scaled_online(plan, distance[i] / distance[ref], requests[i]->start);
  }
  return Status::ok;
}

double offset_from_line(const double* p, const double* dir, std::size_t n, double* off) noexcept {
  double dd = 0.0, pd = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    dd += dir[i] * dir[i];
    pd += p[i] * dir[i];
  }
  const double sigma = dd > 0.0 ? pd / dd : 0.0;
  double e2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = dd > 0.0 ? p[i] - dir[i] * sigma : 0.0;
    if (off != nullptr) off[i] = e;
    e2 += e * e;
  }
  return std::sqrt(e2);
}

double line_deviation(const MultiAxisPlan& plan, std::array<double, kMaxAxes>& per_axis) noexcept {
  per_axis = {};
  const std::size_t n = plan.count();
  std::array<double, kMaxAxes> dir{};
  double dd = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    dir[i] = plan.distance(i);
    dd += dir[i] * dir[i];
  }
  const double t1 = plan.duration();
  if (!(dd > 0.0) || !(t1 > 0.0)) return 0.0;
  // The component of axis i off the line at t (axis == n: the Euclidean distance).
  auto off = [&](std::size_t axis, double t) {
    std::array<double, kMaxAxes> p{}, e{};
    for (std::size_t i = 0; i < n; ++i) p[i] = plan.at(i, t).p;
    const double len = offset_from_line(p.data(), dir.data(), n, e.data());
    return axis < n ? e[axis] : len;
  };
  for (std::size_t i = 0; i < n; ++i) {
    per_axis[i] = detail::max_abs([&](double t) { return off(i, t); }, 0.0, t1, 2048);
  }
  return detail::max_abs([&](double t) { return off(n, t); }, 0.0, t1, 2048);
}

}  // namespace settle::core
