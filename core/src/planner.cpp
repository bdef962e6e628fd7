#include "settle/core/planner.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "extrema.hpp"

namespace settle::core {

namespace {

constexpr double inf = infinity_v<double>;
// Peaks are compared with limits with this relative slack, so that a plan built to touch a
// limit exactly is not refused for the last bit of rounding.
constexpr double kLimitSlack = 1e-9;

bool finite_opt(const std::optional<double>& x) noexcept { return !x || std::isfinite(*x); }

bool needs_mode(const MoveRequest& r) noexcept {
  return r.shaper != ShaperKind::none || r.profile == ProfileKind::scurve ||
         r.profile == ProfileKind::scurve_damped || (r.profile == ProfileKind::ramp_versine && !r.y_fractions);
}

Status validate(const MoveRequest& r) noexcept {
  if (!std::isfinite(r.distance) || !finite_opt(r.time) || !finite_opt(r.vmax) || !finite_opt(r.amax) ||
      !finite_opt(r.jmax) || !finite_opt(r.omega) || !std::isfinite(r.zeta) || !std::isfinite(r.vtol)) {
    return Status::non_finite_input;
  }
  if (r.y_fractions) {
    for (double y : *r.y_fractions) {
      if (!std::isfinite(y)) return Status::non_finite_input;
    }
  }
  for (std::size_t i = 0; i < std::min(r.gamma_count, kMaxGammas); ++i) {
    if (!std::isfinite(r.gammas[i])) return Status::non_finite_input;
  }
  if (r.time && !(*r.time > 0.0)) return Status::non_positive_time;
  for (const auto* l : {&r.vmax, &r.amax, &r.jmax}) {
    if (*l && !(**l > 0.0)) return Status::non_positive_limit;
  }
  if (needs_mode(r)) {
    if (!r.omega || !(*r.omega > 0.0)) return Status::non_positive_omega;
  }
  if (!(r.zeta >= 0.0 && r.zeta < 1.0)) return Status::zeta_out_of_range;
  return Status::ok;
}

Status check_limits(const MoveRequest& r, const Peaks<double>& pk) noexcept {
  if (r.vmax && pk.v > *r.vmax * (1.0 + kLimitSlack)) return Status::velocity_limit_exceeded;
  if (r.amax && pk.a > *r.amax * (1.0 + kLimitSlack)) return Status::acceleration_limit_exceeded;
  if (r.jmax && pk.j > *r.jmax * (1.0 + kLimitSlack)) return Status::jerk_limit_exceeded;
  return Status::ok;
}

RampCycloidParams scurve_params(double distance, double tau, double cruise, double v, double omega, double zeta) noexcept {
  const CycloidWeights w = cycloid_weights(tau, omega, zeta);
  const double sg = distance < 0.0 ? -1.0 : 1.0;
  return {distance, tau, cruise, sg * v / tau, w.c2, w.c3};
}

// S-curve from (D, T) and optionally vmax (seed 000's planning rule): with vmax the profile
// cruises at vmax when it must; otherwise (or when vmax is generous) the 4-segment profile.
Status scurve_timed(const MoveRequest& r, double zeta, RampCycloidParams& out) noexcept {
  const double d = std::fabs(r.distance);
  const double t = *r.time;
  if (r.vmax && d / *r.vmax >= t) return Status::time_too_short_for_vmax;
  double tau = t / 4.0;
  double cruise = 0.0;
  if (r.vmax && *r.vmax < 2.0 * d / t) {  // a cruise at vmax is needed
    // With a short transition the velocity overshoots vmax; lowering the cruise velocity only
    // shortens tau and makes that worse, so such a request is refused by the peak check.
    tau = (t * *r.vmax - d) / (2.0 * *r.vmax);
    cruise = t - 4.0 * tau;
  }
  out = scurve_params(r.distance, tau, cruise, d / (t - 2.0 * tau), *r.omega, zeta);
  return Status::ok;
}

// Generic shortest move time: the smallest T in [t_lo, t_hi] for which feasible(T) holds, by a
// geometric scan and bisection. Used for profiles whose peaks have no closed-form inverse.
template <typename F>
bool shortest_time(F&& feasible, double t_lo, double t_hi, double& t_out) noexcept {
  constexpr int kScan = 64;
  const double ratio = std::pow(t_hi / t_lo, 1.0 / kScan);
  double prev = t_lo;
  if (feasible(t_lo)) {
    t_out = t_lo;
    return true;
  }
  for (int i = 1; i <= kScan; ++i) {
    const double t = t_lo * std::pow(ratio, i);
    if (feasible(t)) {
      double lo = prev, hi = t;
      for (int it = 0; it < 60 && hi - lo > 1e-13 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (feasible(mid)) {
          hi = mid;
        } else {
          lo = mid;
        }
      }
      t_out = hi;
      return true;
    }
    prev = t;
  }
  return false;
}

Status plan_scurve(const MoveRequest& r, Profile<double>& prof, Peaks<double>& pk) noexcept {
  const bool damped = r.profile == ProfileKind::scurve_damped;
  const double zeta = damped ? r.zeta : 0.0;
  RampCycloidParams p{};
  if (r.time) {
    const Status st = scurve_timed(r, zeta, p);
    if (st != Status::ok) return st;
  } else {
    if (!r.vmax || !r.amax) return Status::missing_time_or_limits;
    const Status st =
        plan_fastest_scurve(r.distance, *r.vmax, *r.amax, r.jmax.value_or(inf), *r.omega, zeta, damped, p);
    if (st != Status::ok) return st;
  }
  pk = ramp_cycloid_peaks(p);
  prof = Profile<double>{r.profile, RampCycloid<double>{p}};
  return Status::ok;
}

Status plan_ramp_versine(const MoveRequest& r, Profile<double>& prof, Peaks<double>& pk) noexcept {
  if (r.y_fractions) {
    const auto& f = *r.y_fractions;
    if (std::fabs(f[0] + f[1] + f[2] - 1.0) > 1e-9) return Status::bad_shape_parameter;
  }
  auto make = [&](double tau) {
    if (r.y_fractions) {
      const auto& f = *r.y_fractions;
      return RampVersineParams{r.distance, tau, f[0] * r.distance, f[1] * r.distance, f[2] * r.distance};
    }
    return ramp_versine_zero_vibration(r.distance, tau, *r.omega, r.zeta);
  };
  double tau = 0.0;
  if (r.time) {
    tau = *r.time;
  } else {
    // Only a velocity limit can be met: the velocity steps make acceleration and jerk impulses.
    if (!r.vmax) return Status::missing_time_or_limits;
    if (r.amax) return Status::acceleration_limit_exceeded;
    if (r.jmax) return Status::jerk_limit_exceeded;
    const double d = std::fabs(r.distance);
    auto ok = [&](double t) { return ramp_versine_peaks(make(t)).v <= *r.vmax; };
    if (!shortest_time(ok, d / *r.vmax, 1e4 * d / *r.vmax, tau)) return Status::velocity_limit_exceeded;
  }
  const RampVersineParams p = make(tau);
  pk = ramp_versine_peaks(p);
  prof = Profile<double>{ProfileKind::ramp_versine, RampVersine<double>{p}};
  return Status::ok;
}

Status plan_pseudopoly(const MoveRequest& r, Profile<double>& prof, Peaks<double>& pk) noexcept {
  static constexpr double k345[3] = {3.0, 4.0, 5.0};
  const bool is345 = r.profile == ProfileKind::poly345;
  const double* g = is345 ? k345 : r.gammas.data();
  const std::size_t n = is345 ? 3 : r.gamma_count;
  PseudoPolyParams p{};
  // Design on a unit duration first: the coefficients do not depend on T or D.
  Status st = pseudo_poly_design(r.distance, 1.0, g, n, p);
  if (st != Status::ok) return st;
  double t = 0.0;
  if (r.time) {
    t = *r.time;
  } else {
    if (!r.vmax && !r.amax && !r.jmax) return Status::missing_time_or_limits;
    const Peaks<double> u = pseudo_poly_unit_peaks(p);
    const double d = std::fabs(r.distance);
    if (r.vmax) t = std::max(t, d * u.v / *r.vmax);
    if (r.amax) t = std::max(t, std::sqrt(d * u.a / *r.amax));
    if (r.jmax) {
      if (!std::isfinite(u.j)) return Status::jerk_limit_exceeded;
      t = std::max(t, std::cbrt(d * u.j / *r.jmax));
    }
  }
  p.duration = t;
  pk = pseudo_poly_peaks(p);
  prof = Profile<double>{r.profile, PseudoPoly<double>{p}};
  return Status::ok;
}

Status plan_trapezoid(const MoveRequest& r, Profile<double>& prof, Peaks<double>& pk) noexcept {
  const double d = std::fabs(r.distance);
  PiecewiseJerkParams p{};
  if (r.time) {
    const double t = *r.time;
    if (r.vmax && d / *r.vmax >= t) return Status::time_too_short_for_vmax;
    // Without a binding vmax, accelerate for a third of the move (cruise at 1.5 D/T).
    const double v = r.vmax ? std::min(*r.vmax, 1.5 * d / t) : 1.5 * d / t;
    p = trapezoid_timed(r.distance, t, v);
  } else {
    if (!r.vmax || !r.amax) return Status::missing_time_or_limits;
    p = trapezoid_time_optimal(r.distance, *r.vmax, *r.amax);
  }
  pk = piecewise_peaks(p);
  prof = Profile<double>{ProfileKind::trapezoid, PiecewiseJerk<double>{p}};
  return Status::ok;
}

Status plan_jerk_limited(const MoveRequest& r, Profile<double>& prof, Peaks<double>& pk) noexcept {
  if (!r.vmax || !r.amax || !r.jmax) return Status::missing_time_or_limits;
  const double d = std::fabs(r.distance);
  PiecewiseJerkParams p = jerk_limited_time_optimal(r.distance, *r.vmax, *r.amax, *r.jmax);
  if (r.time) {
    const double t = *r.time;
    if (d / *r.vmax >= t) return Status::time_too_short_for_vmax;
    if (t < piecewise_duration(p)) {
      const double t_acc = piecewise_duration(trapezoid_time_optimal(r.distance, *r.vmax, *r.amax));
      return t < t_acc ? Status::acceleration_limit_exceeded : Status::jerk_limit_exceeded;
    }
    // Stretch to the requested time by lowering the cruise velocity: duration falls
    // monotonically as v rises, so bisection on v finds the profile of exactly duration t.
    double lo = d / t, hi = *r.vmax;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (piecewise_duration(jerk_limited_time_optimal(r.distance, mid, *r.amax, *r.jmax)) > t) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    p = jerk_limited_time_optimal(r.distance, hi, *r.amax, *r.jmax);
  }
  pk = piecewise_peaks(p);
  prof = Profile<double>{ProfileKind::jerk_limited, PiecewiseJerk<double>{p}};
  return Status::ok;
}

}  // namespace

Status plan_fastest_scurve(double distance, double vmax, double amax, double jmax, double omega, double zeta,
                           bool damped, RampCycloidParams& out) noexcept {
  if (!std::isfinite(distance) || !std::isfinite(vmax) || !std::isfinite(amax) || std::isnan(jmax) ||
      !std::isfinite(omega) || !std::isfinite(zeta)) {
    return Status::non_finite_input;
  }
  if (!(vmax > 0.0 && amax > 0.0 && jmax > 0.0)) return Status::non_positive_limit;
  if (!(omega > 0.0)) return Status::non_positive_omega;
  if (!(zeta >= 0.0 && zeta < 1.0)) return Status::zeta_out_of_range;
  const double z = damped ? zeta : 0.0;
  const double d = std::fabs(distance);
  if (d == 0.0) {
    out = RampCycloidParams{};
    return Status::ok;
  }
  // For a transition length tau, the largest cruise velocity V that keeps every true peak
  // within its limit; the move then lasts D/V + 2 tau (with no cruise when V = D/(2 tau)).
  // Peaks scale as |v| = V vn, |a| = (V/tau) an, |j| = (V/tau^2) jn with vn, an, jn shape factors.
  // vn needs root finding, so the search first runs on a relaxation that applies vmax to V
  // alone (vn >= 1): its minimum is a lower bound, and it is the answer whenever the true
  // velocity peak there is within vmax. Only otherwise is the search repeated with vn.
  bool with_vn = false;
  auto best_v = [&](double tau) {
    const CycloidWeights w = cycloid_weights(tau, omega, z);
    const TransitionPeaks u = transition_peaks(w.c2, w.c3);
    double v = std::min({vmax, amax * tau / u.accel, d / (2.0 * tau)});
    if (std::isfinite(jmax)) v = std::min(v, jmax * tau * tau / u.jerk);
    if (with_vn && u.accel > 1.0) v = std::min(v, vmax / transition_velocity_peak(w.c2, w.c3));
    return v;
  };
  auto total = [&](double tau) { return d / best_v(tau) + 2.0 * tau; };
  const double scales[4] = {d / vmax, std::sqrt(d / amax), 6.283185307179586 / omega,
                            std::isfinite(jmax) ? std::cbrt(d / jmax) : d / vmax};
  const double s_lo = *std::min_element(scales, scales + 4) * 1e-2;
  const double s_hi = std::max(d / vmax, std::sqrt(d / amax)) * 2.0;
  auto search = [&]() {
    // Geometric scan of tau, then golden section on the best bracket. T(tau) is flat at its
    // minimum, so tau to 1e-7 gives T to far better than 1e-9.
    constexpr int kScan = 32;
    const double ratio = std::pow(s_hi / s_lo, 1.0 / kScan);
    int best = 0;
    double best_t = inf;
    for (int i = 0; i <= kScan; ++i) {
      const double t = total(s_lo * std::pow(ratio, i));
      if (t < best_t) {
        best_t = t;
        best = i;
      }
    }
    double lo = s_lo * std::pow(ratio, std::max(best - 1, 0));
    double hi = s_lo * std::pow(ratio, std::min(best + 1, kScan));
    constexpr double g = 0.6180339887498948482;
    double c = hi - g * (hi - lo), e = lo + g * (hi - lo);
    double fc = total(c), fe = total(e);
    for (int it = 0; it < 40 && hi - lo > 1e-7 * hi; ++it) {
      if (fc < fe) {
        hi = e;
        e = c;
        fe = fc;
        c = hi - g * (hi - lo);
        fc = total(c);
      } else {
        lo = c;
        c = e;
        fc = fe;
        e = lo + g * (hi - lo);
        fe = total(e);
      }
    }
    const double grid = s_lo * std::pow(ratio, best);
    if (best_t < std::min(fc, fe)) return grid;
    return fc < fe ? c : e;
  };
  double tau = search();
  {
    const CycloidWeights w = cycloid_weights(tau, omega, z);
    if (best_v(tau) * transition_velocity_peak(w.c2, w.c3) > vmax * (1.0 + 1e-12)) {
      with_vn = true;
      tau = search();
    }
  }
  const double v = best_v(tau);
  const double cruise = std::max(0.0, d / v - 2.0 * tau);
  if (!std::isfinite(v) || !(v > 0.0)) return Status::no_solution;
  out = scurve_params(distance, tau, cruise, v, omega, z);
  return Status::ok;
}

Peaks<double> shaped_peaks(const Profile<double>& p, const Shaper<double>& s, const Peaks<double>& unshaped) noexcept {
  if (s.is_identity()) return unshaped;
  const Move<double> m{p, s, unshaped};
  const double t1 = m.duration();
  Peaks<double> out = unshaped;
  // A Dirac in the profile stays a Dirac after shaping: keep the infinite peaks and flags.
  if (std::isfinite(unshaped.v)) out.v = detail::max_abs([&](double t) { return m.at(t).v; }, 0.0, t1, 1024);
  if (std::isfinite(unshaped.a)) out.a = detail::max_abs([&](double t) { return m.at(t).a; }, 0.0, t1, 1024);
  if (std::isfinite(unshaped.j)) out.j = detail::max_abs([&](double t) { return m.at(t).j; }, 0.0, t1, 1024);
  return out;
}

Status plan(const MoveRequest& r, Move<double>& out) noexcept {
  Status st = validate(r);
  if (st != Status::ok) return st;
  Shaper<double> shaper{};
  if (r.shaper != ShaperKind::none) {
    st = design_shaper(r.shaper, *r.omega, r.zeta, r.vtol, shaper);
    if (st != Status::ok) return st;
  }
  Profile<double> prof{};
  Peaks<double> pk{};
  if (r.distance == 0.0) {
    // A trivial move: nothing to do, nothing to shape; still reject an ill-formed request above.
    out = Move<double>{Profile<double>{r.profile, PiecewiseJerk<double>{}}, Shaper<double>{}, Peaks<double>{}};
    return Status::ok;
  }
  switch (r.profile) {
    case ProfileKind::scurve:
    case ProfileKind::scurve_damped: st = plan_scurve(r, prof, pk); break;
    case ProfileKind::ramp_versine: st = plan_ramp_versine(r, prof, pk); break;
    case ProfileKind::pseudopoly:
    case ProfileKind::poly345: st = plan_pseudopoly(r, prof, pk); break;
    case ProfileKind::trapezoid: st = plan_trapezoid(r, prof, pk); break;
    case ProfileKind::jerk_limited: st = plan_jerk_limited(r, prof, pk); break;
  }
  if (st != Status::ok) return st;
  pk = shaped_peaks(prof, shaper, pk);
  st = check_limits(r, pk);
  if (st != Status::ok) return st;
  out = Move<double>{prof, shaper, pk};
  return Status::ok;
}

const char* to_string(ProfileKind k) noexcept {
  switch (k) {
    case ProfileKind::scurve: return "scurve";
    case ProfileKind::scurve_damped: return "scurve-damped";
    case ProfileKind::ramp_versine: return "ramp-versine";
    case ProfileKind::pseudopoly: return "pseudopoly";
    case ProfileKind::poly345: return "poly345";
    case ProfileKind::trapezoid: return "trapezoid";
    case ProfileKind::jerk_limited: return "jerk-limited";
  }
  return "unknown";
}

bool parse_profile_kind(const char* name, ProfileKind& out) noexcept {
  static constexpr ProfileKind all[] = {ProfileKind::scurve,     ProfileKind::scurve_damped, ProfileKind::ramp_versine,
                                        ProfileKind::pseudopoly, ProfileKind::poly345,       ProfileKind::trapezoid,
                                        ProfileKind::jerk_limited};
  if (name == nullptr) return false;
  for (ProfileKind k : all) {
    if (std::strcmp(name, to_string(k)) == 0) {
      out = k;
      return true;
    }
  }
  return false;
}

}  // namespace settle::core
