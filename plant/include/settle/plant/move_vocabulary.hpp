#pragma once
// The words a move is asked for and reported in, shared by the settle CLI (as --options) and the
// Python module (as keywords, the options without their dashes): the profiles' names (core's
// registry), the shapers a request may name, each profile's parameters as named numbers, and the
// option a planner refusal is about.
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "settle/core/planner.hpp"

namespace settle::plant {

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

// The modes a move is designed for, as --omega and --zeta give them (repeated, in order): the
// first is the request's own mode, the rest its extra modes. Several only for profile `fastest`
// (and at most 1 + core::kMaxExtraModes); one zeta per omega, or a single zeta (or none) for a
// single mode. False with the option to blame ("--omega" or "--zeta") and what is wrong (without
// the option's name) otherwise; r is then unchanged.
[[nodiscard]] bool set_design_modes(const std::vector<double>& omegas, const std::vector<double>& zetas,
                                    core::MoveRequest& r, const char*& option, std::string& message);

// The option a planner status is about ("--time", "--vmax", ...), so that the user is told what
// to change.
[[nodiscard]] const char* option_of(core::Status s, const core::MoveRequest& r);
// What went wrong, in one sentence: core::describe(s), or what is known of this request beyond
// it (profile `fastest` with no move found for its modes).
[[nodiscard]] std::string reason_of(core::Status s, const core::MoveRequest& r);

}  // namespace settle::plant
