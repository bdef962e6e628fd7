// SPDX-License-Identifier: Apache-2.0
#pragma once
// Seeded random moves for the fixed-point suites: every profile kind, shaped or not, distances
// up to 2^24 counts, 16 to 2^17 ticks (periods in whole microseconds), move times between half and
// ten periods of the mode (the range the papers' designs are meant for), and output formats that
// fit each move.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "../core/test_helpers.hpp"
#include "settle/core/fixed/format.hpp"
#include "settle/core/planner.hpp"

namespace settle::test {

// A timed move (core's test helpers), shaped if asked; a pseudo-polynomial gets seed 004's optimum.
inline core::Move<double> planned(core::ProfileKind k, double d, double t, double omega = 20.0, double zeta = 0.0,
                                  core::ShaperKind shaper = core::ShaperKind::none) {
  core::MoveRequest r = timed(k, d, t, omega, zeta);
  r.shaper = shaper;
  if (k == core::ProfileKind::pseudopoly) {
    r.gamma_count = 3;
    r.gammas[0] = 3.024;
    r.gammas[1] = 4.565;
    r.gammas[2] = 5.874;
  }
  return must_plan(r);
}

struct FixedCase {
  core::MoveRequest req{};
  core::Move<double> move{};
  core::fixed::Scale scale{};
};

enum class Kinds { closed_forms, pseudopoly, all };

struct FixedCaseGen {
  std::mt19937_64 rng;
  Kinds kinds{Kinds::all};
  double shaped{0.2};  // share of shaped moves

  double uni(double a, double b) { return std::uniform_real_distribution<double>{a, b}(rng); }
  double logu(double a, double b) { return std::exp(uni(std::log(a), std::log(b))); }
  bool coin(double p = 0.5) { return uni(0, 1) < p; }

  core::ProfileKind kind() {
    using core::ProfileKind;
    static constexpr ProfileKind closed[] = {ProfileKind::scurve,  ProfileKind::scurve_damped, ProfileKind::ramp_versine,
                                             ProfileKind::poly345, ProfileKind::trapezoid,     ProfileKind::jerk_limited};
    switch (kinds) {
      case Kinds::closed_forms: return closed[rng() % 6];
      case Kinds::pseudopoly: return ProfileKind::pseudopoly;
      case Kinds::all: break;
    }
    return rng() % 7 == 0 ? ProfileKind::pseudopoly : closed[rng() % 6];
  }

  core::MoveRequest request() {
    using core::ProfileKind;
    core::MoveRequest r{};
    r.profile = kind();
    r.distance = logu(1e-4, 10.0) * (coin() ? 1 : -1);
    const double d = std::fabs(r.distance);
    const double zeta = r.profile == ProfileKind::scurve ? 0.0 : uni(0.0, 0.3);
    if (r.profile == ProfileKind::pseudopoly) {
      r.gamma_count = 3 + rng() % 6;
      double g = uni(3.0, 4.0);
      for (std::size_t i = 0; i < r.gamma_count; ++i) {
        r.gammas[i] = g;
        g += uni(0.3, 2.0);
      }
    }
    const bool limits = r.profile == ProfileKind::jerk_limited || coin(0.3);
    if (limits) {
      const double v = logu(0.05, 5.0) * std::max(d, 1e-3);
      r.limits.vmax = v;
      if (r.profile != ProfileKind::ramp_versine) {
        r.limits.amax = v * logu(1.0, 100.0);
        if (r.profile != ProfileKind::trapezoid) r.limits.jmax = *r.limits.amax * logu(1.0, 200.0);
      }
      r.set_mode(6.283185307179586 / (d / v) * logu(0.5, 10.0), zeta);  // a mode near the move's time scale
    } else {
      r.time = logu(0.01, 10.0);
      r.set_mode(6.283185307179586 / *r.time * logu(0.5, 10.0), zeta);
    }
    return r;
  }

  // A planned move (shaped with probability `shaped`) and a scale mapping it to 1..2^24 counts
  // over 16..2^17 ticks. Shaped moves are assembled from the unshaped plan and the designed shaper
  // rather than planned with their (costly) shaped peaks: ZV, ZVD and EI have positive impulses, so
  // the shaped move is a convex combination of delayed copies and the unshaped peaks bound it.
  bool next(FixedCase& c) {
    c.req = request();
    if (core::plan(c.req, c.move) != core::Status::ok || !(c.move.duration() > 0.0)) return false;
    if (c.req.profile != core::ProfileKind::ramp_versine && coin(shaped)) {
      static constexpr core::ShaperKind shapers[] = {core::ShaperKind::zv, core::ShaperKind::zvd, core::ShaperKind::ei};
      c.req.shaper = shapers[rng() % 3];
      core::Shaper<double> s{};
      if (core::design_shaper(c.req.shaper, c.req.omega(), c.req.zeta(), c.req.vtol, s) != core::Status::ok) return false;
      c.move = core::Move<double>{c.move.profile(), s, c.move.peaks()};
    }
    c.scale.axis.counts_per_unit = logu(1.0, 16777216.0) / std::fabs(c.req.distance);
    // The period is a whole number of microseconds: a move shorter than 2^17 us gets fewer ticks.
    c.scale.axis.period_us =
        static_cast<std::uint32_t>(std::max(1.0, std::nearbyint(c.move.duration() * 1e6 / logu(16.0, 131072.0))));
    const double dt = c.scale.axis.period_s(), cpu = c.scale.axis.counts_per_unit;
    const core::Peaks<double>& pk = c.move.peaks();
    const double vp = pk.v * cpu * dt;
    const double ap = std::isfinite(pk.a) ? pk.a * cpu * dt * dt : vp;
    c.scale.velocity_frac_bits = std::clamp(28 - static_cast<int>(std::ceil(std::log2(vp + 1.0))), 0, 16);
    c.scale.accel_frac_bits = std::clamp(28 - static_cast<int>(std::ceil(std::log2(ap + 1.0))), 0, 16);
    return true;
  }
};

// The double evaluator in the fixed-point output units (counts, LSB of v and a) at time t.
struct Reference {
  double p, v, a;
};
inline Reference reference(const core::Move<double>& m, const core::fixed::Scale& s, double t) {
  const core::Sample<double> x = m.at(t);
  const double cpu = s.axis.counts_per_unit, dt = s.axis.period_s();
  return {x.p * cpu, std::ldexp(x.v * cpu * dt, s.velocity_frac_bits),
          std::ldexp(x.a * cpu * dt * dt, s.accel_frac_bits)};
}

// |fixed - double| at tick n (counts, LSB, LSB). Where v or a jumps exactly at the tick (a
// trapezoid's corners, a ramp-versine's ends) either one-sided limit is a right answer, so when
// the plain reading is off the readings just before and after are tried too.
struct Errors {
  double p{0.0}, v{0.0}, a{0.0};
  Reference ref{};
};
inline Errors errors_at(const core::Move<double>& m, const core::fixed::Scale& s, std::int32_t n,
                        const core::fixed::Sample& f) {
  const double t = n * s.axis.period_s();
  auto diff = [&](double tt) {
    const Reference r = reference(m, s, tt);
    return Errors{std::fabs(f.p - r.p), std::fabs(f.v - r.v), std::fabs(f.a - r.a), r};
  };
  Errors e = diff(t);
  if (e.v > 1.0 || e.a > 1.0) {
    for (double tt : {t - 1e-7 * s.axis.period_s(), t + 1e-7 * s.axis.period_s()}) {
      const Errors o = diff(tt);
      e.p = std::min(e.p, o.p);
      e.v = std::min(e.v, o.v);
      e.a = std::min(e.a, o.a);
    }
  }
  return e;
}

}  // namespace settle::test
