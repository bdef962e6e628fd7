// SPDX-License-Identifier: Apache-2.0
// Every profile in the registry (settle/core/profiles/registry.hpp), so that a new registry line is
// covered without a new test: its name round-trips, its example request plans into its own kind
// and shape, and the double, float and fixed-point evaluators (random access and stepping) agree
// on it. Also the generated dispatch: visit reaches every alternative of the variant, and a
// ProfileKind value no registry line defines is refused, never mapped onto another profile.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <type_traits>
#include <variant>

#include "settle/core/fixed/motion.hpp"
#include "settle/core/planner.hpp"
#include "settle/core/stepper.hpp"

using namespace settle;
using core::ProfileKind;
using core::Status;

namespace {

constexpr auto kUnregistered = static_cast<ProfileKind>(core::kProfileCount);

template <typename Kind>
core::Move<double> plan_example(Kind kind) {
  core::MoveRequest r = core::profile_t<kind.value>::example();
  r.profile = kind.value;
  core::Move<double> m{};
  EXPECT_EQ(core::plan(r, m), Status::ok) << core::to_string(kind.value);
  return m;
}

}  // namespace

TEST(Registry, EveryNameRoundTripsAndIsUnique) {
  std::set<std::string> seen;
  int visited = 0;
  core::for_each_profile([&](auto kind) {
    using P = core::profile_t<kind.value>;
    ++visited;
    EXPECT_EQ(static_cast<std::size_t>(kind.value), static_cast<std::size_t>(visited - 1));
    EXPECT_STREQ(core::to_string(kind.value), P::name);
    EXPECT_STRNE(core::summary(kind.value), "");
    ProfileKind parsed = kUnregistered;
    ASSERT_TRUE(core::parse_profile_kind(P::name, parsed)) << P::name;
    EXPECT_EQ(parsed, kind.value);
    EXPECT_TRUE(seen.insert(P::name).second) << "two profiles are named " << P::name;
  });
  EXPECT_EQ(static_cast<std::size_t>(visited), core::kProfileCount);
  EXPECT_EQ(core::profile_names().size(), core::kProfileCount);
  ProfileKind untouched = ProfileKind::trapezoid;
  EXPECT_FALSE(core::parse_profile_kind("s-curve", untouched));
  EXPECT_FALSE(core::parse_profile_kind(nullptr, untouched));
  EXPECT_EQ(untouched, ProfileKind::trapezoid);
  EXPECT_STREQ(core::to_string(kUnregistered), "unknown");
}

TEST(Registry, AKindNoLineDefinesIsRefusedNotMappedOntoAnother) {
  core::MoveRequest r = core::ScurveProfile::example();
  r.profile = kUnregistered;
  core::Move<double> m{};
  EXPECT_EQ(core::plan(r, m), Status::unsupported_request);
  r.distance = 0.0;  // not even as a trivial move
  EXPECT_EQ(core::plan(r, m), Status::unsupported_request);
}

// The generated visit hands f the alternative the variant holds, for every alternative (the
// hand-written switch it replaces sent every index it did not list to alternative 0).
TEST(Registry, VisitReachesEveryAlternative) {
  using Variant = core::Profile<double>::Variant;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          const core::Profile<double> p{ProfileKind{}, Variant{std::in_place_index<I>}};
          const std::size_t got = p.visit([](const auto& shape) {
            using S = std::decay_t<decltype(shape)>;
            return Variant{S{}}.index();
          });
          EXPECT_EQ(got, I);
        }(),
        ...);
  }(std::make_index_sequence<std::variant_size_v<Variant>>{});
}

TEST(Registry, EveryExamplePlansIntoItsOwnKindAndShape) {
  core::for_each_profile([&](auto kind) {
    using P = core::profile_t<kind.value>;
    SCOPED_TRACE(P::name);
    const core::Move<double> m = plan_example(kind);
    EXPECT_EQ(m.profile().kind(), kind.value);
    EXPECT_TRUE(std::holds_alternative<typename P::template Shape<double>>(m.profile().variant()));
    ASSERT_GT(m.duration(), 0.0);
    ASSERT_NE(m.distance(), 0.0);
    EXPECT_EQ(m.at(m.duration()).p, m.distance());
    EXPECT_TRUE(std::isfinite(m.at(0.0).v));  // finite at the start (no NaN, no inf)
    EXPECT_TRUE(std::isfinite(m.peaks().v));
    // The trivial move of the same kind keeps its kind and shape too.
    core::MoveRequest z = P::example();
    z.profile = kind.value;
    z.distance = 0.0;
    core::Move<double> zm{};
    ASSERT_EQ(core::plan(z, zm), Status::ok);
    EXPECT_TRUE(std::holds_alternative<typename P::template Shape<double>>(zm.profile().variant()));
  });
}

// Float evaluation (the Cortex-M4F's) of every example within float rounding of double, random
// access and stepping alike; the double stepper equals random access to rounding.
TEST(Registry, DoubleAndFloatEvaluatorsAgree) {
  core::for_each_profile([&](auto kind) {
    SCOPED_TRACE(core::to_string(kind.value));
    const core::Move<double> md = plan_example(kind);
    const core::Move<float> mf{md};
    const double dt = 1e-3;
    core::MoveStepper<double> sd{md, dt};
    core::MoveStepper<float> sf{mf, static_cast<float>(dt)};
    const double tol = 4e-6 * std::fabs(md.distance());
    const auto n_end = static_cast<int>(std::ceil(md.duration() / dt)) + 2;
    double worst_f = 0.0, worst_step = 0.0;
    for (int n = 0; n <= n_end; ++n) {
      const double t = n * dt;
      const double pd = md.at(t).p;
      worst_f = std::max(worst_f, std::fabs(static_cast<double>(mf.at(static_cast<float>(t)).p) - pd));
      worst_f = std::max(worst_f, std::fabs(static_cast<double>(sf.step().p) - pd));
      worst_step = std::max(worst_step, std::fabs(sd.step().p - pd));
    }
    EXPECT_LE(worst_f, tol);
    EXPECT_LE(worst_step, 1e-12 * std::fabs(md.distance()));
  });
}

// Converting a planned Move<double> to float (what the servo loop does at submit) gives exactly the
// move whose shape is built in float from the planner's parameters: every value, every tick,
// bitwise. The conversion rounds the double evaluator's own values instead of recomputing them in
// double (casts only on a Cortex-M4F); in place (convert_from, into a slot that held another move)
// it is the same move again. Unshaped, shaped (ZVD on the example's mode) and, for the S-curves,
// with a cruise.
TEST(Registry, FloatConversionIsTheFloatMoveOfTheSameParameters) {
  std::size_t checked = 0;
  core::for_each_profile([&](auto kind) {
    using P = core::profile_t<kind.value>;
    for (const int variant : {0, 1, 2}) {  // unshaped, ZVD, a ramp-cycloid's cruise
      SCOPED_TRACE(std::string{core::to_string(kind.value)} + (variant == 1 ? " zvd" : variant == 2 ? " cruise" : ""));
      core::MoveRequest r = P::example();
      r.profile = kind.value;
      if (variant == 1) r.shaper = core::ShaperKind::zvd;
      core::Move<double> md{};
      if (core::plan(r, md) != Status::ok) continue;  // a kind that refuses a shaper
      if constexpr (std::is_same_v<typename P::template Shape<double>, core::RampCycloid<double>>) {
        if (variant == 2) {  // the same transitions around a cruise (a vmax that binds)
          core::RampCycloidParams c = std::get<core::RampCycloid<double>>(md.profile().variant()).params();
          c.cruise = 0.05;
          c.distance += c.amplitude * c.tau * c.cruise;
          md.assign<core::RampCycloid<double>>(kind.value, c, nullptr, md.peaks());
        }
      }
      const auto& shape_d = *std::get_if<typename P::template Shape<double>>(&md.profile().variant());
      const typename P::template Shape<float> shape_f{shape_d.params()};
      const core::Move<float> ref{core::Profile<float>{kind.value, shape_f}, core::Shaper<float>{md.shaper()},
                                  core::Peaks<float>{static_cast<float>(md.peaks().v), static_cast<float>(md.peaks().a),
                                                     static_cast<float>(md.peaks().j), md.peaks().velocity_step,
                                                     md.peaks().acceleration_step}};
      const core::Move<float> converted{md};
      core::Move<float> slot{plan_example(std::integral_constant<core::ProfileKind, core::ProfileKind::poly345>{})};
      slot.convert_from(md);
      for (const core::Move<float>* m : {&converted, static_cast<const core::Move<float>*>(&slot)}) {
        EXPECT_EQ(m->profile().kind(), kind.value);
        EXPECT_EQ(m->duration(), ref.duration());
        EXPECT_EQ(m->distance(), ref.distance());
        ASSERT_EQ(m->shaper().count, ref.shaper().count);
        const int n_end = static_cast<int>(std::ceil(md.duration() / 1e-3)) + 2;
        int differ = 0;
        core::MoveStepper<float> st{*m, 1e-3F}, st_ref{ref, 1e-3F};
        for (int n = -1; n <= n_end; ++n) {
          const float t = static_cast<float>(n) * 1e-3F;
          const core::Sample<float> a = m->at(t), b = ref.at(t);
          differ += a.p != b.p || a.v != b.v || a.a != b.a || a.j != b.j;
          if (n >= 0) differ += st.step().p != st_ref.step().p;
        }
        EXPECT_EQ(differ, 0);
      }
      ++checked;
    }
  });
  EXPECT_GE(checked, core::kProfileCount + 2);  // every kind unshaped, and some shaped or cruising
}

// Move::at is the shape's own evaluator behind a dispatch that changes nothing: for every profile,
// unshaped and ZVD-shaped, in double and float, at seeded random times (before the start, inside,
// past the end), it equals bitwise the shape's at() (unshaped: of t; shaped: the impulse sum
// written out here, in the same order), and past the end the target exactly. The stepper equals
// Move::at at its own ticks bitwise where it steps by random access (every shape but the
// ramp-cycloid's, whose phasor stepping differs from sin/cos by rounding).
template <typename T>
void expect_dispatch_is_the_shape(const core::Move<double>& md, auto kind) {
  using P = core::profile_t<decltype(kind)::value>;
  using Shape = typename P::template Shape<T>;
  const core::Move<T> m{md};
  const Shape& shape = *std::get_if<Shape>(&m.profile().variant());
  const auto& sh = m.shaper();
  std::mt19937_64 rng{36};
  std::uniform_real_distribution<double> u{-0.1, 1.2};
  int differ = 0;
  for (int i = 0; i < 2000; ++i) {
    const T t = static_cast<T>(u(rng) * static_cast<double>(m.duration()));
    core::Sample<T> ref{};
    if (t >= m.duration()) {
      ref = {m.distance(), T(0), T(0), T(0)};
    } else if (sh.count == 1) {
      ref = shape.at(t - sh.time[0]);
    } else {
      for (std::size_t k = 0; k < sh.count; ++k) {
        const core::Sample<T> s = shape.at(t - sh.time[k]);
        ref.p += sh.amp[k] * s.p;
        ref.v += sh.amp[k] * s.v;
        ref.a += sh.amp[k] * s.a;
        ref.j += sh.amp[k] * s.j;
      }
    }
    const core::Sample<T> got = m.at(t);
    differ += got.p != ref.p || got.v != ref.v || got.a != ref.a || got.j != ref.j;
  }
  EXPECT_EQ(differ, 0);
  if constexpr (!std::is_same_v<Shape, core::RampCycloid<T>>) {
    const T dt = T(1e-3);
    core::MoveStepper<T> st{m, dt};
    const int n_end = static_cast<int>(std::ceil(md.duration() / 1e-3)) + 2;
    int step_differ = 0;
    for (int n = 0; n <= n_end; ++n) {
      const core::Sample<T> a = st.step(), b = m.at(static_cast<T>(n) * dt);
      step_differ += a.p != b.p || a.v != b.v || a.a != b.a || a.j != b.j;
    }
    EXPECT_EQ(step_differ, 0);
  }
}

TEST(Registry, MoveAtIsTheShapesOwnEvaluationBitwise) {
  core::for_each_profile([&](auto kind) {
    for (const bool shaped : {false, true}) {
      SCOPED_TRACE(std::string{core::to_string(kind.value)} + (shaped ? " zvd" : ""));
      core::MoveRequest r = core::profile_t<kind.value>::example();
      r.profile = kind.value;
      if (shaped) r.shaper = core::ShaperKind::zvd;
      core::Move<double> md{};
      if (core::plan(r, md) != Status::ok) continue;
      expect_dispatch_is_the_shape<double>(md, kind);
      expect_dispatch_is_the_shape<float>(md, kind);
    }
  });
}

// The fixed-point motion built from every example (its pieces: the shape's own decomposition, or
// the pseudo-polynomial fit) is within one count of the double move at every tick, rests exactly
// on the rounded target, and its stepper gives random access's positions.
TEST(Registry, FixedPointMatchesDoubleAtEveryTick) {
  core::for_each_profile([&](auto kind) {
    SCOPED_TRACE(core::to_string(kind.value));
    const core::Move<double> m = plan_example(kind);
    const core::fixed::Scale scale{{1e5 / std::fabs(m.distance()), 1000}, 16, 16};  // 1e5 counts, 1 ms
    core::fixed::PolyMotion fm{};
    ASSERT_EQ(fm.build(m, scale), Status::ok);
    EXPECT_EQ(fm.target(), static_cast<std::int32_t>(std::nearbyint(m.distance() * scale.axis.counts_per_unit)));
    core::fixed::MotionStepper<core::fixed::PolyMotion::kMaxTracks> stepper{fm};
    double worst = 0.0;
    std::int32_t worst_step = 0;
    for (std::int32_t n = 0; n <= fm.end_tick() + 2; ++n) {
      const core::fixed::Sample f = fm.at_tick(n);
      const double want = m.at(n * scale.axis.period_s()).p * scale.axis.counts_per_unit;
      worst = std::max(worst, std::fabs(f.p - want));
      worst_step = std::max(worst_step, std::abs(stepper.next().p - f.p));
    }
    EXPECT_LE(worst, 1.0);
    EXPECT_LE(worst_step, 1);
    EXPECT_EQ(fm.at_tick(fm.end_tick()).p, fm.target());
  });
}

// A closed-form shape's pieces (what the fixed-point builder quantises and the simulator's
// one-sided evaluation reads) are the very curve its floating-point at() evaluates: p, v, a and j
// agree to rounding inside every piece, and the pieces tile [0, duration] without gaps.
TEST(Registry, PiecesAreTheCurveTheEvaluatorComputes) {
  int closed_form = 0;
  core::for_each_profile([&](auto kind) {
    SCOPED_TRACE(core::to_string(kind.value));
    const core::Move<double> m = plan_example(kind);
    m.profile().visit([&](const auto& shape) {
      if constexpr (requires { shape.piece_count(); }) {
        ++closed_form;
        const core::Sample<double> pk{m.distance(), m.peaks().v, m.peaks().a, m.peaks().j};
        double end = 0.0;
        ASSERT_GT(shape.piece_count(), 0);
        for (int i = 0; i < shape.piece_count(); ++i) {
          const core::Piece pc = shape.piece(i);
          EXPECT_NEAR(pc.start, end, 1e-12 * shape.duration());
          end = pc.start + pc.length;
          for (int k = 1; k < 16; ++k) {
            const double t = pc.start + pc.length * k / 16.0;
            const core::Sample<double> a = shape.at(t), b = core::piece_at(pc, t);
            EXPECT_NEAR(a.p, b.p, 1e-12 * std::fabs(pk.p)) << "piece " << i << " t " << t;
            if (std::isfinite(pk.v)) {
              EXPECT_NEAR(a.v, b.v, 1e-9 * pk.v) << "piece " << i << " t " << t;
            }
            if (std::isfinite(pk.a)) {
              EXPECT_NEAR(a.a, b.a, 1e-9 * pk.a) << "piece " << i << " t " << t;
            }
            if (std::isfinite(pk.j)) {
              EXPECT_NEAR(a.j, b.j, 1e-9 * pk.j) << "piece " << i << " t " << t;
            }
          }
        }
        EXPECT_NEAR(end, shape.duration(), 1e-12 * shape.duration());
      }
    });
  });
  EXPECT_GE(closed_form, 5);  // scurve, scurve-damped, ramp-versine, trapezoid, jerk-limited at least
}
