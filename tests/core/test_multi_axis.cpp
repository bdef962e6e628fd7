// SPDX-License-Identifier: Apache-2.0
// Coordinated multi-axis moves (issue 17, docs/multi_axis.md): every axis starts and ends together,
// stays within its own limits, and leaves every mode at rest. The residuals are checked by an RK4
// integration of each mode driven by the axis's own command (mode_sim.hpp), not by the planner's
// formulas; the limits by sampling the commands densely, not by the reported peaks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mode_sim.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/core/online.hpp"
#include "settle/core/planner.hpp"
#include "settle/core/profiles/registry.hpp"

using namespace settle;
using core::MultiAxisPlan;
using core::MultiAxisRequest;
using core::ProfileKind;
using core::Status;
using core::SyncMode;

namespace {

// Three axes with three different modes and different limits (the second axis binds velocity).
MultiAxisRequest three_axes(ProfileKind profile, SyncMode sync) {
  MultiAxisRequest r{};
  r.base.profile = profile;
  r.sync = sync;
  r.count = 3;
  const double d[3] = {0.1, 0.05, -0.2}, w[3] = {22.0, 30.0, 15.0}, z[3] = {0.0, 0.05, 0.1};
  const double v[3] = {1.0, 0.05, 1.5}, a[3] = {20.0, 10.0, 40.0}, j[3] = {800.0, 800.0, 1500.0};
  for (std::size_t i = 0; i < 3; ++i) {
    r.axes[i].distance = d[i];
    r.axes[i].omega = w[i];
    r.axes[i].zeta = z[i];
    r.axes[i].limits.vmax = v[i];
    r.axes[i].limits.amax = a[i];
    r.axes[i].limits.jmax = j[i];
  }
  return r;
}

// The breakpoints of axis `axis`'s command: its own move's (time sync) or the path's.
std::vector<double> breakpoints(const MultiAxisPlan& p, std::size_t axis) {
  std::vector<double> b = test::move_breakpoints(p.sync() == SyncMode::path ? p.path() : p.axis_move(axis));
  b.insert(b.begin(), 0.0);
  b.push_back(p.duration());
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end(), [](double x, double y) { return std::fabs(x - y) < 1e-13; }), b.end());
  return b;
}

// Residual amplitude of mode (omega, zeta) once axis `axis`'s command is over, by RK4.
double residual(const MultiAxisPlan& p, std::size_t axis, double omega, double zeta) {
  const std::vector<double> b = breakpoints(p, axis);
  test::ModeState s{};
  for (std::size_t k = 0; k + 1 < b.size(); ++k) {
    test::integrate(s, omega, zeta, b[k], b[k + 1], [&](double t) { return p.at(axis, t).a; });
  }
  const double wd = omega * std::sqrt(1.0 - zeta * zeta);
  return std::hypot(s.e, (s.de + zeta * omega * s.e) / wd);
}

struct Sampled {
  double v{0.0}, a{0.0}, j{0.0};
};
Sampled sampled_peaks(const MultiAxisPlan& p, std::size_t axis) {
  Sampled s{};
  const int n = 200000;
  for (int k = 0; k <= n; ++k) {
    const auto x = p.at(axis, p.duration() * k / n);
    s.v = std::max(s.v, std::fabs(x.v));
    s.a = std::max(s.a, std::fabs(x.a));
    s.j = std::max(s.j, std::fabs(x.j));
  }
  return s;
}

void expect_coordinated(const MultiAxisRequest& r, const MultiAxisPlan& p, bool every_mode_on_every_axis) {
  ASSERT_EQ(p.count(), r.count);
  ASSERT_GT(p.duration(), 0.0);
  for (std::size_t i = 0; i < r.count; ++i) {
    const double d = r.axes[i].distance;
    SCOPED_TRACE(i);
    // Every axis ends on its target at rest exactly when the move ends, and not before its last instant.
    const auto end = p.at(i, p.duration());
    EXPECT_EQ(end.p, d);
    EXPECT_EQ(end.v, 0.0);
    const double own = p.sync() == SyncMode::path ? p.duration() : p.axis_move(i).duration();
    EXPECT_NEAR(own, p.duration(), 1e-12 * p.duration());
    EXPECT_NE(p.at(i, p.duration() * (1.0 - 1e-3)).p, d);
    // Each axis within its own limits (a relative 1e-9 of slack for limits met exactly).
    const Sampled s = sampled_peaks(p, i);
    EXPECT_LE(s.v, *r.axes[i].limits.vmax * (1.0 + 1e-9));
    EXPECT_LE(s.a, *r.axes[i].limits.amax * (1.0 + 1e-9));
    EXPECT_LE(s.j, *r.axes[i].limits.jmax * (1.0 + 1e-9));
    // Every mode at rest: the axis's own, and with path sync every other axis's too.
    for (std::size_t k = 0; k < r.count; ++k) {
      if (k != i && !every_mode_on_every_axis) continue;
      EXPECT_LE(residual(p, i, *r.axes[k].omega, r.axes[k].zeta), 1e-9 * std::fabs(d))
          << "axis " << i << " mode of axis " << k;
    }
  }
}

TEST(MultiAxis, PathSyncIsAStraightLineWithEveryModeAtRestOnEveryAxis) {
  // jerk-limited: one ZV per mode; scurve: its own design for the first mode, ZV for the others;
  // fastest: its own design for every mode (two here: its segment table holds the time-optimal move
  // convolved with four impulses, not eight).
  for (const ProfileKind k : {ProfileKind::jerk_limited, ProfileKind::scurve, ProfileKind::fastest}) {
    SCOPED_TRACE(core::to_string(k));
    MultiAxisRequest r = three_axes(k, SyncMode::path);
    if (k == ProfileKind::fastest) r.count = 2;
    MultiAxisPlan p{};
    std::size_t culprit = 0;
    ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
    EXPECT_EQ(p.path_mode_count(), r.count);
    if (k == ProfileKind::fastest) {
      EXPECT_TRUE(p.path().shaper().is_identity());
    }
    if (k == ProfileKind::jerk_limited) {
      EXPECT_EQ(p.path().shaper().count, 8u);
    }
    if (k == ProfileKind::scurve) {
      EXPECT_EQ(p.path().shaper().count, 4u);
    }
    expect_coordinated(r, p, true);
    // Straight by construction: every axis is D_i s(t).
    std::array<double, core::kMaxAxes> per_axis{};
    EXPECT_LE(core::line_deviation(p, per_axis), 1e-15);
    for (int n = 0; n <= 1000; ++n) {
      const double t = p.duration() * n / 1000.0;
      const double s = p.path().at(t).p;
      for (std::size_t i = 0; i < r.count; ++i) EXPECT_EQ(p.at(i, t).p, r.axes[i].distance * s);
    }
  }
}

// What a loop streams to each axis (settle stream --axes): a move of its own that is the plan's
// command on that axis, of the plan's duration (path: to the last bit, so every axis ends on the
// same tick), and within the axis's limits.
TEST(MultiAxis, EachAxisCommandIsThePlansCommandOnThatAxis) {
  for (const SyncMode sync : {SyncMode::path, SyncMode::time}) {
    for (const ProfileKind k : {ProfileKind::jerk_limited, ProfileKind::scurve, ProfileKind::fastest}) {
      if (k == ProfileKind::fastest && sync == SyncMode::time) continue;  // it takes no time to stretch to
      SCOPED_TRACE(core::to_string(k));
      SCOPED_TRACE(core::to_string(sync));
      const MultiAxisRequest r = three_axes(k, sync);
      MultiAxisPlan p{};
      std::size_t culprit = 0;
      ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
      for (std::size_t i = 0; i < r.count; ++i) {
        SCOPED_TRACE(i);
        core::Move<double> m{};
        ASSERT_EQ(core::axis_command(r, p, i, m), Status::ok);
        const double d = std::fabs(r.axes[i].distance);
        // Path: the path's duration exactly. Time: each axis's own plan to the common time, equal to
        // rounding (the loop ends it on the same tick unless the duration falls within that
        // rounding of a tick boundary).
        if (sync == SyncMode::path) {
          EXPECT_EQ(m.duration(), p.duration());
        } else {
          EXPECT_NEAR(m.duration(), p.duration(), 1e-12 * p.duration());
        }
        EXPECT_EQ(m.distance(), r.axes[i].distance);
        double worst = 0.0;
        for (int n = 0; n <= 20000; ++n) {
          const double t = p.duration() * n / 20000.0;
          worst = std::max(worst, std::fabs(m.at(t).p - p.at(i, t).p));
        }
        EXPECT_LE(worst, 1e-12 * d);
        EXPECT_LE(m.peaks().v, *r.axes[i].limits.vmax * (1.0 + 1e-9));
        EXPECT_LE(m.peaks().a, *r.axes[i].limits.amax * (1.0 + 1e-9));
      }
      core::Move<double> m{};
      EXPECT_EQ(core::axis_command(r, p, 3, m), Status::bad_shape_parameter);
    }
  }
}

TEST(MultiAxis, PathLimitsAreTheTightestAxisLimitOverItsDistance) {
  // Axis 1 (vmax 0.05 over 0.05: 1 path unit/s) binds the velocity of the jerk-limited path, whose
  // shapers keep its cruise: axis 1 reaches its vmax, the others stay below theirs.
  const MultiAxisRequest r = three_axes(ProfileKind::jerk_limited, SyncMode::path);
  MultiAxisPlan p{};
  std::size_t culprit = 0;
  ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  EXPECT_NEAR(sampled_peaks(p, 1).v, 0.05, 1e-12);
  EXPECT_LT(sampled_peaks(p, 0).v, 1.0);
  EXPECT_LT(sampled_peaks(p, 2).v, 1.5);
  // An axis that does not move neither limits the path nor brings its mode.
  MultiAxisRequest r2 = r;
  r2.count = 4;
  r2.axes[3] = {0.0, 1e-9, 1e-9, 1e-9, 3.0, 0.0};
  MultiAxisPlan p2{};
  ASSERT_EQ(core::plan_axes(r2, p2, culprit), Status::ok);
  EXPECT_EQ(p2.duration(), p.duration());
  EXPECT_EQ(p2.path_mode_count(), 3u);
  EXPECT_EQ(p2.at(3, 0.5 * p2.duration()).p, 0.0);
}

TEST(MultiAxis, TimeSyncStretchesEveryAxisToTheSlowestWithItsOwnModeAtRest) {
  // With no shaper, jerk-limited designs for no mode: each axis gets a ZV for its own, as with --shaper zv.
  for (const core::ShaperKind sh : {core::ShaperKind::none, core::ShaperKind::zv, core::ShaperKind::zvd}) {
    SCOPED_TRACE(core::to_string(sh));
    MultiAxisRequest r = three_axes(ProfileKind::jerk_limited, SyncMode::time);
    r.base.shaper = sh;
    MultiAxisPlan p{};
    std::size_t culprit = 0;
    ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
    expect_coordinated(r, p, false);
    // The common duration is the slowest axis's shortest move, planned alone.
    double slowest = 0.0;
    for (std::size_t i = 0; i < 3; ++i) {
      core::MoveRequest q = r.base;
      if (sh == core::ShaperKind::none) q.shaper = core::ShaperKind::zv;
      q.distance = r.axes[i].distance;
      q.limits = r.axes[i].limits;
      q.mode_count = 0;
      if (r.axes[i].omega) q.set_mode(*r.axes[i].omega, r.axes[i].zeta);
      core::Move<double> m{};
      ASSERT_EQ(core::plan(q, m), Status::ok);
      slowest = std::max(slowest, m.duration());
    }
    EXPECT_DOUBLE_EQ(p.duration(), slowest);
    // The path leaves the line; the reported deviation matches a dense resampling of it.
    std::array<double, core::kMaxAxes> per_axis{};
    const double dev = core::line_deviation(p, per_axis);
    double dd = 0.0;
    for (std::size_t i = 0; i < 3; ++i) dd += r.axes[i].distance * r.axes[i].distance;
    double resampled = 0.0;
    for (int n = 0; n <= 100000; ++n) {
      const double t = p.duration() * n / 100000.0;
      double x[3], pd = 0.0;
      for (std::size_t i = 0; i < 3; ++i) {
        x[i] = p.at(i, t).p;
        pd += x[i] * r.axes[i].distance;
      }
      double e2 = 0.0;
      for (std::size_t i = 0; i < 3; ++i) e2 += std::pow(x[i] - r.axes[i].distance * pd / dd, 2);
      resampled = std::max(resampled, std::sqrt(e2));
    }
    EXPECT_GT(dev, 1e-4);
    EXPECT_GE(dev, resampled * (1.0 - 1e-12));
    EXPECT_LE(dev, resampled * (1.0 + 1e-6));
    for (std::size_t i = 0; i < 3; ++i) EXPECT_LE(per_axis[i], dev * (1.0 + 1e-12));
  }
}

TEST(MultiAxis, TheResidualCheckSeesAMoveNotShapedForTheMode) {
  // The control of the checks above: jerk-limited moves for axes that declare no mode leave the
  // modes ringing.
  const MultiAxisRequest r = three_axes(ProfileKind::jerk_limited, SyncMode::time);
  MultiAxisRequest blind = r;
  for (std::size_t i = 0; i < 3; ++i) blind.axes[i].omega.reset();
  MultiAxisPlan p{};
  std::size_t culprit = 0;
  ASSERT_EQ(core::plan_axes(blind, p, culprit), Status::ok);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(p.axis_move(i).shaper().is_identity());
    EXPECT_GT(residual(p, i, *r.axes[i].omega, r.axes[i].zeta), 1e-4 * std::fabs(r.axes[i].distance)) << i;
  }
}

TEST(MultiAxis, RefusesWithTheAxisToBlame) {
  MultiAxisPlan p{};
  std::size_t culprit = 0;
  MultiAxisRequest r = three_axes(ProfileKind::jerk_limited, SyncMode::path);
  MultiAxisRequest bad = r;
  bad.count = 0;
  EXPECT_EQ(core::plan_axes(bad, p, culprit), Status::bad_shape_parameter);
  bad.count = core::kMaxAxes + 1;
  EXPECT_EQ(core::plan_axes(bad, p, culprit), Status::bad_shape_parameter);
  bad = r;
  bad.axes[1].limits.vmax = -1.0;
  EXPECT_EQ(core::plan_axes(bad, p, culprit), Status::non_positive_limit);
  EXPECT_EQ(culprit, 1u);
  bad = r;
  bad.axes[2].zeta = 1.0;
  EXPECT_EQ(core::plan_axes(bad, p, culprit), Status::zeta_out_of_range);
  EXPECT_EQ(culprit, 2u);
  bad = r;
  bad.axes[0].distance = NAN;
  EXPECT_EQ(core::plan_axes(bad, p, culprit), Status::non_finite_input);
  EXPECT_EQ(culprit, 0u);
  // Time sync stretches moves to a time: `fastest` finds its own and cannot.
  bad = three_axes(ProfileKind::fastest, SyncMode::time);
  EXPECT_EQ(core::plan_axes(bad, p, culprit), Status::unsupported_request);
  EXPECT_LT(culprit, 3u);
  // A failed plan leaves the output untouched.
  EXPECT_EQ(p.count(), 0u);
}

TEST(MultiAxis, OneAxisIsTheSingleAxisPlan) {
  // Path sync of one axis: the same move as planning it alone (scaled by its distance).
  MultiAxisRequest r = three_axes(ProfileKind::scurve, SyncMode::path);
  r.count = 1;
  MultiAxisPlan p{};
  std::size_t culprit = 0;
  ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  core::MoveRequest q{};
  q.profile = ProfileKind::scurve;
  q.distance = r.axes[0].distance;
  q.limits = r.axes[0].limits;
  if (r.axes[0].omega) q.set_mode(*r.axes[0].omega);
  core::Move<double> m{};
  ASSERT_EQ(core::plan(q, m), Status::ok);
  EXPECT_NEAR(p.duration(), m.duration(), 1e-12 * m.duration());
  for (int n = 0; n <= 100; ++n) {
    const double t = m.duration() * n / 100.0;
    EXPECT_NEAR(p.at(0, t).p, m.at(t).p, 1e-12);
  }
}

// Halt and retarget of a coordinated move (docs/multi_axis.md, "Halt and retarget"): each axis's
// request is made from its own command (axis_command) with what axis_online gives it, as the loop
// does on every axis it streams to; a path's halt, or its retarget to targets on the line, is
// planned once (plan_path_online), anything else on each axis alone. Checked against the axes' own
// limits (sampled) and an RK4 integration of each mode driven by each axis's whole command, not
// against the planner.
struct AxisBlends {
  std::array<core::Move<double>, 3> move{};
  std::array<core::Blend, 3> blend{};
  std::array<core::AxisOnline, 3> online{};
  bool once{false};  // planned once for the path
};

MultiAxisPlan planned(const MultiAxisRequest& r) {
  MultiAxisPlan p{};
  std::size_t culprit = 0;
  EXPECT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  return p;
}

AxisBlends change_axes(const MultiAxisRequest& r, const MultiAxisPlan& p, double t,
                       const std::array<std::optional<double>, 3>& targets) {
  AxisBlends out{};
  std::array<core::OnlineRequest, 3> q{};
  std::array<const core::OnlineRequest*, 3> qp{};
  std::array<double, 3> d{};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(core::axis_command(r, p, i, out.move[i]), Status::ok);
    EXPECT_EQ(core::axis_online(r, p, i, out.online[i]), Status::ok);
    const core::AxisOnline& o = out.online[i];
    EXPECT_EQ(core::online_request(out.move[i], t, o.modes.data(), o.mode_count, o.limits, targets[i], q[i]), Status::ok);
    // The blends themselves (a halt's choice among them and finishing the move, on 1 and 3 path
    // axes: test_halt.cpp).
    q[i].running.reset();
    qp[i] = &q[i];
    d[i] = r.axes[i].distance;
  }
  out.once = r.sync == SyncMode::path && core::path_change(qp.data(), d.data(), 3);
  if (out.once) {
    std::array<core::OnlinePlan, 3> plans{};
    std::size_t culprit = 3;
    EXPECT_EQ(core::plan_path_online(qp.data(), d.data(), 3, plans.data(), culprit), Status::ok) << " t " << t;
    for (std::size_t i = 0; i < 3; ++i) out.blend[i] = plans[i].blend;
    return out;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(core::plan_online(q[i], out.blend[i]), Status::ok) << "axis " << i << " t " << t;
  }
  return out;
}

// Within the axis's own limits, at rest at the end, every listed mode at rest once the whole
// command (the move to t, then the blend) is over.
void expect_axis_blend(const MultiAxisRequest& r, const AxisBlends& ab, std::size_t i, double t,
                       std::optional<double> target, int n) {
  const core::Blend& b = ab.blend[i];
  const double d = std::max(std::fabs(r.axes[i].distance), target ? std::fabs(*target) : 0.0);
  double v = 0.0, a = 0.0;
  for (int k = 0; k <= 4000; ++k) {
    const core::Sample<double> s = b.at(b.duration() * k / 4000.0);
    v = std::max(v, std::fabs(s.v));
    a = std::max(a, std::fabs(s.a));
  }
  EXPECT_LE(v, *r.axes[i].limits.vmax * (1.0 + 1e-9)) << "case " << n << " axis " << i;
  EXPECT_LE(a, *r.axes[i].limits.amax * (1.0 + 1e-9)) << "case " << n << " axis " << i;
  EXPECT_LE(b.peaks().j, *r.axes[i].limits.jmax * (1.0 + 1e-9)) << "case " << n << " axis " << i;
  const core::Sample<double> e = b.at(std::nextafter(b.duration(), 0.0));
  EXPECT_LE(std::fabs(e.v), 1e-9 * *r.axes[i].limits.vmax) << "case " << n << " axis " << i;
  if (target) {
    EXPECT_NEAR(b.end_position(), *target, 1e-9 * d) << "case " << n << " axis " << i;
  }
  const core::AxisOnline& o = ab.online[i];
  for (std::size_t k = 0; k < o.mode_count; ++k) {
    EXPECT_LE(test::residual_after_blend(ab.move[i], t, b, o.modes[k].omega, o.modes[k].zeta), 1e-9 * d)
        << "case " << n << " axis " << i << " mode " << k;
  }
}

// Path sync: a halt is planned once and every axis's blend is the reference's scaled by D_i / D_0
// (its segment length bit for bit), so a halt from any of a hundred random times keeps the
// straight line, stops every axis at the same instant, and leaves every axis's modes at rest
// within its own limits.
TEST(MultiAxisOnline, PathSyncHaltsKeepTheLineAndEndTogetherAtRest) {
  std::mt19937_64 rng{20261203};
  for (const ProfileKind k : {ProfileKind::jerk_limited, ProfileKind::scurve}) {
    SCOPED_TRACE(core::to_string(k));
    const MultiAxisRequest r = three_axes(k, SyncMode::path);
    const MultiAxisPlan p = planned(r);
    for (int n = 0; n < 50; ++n) {
      const double t = std::uniform_real_distribution<double>{0.0, 1.0}(rng) * p.duration();
      const AxisBlends ab = change_axes(r, p, t, {});
      EXPECT_TRUE(ab.once) << "case " << n;
      const core::Blend& b0 = ab.blend[0];
      for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(ab.online[i].mode_count, 3u);
        expect_axis_blend(r, ab, i, t, std::nullopt, n);
        const core::Blend& b = ab.blend[i];
        EXPECT_EQ(b.segment_length(), b0.segment_length()) << "case " << n << " axis " << i;
        const double ratio = r.axes[i].distance / r.axes[0].distance;
        double off = 0.0;
        for (int m = 0; m <= 400; ++m) {
          const double u = b0.duration() * m / 400.0;
          off = std::max(off, std::fabs(b.at(u).p - ratio * b0.at(u).p));
        }
        EXPECT_LE(off, 1e-12 * std::fabs(r.axes[i].distance)) << "case " << n << " axis " << i;
      }
    }
  }
}

// A retarget to a point on the line (lambda D) is planned once too and keeps the line; one off
// the line blends each axis on its own, still at rest on its modes and within its limits.
TEST(MultiAxisOnline, PathSyncRetargetsReachTheNewTargetsAtRest) {
  std::mt19937_64 rng{17};
  const MultiAxisRequest r = three_axes(ProfileKind::jerk_limited, SyncMode::path);
  const MultiAxisPlan p = planned(r);
  std::uniform_real_distribution<double> uni{0.0, 1.0};
  for (int n = 0; n < 30; ++n) {
    const double t = uni(rng) * p.duration();
    const double lambda = 0.3 + 1.2 * uni(rng);
    std::array<std::optional<double>, 3> on{}, off{};
    for (std::size_t i = 0; i < 3; ++i) {
      on[i] = lambda * r.axes[i].distance;
      off[i] = (0.3 + 1.2 * uni(rng)) * r.axes[i].distance;
    }
    const AxisBlends a = change_axes(r, p, t, on);
    EXPECT_TRUE(a.once) << "case " << n;
    for (std::size_t i = 0; i < 3; ++i) {
      expect_axis_blend(r, a, i, t, on[i], n);
      EXPECT_EQ(a.blend[i].segment_length(), a.blend[0].segment_length()) << "case " << n;
    }
    const AxisBlends b = change_axes(r, p, t, off);
    EXPECT_FALSE(b.once) << "case " << n;
    for (std::size_t i = 0; i < 3; ++i) expect_axis_blend(r, b, i, t, off[i], n);
  }
}

// What is one path's change and what is not: plan_path_online refuses the rest, `out` untouched.
TEST(MultiAxisOnline, OnlyAPathsOwnChangeIsPlannedOnce) {
  const MultiAxisRequest r = three_axes(ProfileKind::jerk_limited, SyncMode::path);
  const MultiAxisPlan p = planned(r);
  const double t = 0.4 * p.duration();
  std::array<core::Move<double>, 3> m{};
  std::array<core::OnlineRequest, 3> q{};
  std::array<const core::OnlineRequest*, 3> qp{};
  std::array<double, 3> d{};
  for (std::size_t i = 0; i < 3; ++i) {
    core::AxisOnline o{};
    ASSERT_EQ(core::axis_command(r, p, i, m[i]), Status::ok);
    ASSERT_EQ(core::axis_online(r, p, i, o), Status::ok);
    ASSERT_EQ(core::online_request(m[i], t, o.modes.data(), o.mode_count, o.limits, std::nullopt, q[i]), Status::ok);
    qp[i] = &q[i];
    d[i] = r.axes[i].distance;
  }
  EXPECT_EQ(core::path_reference(d.data(), 3), 0u);
  EXPECT_TRUE(core::path_change(qp.data(), d.data(), 3));
  const auto refused = [&](const char* what) {
    EXPECT_FALSE(core::path_change(qp.data(), d.data(), 3)) << what;
    std::array<core::OnlinePlan, 3> out{};
    out[1].rest_after = -1.0;
    std::size_t culprit = 9;
    EXPECT_EQ(core::plan_path_online(qp.data(), d.data(), 3, out.data(), culprit), Status::bad_shape_parameter) << what;
    EXPECT_EQ(out[1].rest_after, -1.0) << what;
  };
  core::OnlineRequest keep = q[1];
  q[1].target = 0.5 * d[1];  // a retarget of one axis, a halt of the others
  refused("retarget and halt");
  q[1] = keep;
  q[1].modes[0].omega *= 1.001;
  refused("another mode");
  q[1] = keep;
  q[1].limits.vmax *= 0.9;  // the reference's blend scaled could exceed it
  refused("a tighter limit");
  q[1] = keep;
  q[1].start.v *= 1.001;  // not where the path puts it
  refused("another state");
  q[1] = keep;
  qp[2] = nullptr;  // a moving axis without a request
  refused("no request");
  qp[2] = &q[2];
  // Retargets: on the line (lambda D_i) once; off it, each alone.
  for (std::size_t i = 0; i < 3; ++i) q[i].target = 0.7 * d[i];
  EXPECT_TRUE(core::path_change(qp.data(), d.data(), 3));
  q[2].target = 0.7 * d[2] * (1.0 + 1e-9);
  refused("off the line");
  // An axis that does not move has no request and does not count; none moving is no path.
  for (std::size_t i = 0; i < 3; ++i) q[i].target.reset();
  d[1] = 0.0;
  qp[1] = nullptr;
  EXPECT_TRUE(core::path_change(qp.data(), d.data(), 3));
  d = {0.0, 0.0, 0.0};
  EXPECT_EQ(core::path_reference(d.data(), 3), 3u);
  refused("nothing moves");
}

// Time sync: each axis halts on its own mode and limits.
TEST(MultiAxisOnline, TimeSyncHaltsEachAxisOnItsOwnModeAndLimits) {
  std::mt19937_64 rng{4};
  const MultiAxisRequest r = three_axes(ProfileKind::scurve, SyncMode::time);
  const MultiAxisPlan p = planned(r);
  for (int n = 0; n < 30; ++n) {
    const double t = std::uniform_real_distribution<double>{0.0, 1.0}(rng) * p.duration();
    const AxisBlends ab = change_axes(r, p, t, {});
    for (std::size_t i = 0; i < 3; ++i) {
      ASSERT_EQ(ab.online[i].mode_count, 1u);
      EXPECT_EQ(ab.online[i].modes[0].omega, *r.axes[i].omega);
      EXPECT_EQ(ab.online[i].limits.vmax, *r.axes[i].limits.vmax);
      expect_axis_blend(r, ab, i, t, std::nullopt, n);
    }
  }
}

TEST(MultiAxisOnline, LimitsAreThePathsTimesTheDistanceOrTheMovesOwnPeaks) {
  MultiAxisRequest r = three_axes(ProfileKind::jerk_limited, SyncMode::path);
  MultiAxisPlan p{};
  std::size_t culprit = 0;
  ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  core::AxisOnline o{};
  // vmax: the second axis binds (0.05 over 0.05: 1 per unit of path); amax is 200 on every axis.
  ASSERT_EQ(core::axis_online(r, p, 2, o), Status::ok);
  EXPECT_DOUBLE_EQ(o.limits.vmax, 1.0 * 0.2);
  EXPECT_DOUBLE_EQ(o.limits.amax, 200.0 * 0.2);
  // No axis gives a limit (a move of a given time): the path's own peaks times |D_i|, the axis
  // move's own peaks.
  r = three_axes(ProfileKind::poly345, SyncMode::path);
  r.base.time = 0.5;
  for (std::size_t i = 0; i < 3; ++i) r.axes[i].limits = {};
  ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  ASSERT_EQ(core::axis_online(r, p, 2, o), Status::ok);
  EXPECT_EQ(o.limits.vmax, p.peaks(2).v);
  EXPECT_EQ(o.limits.amax, p.peaks(2).a);
  EXPECT_EQ(o.limits.jmax, p.peaks(2).j);
  // A trapezoid has no jerk peak to keep: amax times the fastest mode's omega.
  r.base.profile = ProfileKind::trapezoid;
  ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  ASSERT_EQ(core::axis_online(r, p, 2, o), Status::ok);
  EXPECT_EQ(o.limits.jmax, o.limits.amax * 30.0);
  // Time sync without a mode on the axis: the fallback mode (the plant's fundamental) is kept.
  r = three_axes(ProfileKind::jerk_limited, SyncMode::time);
  r.axes[0].omega.reset();
  ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  ASSERT_EQ(core::axis_online(r, p, 0, o), Status::ok);
  EXPECT_EQ(o.mode_count, 0u);
  const core::Mode fundamental{12.0, 0.02};
  ASSERT_EQ(core::axis_online(r, p, 0, o, &fundamental), Status::ok);
  ASSERT_EQ(o.mode_count, 1u);
  EXPECT_EQ(o.modes[0].omega, 12.0);
  ASSERT_EQ(core::axis_online(r, p, 1, o, &fundamental), Status::ok);
  EXPECT_EQ(o.modes[0].omega, 30.0);
  // Refused: an axis that does not move, one that is not there, more path modes than a blend holds.
  r = three_axes(ProfileKind::jerk_limited, SyncMode::path);
  r.axes[1].distance = 0.0;
  ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  EXPECT_EQ(core::axis_online(r, p, 1, o), Status::non_positive_limit);
  EXPECT_EQ(core::axis_online(r, p, 3, o), Status::bad_shape_parameter);
  r = three_axes(ProfileKind::scurve, SyncMode::path);
  r.count = 5;
  for (std::size_t i = 0; i < 5; ++i) {
    r.axes[i] = r.axes[0];
    r.axes[i].distance = 0.1 * static_cast<double>(i + 1);
    r.axes[i].omega = 20.0 + 3.0 * static_cast<double>(i);
  }
  ASSERT_EQ(core::plan_axes(r, p, culprit), Status::ok);
  EXPECT_EQ(core::axis_online(r, p, 0, o), Status::unsupported_request);
}

}  // namespace

// The one line geometry every line deviation uses, against the cross product: in three axes the
// distance of p from the line along d is |p x d| / |d|, and the offset is perpendicular to d.
TEST(MultiAxis, OffsetFromTheLineIsTheCrossProductsDistance) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  for (int k = 0; k < 1000; ++k) {
    const double p[3] = {u(rng), u(rng), u(rng)}, d[3] = {u(rng), u(rng), u(rng)};
    double off[3] = {NAN, NAN, NAN};
    const double len = core::offset_from_line(p, d, 3, off);
    const double cx = p[1] * d[2] - p[2] * d[1], cy = p[2] * d[0] - p[0] * d[2], cz = p[0] * d[1] - p[1] * d[0];
    const double dn = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    EXPECT_NEAR(len, std::sqrt(cx * cx + cy * cy + cz * cz) / dn, 1e-12 * 25.0);
    EXPECT_NEAR(off[0] * d[0] + off[1] * d[1] + off[2] * d[2], 0.0, 1e-12 * 25.0 * dn);
    EXPECT_NEAR(std::sqrt(off[0] * off[0] + off[1] * off[1] + off[2] * off[2]), len, 1e-12 * 25.0);
  }
  // A point on the line, a line of zero length, and one axis.
  const double on[2] = {2.0, -4.0}, dir[2] = {-1.0, 2.0}, zero[2] = {0.0, 0.0};
  double off[2] = {NAN, NAN};
  EXPECT_NEAR(core::offset_from_line(on, dir, 2, off), 0.0, 1e-15);
  EXPECT_EQ(core::offset_from_line(on, zero, 2, off), 0.0);
  EXPECT_EQ(off[0], 0.0);
  EXPECT_EQ(off[1], 0.0);
  const double one = 3.0, d1 = 7.0;
  EXPECT_EQ(core::offset_from_line(&one, &d1, 1), 0.0);
}
