// SPDX-License-Identifier: Apache-2.0
#pragma once
// Profile `fastest`: a short rest-to-rest move under vmax, amax and jmax that leaves every
// design mode (omega, zeta and the request's extra modes) exactly at rest, or, with `robust`,
// keeps their residual within 5 % of a step's over omega (1 +- robust/100). It plans several
// families and keeps the shortest feasible one; each family is a local search from seeds, so the
// result is not a proven time optimum (docs/fastest.md measures how far from one it lands):
//   bang_bang   jerk +-J except on limit arcs (Pontryagin's structure), Newton on the switch
//               times of a chain of limit / peak / cruise / dwell nodes (exact designs)
//   bang_coast  jerk in {+J, 0, -J}, switch times solved under the zero-residual conditions
//               (only where bang_bang does not win)
//   scurve / scurve_damped   the ramp-cycloid S-curves (single mode)
//   shaped_zv / _zvd / _zvdd / _ei   the time-optimal jerk-limited move convolved with shapers
//   shaped_spread   (--robust) convolved with ZV shapers at frequencies spread over the band
//   shaped_joint_zv   (two or more modes) convolved with one ZV shaper designed for all modes
//               at once: n + 1 impulses, where one ZV per mode takes 2^n (three modes fit)
// Every family but the S-curves is a piecewise-constant-jerk move (the shaped ones flattened:
// the sum of delayed copies is again piecewise constant in jerk), so the shape holds either a
// RampCycloid or a PiecewiseJerk table.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <variant>

#include "settle/core/kinematics.hpp"
#include "settle/core/move_request.hpp"
#include "settle/core/piece.hpp"
#include "settle/core/piecewise_jerk.hpp"
#include "settle/core/ramp_cycloid.hpp"
#include "settle/core/status.hpp"

namespace settle::core {

// Room for the bang-bang chains of up to 23 nodes (2 n + 1 segments; docs/fastest.md, "Dwells
// changed in chains of up to 23 nodes"; 31 before) and for the flattened time-optimal move
// convolved with up to five impulses (8 breakpoints each), and within the fixed-point
// PolyMotion's 48 segments (core/fixed/motion.hpp).
inline constexpr std::size_t kFastestSegments = 47;

enum class FastestFamily : std::uint8_t {
  none,
  bang_coast,
  scurve,
  scurve_damped,
  shaped_zv,
  shaped_zvd,
  shaped_zvdd,
  shaped_ei,
  shaped_spread,  // ZV at omega (1 +- spread) for --robust, composed
  bang_bang,      // jerk +-J except on limit arcs, Newton on the switch times (exact designs)
  shaped_joint_zv,  // one ZV designed for all modes at once: n + 1 impulses (shaper.hpp)
  shaped_ei2,       // two-hump EI per mode (--robust only)
  shaped_ei3,       // three-hump EI per mode (--robust only)
};
inline constexpr std::size_t kFastestFamilies = 13;
[[nodiscard]] constexpr const char* to_string(FastestFamily f) noexcept {
  constexpr const char* names[kFastestFamilies] = {"none",          "bang-coast", "scurve",         "scurve-damped",
                                                   "time-optimal*ZV", "time-optimal*ZVD", "time-optimal*ZVDD",
                                                   "time-optimal*EI", "time-optimal*spread-ZV", "bang-bang",
                                                   "time-optimal*joint-ZV", "time-optimal*EI2", "time-optimal*EI3"};
  const auto i = static_cast<std::size_t>(f);
  return i < kFastestFamilies ? names[i] : "unknown";
}

// The planner's output: the family that won, its move (a ramp-cycloid, or a constant-jerk table
// with each segment's starting acceleration), and what every family reached.
using FastestTable = PiecewiseJerkTable<kFastestSegments>;
struct FastestParams {
  FastestFamily family{FastestFamily::none};
  RampCycloidParams curve{};  // family scurve / scurve_damped
  FastestTable table{};       // otherwise: constant-jerk segments (table.distance is the move's)
  // The duration each family reached for this request (0: infeasible or not tried), reported by
  // `settle plan` so that the choice can be checked.
  std::array<double, kFastestFamilies> family_time{};
};

[[nodiscard]] constexpr bool is_ramp_cycloid(FastestFamily f) noexcept {
  return f == FastestFamily::scurve || f == FastestFamily::scurve_damped;
}

// The evaluated move: a ramp-cycloid or a PiecewiseJerk table, whichever the family is (one of
// them, not both: the shape is as large as the larger), and the family times it reports.
template <typename T>
class Fastest {
 public:
  using Params = FastestParams;
  using Table = PiecewiseJerk<T, kFastestSegments>;
  Fastest() = default;
  explicit Fastest(const FastestParams& p) noexcept : family_{p.family}, family_time_{p.family_time} {
    if (is_ramp_cycloid(p.family)) {
      shape_.template emplace<RampCycloid<T>>(p.curve);
    } else {
      shape_.template emplace<Table>(p.table);
    }
  }
  template <typename U>
  explicit Fastest(const Fastest<U>& o) noexcept : family_{o.family_}, family_time_{o.family_time_} {
    if (const auto* c = std::get_if<RampCycloid<U>>(&o.shape_)) {
      shape_.template emplace<RampCycloid<T>>(*c);
    } else if (const auto* t = std::get_if<typename Fastest<U>::Table>(&o.shape_)) {
      shape_.template emplace<Table>(*t);
    }
  }

  // The planner's parameters, reassembled (the shape keeps only its own).
  [[nodiscard]] FastestParams params() const noexcept {
    FastestParams p{};
    p.family = family_;
    p.family_time = family_time_;
    if (const auto* c = curve()) p.curve = c->params();
    if (const auto* t = table()) p.table = t->params();
    return p;
  }
  [[nodiscard]] T duration() const noexcept {
    return visit([](const auto& s) { return s.duration(); });
  }
  [[nodiscard]] T distance() const noexcept {
    return visit([](const auto& s) { return s.distance(); });
  }
  [[nodiscard]] FastestFamily family() const noexcept { return family_; }
  [[nodiscard]] const RampCycloid<T>* curve() const noexcept { return std::get_if<RampCycloid<T>>(&shape_); }
  [[nodiscard]] const Table* table() const noexcept { return std::get_if<Table>(&shape_); }

  template <typename F>
  void for_each_param(F&& f) const {
    f("family_code", 0, static_cast<double>(family_));
    for (std::size_t k = 1; k < kFastestFamilies; ++k) {
      if (family_time_[k] > 0.0) f(family_param_name(k), 0, family_time_[k]);
    }
    visit([&](const auto& s) { s.for_each_param(f); });
  }

  [[nodiscard]] int piece_count() const noexcept {
    return visit([](const auto& s) { return s.piece_count(); });
  }
  [[nodiscard]] Piece piece(int i) const noexcept {
    return visit([i](const auto& s) { return s.piece(i); });
  }
  [[nodiscard]] Sample<T> at(T t) const noexcept {
    return visit([t](const auto& s) { return s.at(t); });
  }

 private:
  template <typename U>
  friend class Fastest;
  // f(the table or the curve). Not std::visit: it may throw bad_variant_access, and core is
  // built without exceptions (as Profile::visit).
  template <typename F>
  decltype(auto) visit(F&& f) const noexcept {
    if (const auto* t = table()) return f(*t);
    return f(*std::get_if<RampCycloid<T>>(&shape_));
  }
  [[nodiscard]] static const char* family_param_name(std::size_t k) noexcept {
    constexpr const char* names[kFastestFamilies] = {"",         "time_bang_coast", "time_scurve", "time_scurve_damped",
                                                     "time_zv",  "time_zvd",        "time_zvdd",   "time_ei",
                                                     "time_spread_zv", "time_bang_bang", "time_joint_zv", "time_ei2",
                                                     "time_ei3"};
    return names[k];
  }

  FastestFamily family_{FastestFamily::none};
  std::array<double, kFastestFamilies> family_time_{};
  std::variant<RampCycloid<T>, Table> shape_{};
};

// The planner (core/src/fastest.cpp): every family, the shortest feasible one that never runs
// backwards (v keeps the sign of the distance). -D plans as the move of D mirrored, to the bit.
[[nodiscard]] Status plan_fastest(const MoveRequest& r, FastestParams& out, Peaks<double>& pk) noexcept;

// Whether a move of piecewise-constant jerk is the shortest of its problem (distance, limits and
// modes of `r`; D > 0), proven by linear-programming duality (docs/fastest.md, "A certificate of the
// shortest move"): a dual whose switching function has the jerk's sign on every ramp and vanishes on
// every hold, with nonnegative measures where a limit binds. `at` is where the first condition
// fails (s), `gap` the dual's value over D minus 1 (a check of the derivation: near 0 where the
// conditions hold). No heap; the dual's system is at most kFastestSegments rows.
enum class FastestProof : std::uint8_t {
  proven,
  not_the_problems,  // not at rest at D, beyond a limit, or a mode rings at the end
  not_a_chain,       // a jerk other than +-jmax, or a hold neither at a limit nor at rest
  no_dual,           // no dual fits the turns and holds (to 1e-7)
  against_the_jerk,  // the switching function against the jerk on a ramp
  negative_measure,  // a limit's measure negative somewhere it binds
  robust,            // a --robust request: its band is another problem (the proof is for exact rest)
};
struct FastestCertificate {
  FastestProof proof{FastestProof::not_a_chain};
  double at{0.0};
  double gap{0.0};
};
[[nodiscard]] FastestCertificate certify_fastest(const FastestTable& t, const MoveRequest& r) noexcept;
[[nodiscard]] const char* to_string(FastestProof p) noexcept;
// Whether a proof that fails says where (`at`): the sign tests. `gap` is reported with those and
// with a proof.
[[nodiscard]] constexpr bool located(FastestProof p) noexcept {
  return p == FastestProof::against_the_jerk || p == FastestProof::negative_measure;
}

// Exact peaks of a piecewise-constant-jerk table (jerk and acceleration at breakpoints, velocity
// also where the acceleration crosses zero inside a segment).
[[nodiscard]] Peaks<double> jerk_table_peaks(const FastestTable& p) noexcept;

// The residual a table leaves on a mode: residual_amplitude / residual_ratio (residual.hpp).

struct FastestProfile {
  static constexpr const char* name = "fastest";
  static constexpr const char* summary =
      "short move under vmax/amax/jmax leaving every given mode at rest (the shortest of several searched "
      "families; each plan says whether it is proven the shortest)";
  template <typename T>
  using Shape = Fastest<T>;
  // No time: it chooses the shortest itself.
  static constexpr ParamSet params{Param::vmax,  Param::amax,  Param::jmax,  Param::omega,
                                   Param::zeta, Param::modes, Param::robust};
  [[nodiscard]] static Status plan(const MoveRequest& r, FastestParams& out, Peaks<double>& pk) noexcept {
    return plan_fastest(r, out, pk);
  }
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = 0.1;
    r.limits.vmax = 1.0;
    r.limits.amax = 20.0;
    r.limits.jmax = 800.0;
    r.set_mode(22.0);
    return r;
  }
};

}  // namespace settle::core
