// SPDX-License-Identifier: Apache-2.0
#pragma once
// The words a move is asked for and reported in, shared by the settle CLI (as --options) and the
// Python module (as keywords, the options without their dashes): the profiles' names (core's
// registry), the shapers a request may name, each profile's parameters as named numbers, and the
// option a planner refusal is about.
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "settle/core/planner.hpp"

namespace settle::plant {

// A closed or open interval of valid values.
struct Range {
  double lo;
  double hi;
  bool lo_open{false};
  bool hi_open{false};

  [[nodiscard]] constexpr bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  [[nodiscard]] std::string text() const;  // "(0, 3600]"
};

// The longest move, move + tail or move + settle time a request may ask for (s).
inline constexpr double kMaxMoveSeconds = 3600.0;

// The valid values of each number a move is asked for: the CLI's option table (--distance, ...) and
// the Python module's keywords (distance=, ...) both take them from here, so the two refuse the
// same requests. Units: m or rad, s, and their derivatives; omega rad/s; robust %.
namespace move_range {
inline constexpr Range distance{-1e6, 1e6};
inline constexpr Range time{1e-6, kMaxMoveSeconds};
inline constexpr Range vmax{0.0, 1e9, true};
inline constexpr Range amax{0.0, 1e12, true};
inline constexpr Range jmax{0.0, 1e15, true};
inline constexpr Range omega{1e-3, 1e6};
inline constexpr Range zeta{0.0, 1.0, false, true};
inline constexpr Range robust{0.0, 50.0, true, false};
inline constexpr Range gamma{2.0, 100.0, true, false};  // each pseudopoly exponent
inline constexpr Range y{-100.0, 100.0};                // each ramp-versine fraction
inline constexpr Range vtol{0.0, 0.5, true, true};
}  // namespace move_range

// Samples one `sample` request may produce (settle sample, settle.sample): move duration / dt + 1.
inline constexpr double kMaxSampleCount = 2e6;

// "scurve, scurve-damped, ...": every registered profile, in registry order.
[[nodiscard]] std::string profile_list();

struct ShaperName {
  const char* name;
  core::ShaperKind kind;
};
// The shapers a request may name (none, zv, zvd, zvdd, ei).
[[nodiscard]] std::span<const ShaperName> shaper_names();
[[nodiscard]] std::string shaper_list();  // "none, zv, zvd, zvdd, ei"
// False for a name shaper_names() does not hold (and `out` untouched).
[[nodiscard]] bool parse_shaper(const std::string& name, core::ShaperKind& out);

// The numbers that define the planned profile, named as `settle plan --json` names them.
[[nodiscard]] std::vector<std::pair<std::string, double>> profile_params(const core::Profile<double>& prof);
// The family that won, for a profile that plans several (`fastest`); "" for the others.
[[nodiscard]] std::string profile_family(const core::Profile<double>& prof);
// Whether a `fastest` move is proven the shortest of its request's problem (core::certify_fastest;
// a ramp-cycloid move is not a chain the proof reads); nullopt for another profile or a shaped move.
[[nodiscard]] std::optional<core::FastestCertificate> shortest_proof(const core::Move<double>& m,
                                                                     const core::MoveRequest& r);

// The modes a move is designed for, as --omega and --zeta give them (repeated, in order): they
// replace the request's modes (none when no omega is given). Several only for profile `fastest`
// (and at most core::kMaxModes); one zeta per omega, or a single zeta (or none) for a single mode. False with the option to blame ("--omega" or "--zeta") and what is wrong (without
// the option's name) otherwise; r is then unchanged.
[[nodiscard]] bool set_design_modes(const std::vector<double>& omegas, const std::vector<double>& zetas,
                                    core::MoveRequest& r, const char*& option, std::string& message);

// The profiles, and the shapers, that use parameter p (core's registry: each profile's `params`,
// core::shaper_params): "scurve-damped, ramp-versine, fastest", "" when none.
[[nodiscard]] std::string profiles_using(core::Param p);
[[nodiscard]] std::string shapers_using(core::Param p);
// "profiles A, B; shaper S" from the two lists (either may be empty).
[[nodiscard]] std::string users_text(const std::string& profiles, const std::string& shapers);

// Refuses a parameter the caller was given (`given`) that the move planned from `r` would ignore:
// one its profile and shaper do not use (core::used_params) and the caller does not use itself
// (`also_used`: a change of the move mid-way keeps its mode at rest, say). Also a zeta given without
// an omega when `omega_fallback` is false (no default mode to pair it with). False, with the
// parameter and what is wrong (without the parameter's name: "not used by profile scurve (used
// by ...)"), at the first such parameter in core::Param order.
[[nodiscard]] bool check_params_used(const core::MoveRequest& r, core::ParamSet given, core::ParamSet also_used,
                                     bool omega_fallback, core::Param& unused, std::string& message);

// The option a planner status is about ("--time", "--vmax", ...), so that the user is told what
// to change.
[[nodiscard]] const char* option_of(core::Status s, const core::MoveRequest& r);
// What went wrong, in one sentence: core::describe(s), or what is known of this request beyond
// it (profile `fastest` with no move found for its modes).
[[nodiscard]] std::string reason_of(core::Status s, const core::MoveRequest& r);

}  // namespace settle::plant
