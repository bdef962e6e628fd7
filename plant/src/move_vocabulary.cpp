// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/move_vocabulary.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <type_traits>

namespace settle::plant {

namespace {

constexpr ShaperName kShapers[] = {{"none", core::ShaperKind::none},
                                   {"zv", core::ShaperKind::zv},
                                   {"zvd", core::ShaperKind::zvd},
                                   {"zvdd", core::ShaperKind::zvdd},
                                   {"ei", core::ShaperKind::ei},
                                   {"ei2", core::ShaperKind::ei2},
                                   {"ei3", core::ShaperKind::ei3}};

template <typename Range, typename Name>
std::string join(const Range& items, Name&& name) {
  std::string out;
  for (const auto& item : items) {
    if (!out.empty()) out += ", ";
    out += name(item);
  }
  return out;
}

}  // namespace

std::string profile_list() {
  return join(core::profile_names(), [](const char* n) { return n; });
}

std::span<const ShaperName> shaper_names() { return kShapers; }

std::string shaper_list() {
  return join(shaper_names(), [](const ShaperName& s) { return s.name; });
}

std::string Range::text() const {
  char lo_s[32], hi_s[32];
  std::snprintf(lo_s, sizeof lo_s, "%g", lo);
  std::snprintf(hi_s, sizeof hi_s, "%g", hi);
  return std::string{lo_open ? "(" : "["} + lo_s + ", " + hi_s + (hi_open ? ")" : "]");
}

bool parse_shaper(const std::string& name, core::ShaperKind& out) {
  for (const ShaperName& s : kShapers) {
    if (name == s.name) {
      out = s.kind;
      return true;
    }
  }
  return false;
}

std::vector<std::pair<std::string, double>> profile_params(const core::Profile<double>& prof) {
  std::vector<std::pair<std::string, double>> out;
  prof.visit([&](const auto& shape) {
    shape.for_each_param([&](const char* name, std::size_t index, double value) {
      std::string n = name;
      if (const auto hash = n.find('#'); hash != std::string::npos) n.replace(hash, 1, std::to_string(index));
      out.emplace_back(std::move(n), value);
    });
  });
  return out;
}

std::string profile_family(const core::Profile<double>& prof) {
  std::string out;
  prof.visit([&](const auto& shape) {
    if constexpr (requires { to_string(shape.family()); }) out = to_string(shape.family());
  });
  return out;
}

std::optional<core::FastestCertificate> shortest_proof(const core::Move<double>& m, const core::MoveRequest& r) {
  if (r.profile != core::ProfileKind::fastest || !m.shaper().is_identity()) return std::nullopt;
  core::FastestCertificate c{};  // a ramp-cycloid move: not a chain of ramps and holds
  m.profile().visit([&](const auto& shape) {
    if constexpr (std::is_same_v<std::decay_t<decltype(shape)>, core::Fastest<double>>) {
      if (const auto* t = shape.table()) c = core::certify_fastest(t->params(), r);
    }
  });
  return c;
}

std::string profiles_using(core::Param p) {
  std::string out;
  core::for_each_profile([&](auto kind) {
    if (core::profile_params(kind.value).contains(p)) out += (out.empty() ? "" : ", ") + std::string{core::to_string(kind.value)};
  });
  return out;
}

std::string users_text(const std::string& profiles, const std::string& shapers) {
  const auto named = [](const char* what, const std::string& list) {
    if (list.empty()) return std::string{};
    return std::string{what} + (list.find(',') != std::string::npos ? "s " : " ") + list;
  };
  return named("profile", profiles) + (profiles.empty() || shapers.empty() ? "" : "; ") + named("shaper", shapers);
}

std::string shapers_using(core::Param p) {
  std::string out;
  for (const ShaperName& s : kShapers) {
    if (core::shaper_params(s.kind).contains(p)) out += (out.empty() ? "" : ", ") + std::string{s.name};
  }
  return out;
}

bool check_params_used(const core::MoveRequest& r, core::ParamSet given, core::ParamSet also_used, bool omega_fallback,
                       core::Param& unused, std::string& message) {
  const core::ParamSet used = core::used_params(r) | also_used;
  for (std::size_t i = 0; i < core::kParamCount; ++i) {
    const auto p = static_cast<core::Param>(i);
    if (!given.contains(p) || used.contains(p)) continue;
    unused = p;
    message = std::string{"not used by profile "} + core::to_string(r.profile);
    const core::ParamOverride o = core::profile_overrides(r.profile);
    if (given.contains(o.given) && o.unused.contains(p)) message += std::string{" with "} + core::to_string(o.given) + " given";
    if (r.shaper != core::ShaperKind::none) message += std::string{" and shaper "} + core::to_string(r.shaper);
    const std::string profiles = profiles_using(p), shapers = shapers_using(p);
    message += " (used by " + users_text(profiles, shapers) + ")";
    return false;
  }
  if (given.contains(core::Param::zeta) && !given.contains(core::Param::omega) && !omega_fallback) {
    unused = core::Param::zeta;
    message = "given without omega, it would be dropped: it is the damping ratio of the mode omega gives; give omega "
              "too (rad/s)";
    return false;
  }
  return true;
}

bool set_design_modes(const std::vector<double>& omegas, const std::vector<double>& zetas, core::MoveRequest& r,
                      const char*& option, std::string& message) {
  if (omegas.size() > 1 && !core::profile_params(r.profile).contains(core::Param::modes)) {
    option = "--omega";
    message = "given more than once: only profile " + profiles_using(core::Param::modes) +
              " designs for several modes (profile " + core::to_string(r.profile) + " for one)";
    return false;
  }
  if (omegas.size() > core::kMaxModes) {
    option = "--omega";
    message = "at most " + std::to_string(core::kMaxModes) + " modes";
    return false;
  }
  if (zetas.size() > 1 && zetas.size() != omegas.size()) {
    option = "--zeta";
    message = "one per omega, in the same order (or one for a single mode)";
    return false;
  }
  // A zeta without an omega designs for nothing: the caller may pair it with a default omega.
  r.mode_count = 0;
  for (std::size_t i = 0; i < omegas.size(); ++i) (void)r.add_mode({omegas[i], i < zetas.size() ? zetas[i] : 0.0});
  return true;
}

const char* option_of(core::Status s, const core::MoveRequest& r) {
  using core::Status;
  switch (s) {
    case Status::missing_time_or_limits:
      // A move time was given: the profile needs limits; name the first one missing.
      if (r.time) return !r.limits.vmax ? "--vmax" : !r.limits.amax ? "--amax" : "--jmax";
      return "--time";
    case Status::non_positive_time:
    case Status::time_too_short_for_vmax: return "--time";
    case Status::non_positive_limit:
      if (r.limits.vmax && !(*r.limits.vmax > 0.0)) return "--vmax";
      if (r.limits.amax && !(*r.limits.amax > 0.0)) return "--amax";
      return "--jmax";
    case Status::velocity_limit_exceeded: return "--vmax";
    case Status::acceleration_limit_exceeded: return "--amax";
    case Status::jerk_limit_exceeded: return "--jmax";
    case Status::non_positive_omega: return "--omega";
    case Status::zeta_out_of_range: return "--zeta";
    case Status::too_few_gammas:
    case Status::too_many_gammas:
    case Status::gamma_too_small:
    case Status::gammas_not_distinct:
    case Status::singular_system: return "--gammas";
    case Status::bad_shape_parameter: return r.robust ? "--robust" : "--y";
    case Status::vtol_out_of_range: return "--vtol";
    case Status::bad_impulse:
    case Status::shaper_gain_not_unity:
    case Status::too_many_impulses: return "--shaper";
    case Status::no_solution:
      // Without a shaper, what did not converge is the profile's own design for the mode or
      // the limits: name what the user gave for it.
      if (r.shaper != core::ShaperKind::none) return "--shaper";
      if (r.robust) return "--robust";
      if (r.profile == core::ProfileKind::fastest) return "--omega";  // no move for these modes
      if (r.time) return "--time";
      if (r.limits.vmax) return "--vmax";
      return "--profile";
    case Status::non_finite_input: {
      const std::pair<const char*, std::optional<double>> opts[] = {
          {"--distance", r.distance}, {"--time", r.time}, {"--vmax", r.limits.vmax}, {"--amax", r.limits.amax},
          {"--jmax", r.limits.jmax},         {"--omega", r.omega()}, {"--zeta", r.zeta()}, {"--vtol", r.vtol}};
      for (const auto& [name, v] : opts) {
        if (v && !std::isfinite(*v)) return name;
      }
      if (r.y_fractions) return "--y";
      if (r.gamma_count > 0) return "--gammas";
      return "--distance";
    }
    default: return "--profile";
  }
}

std::string reason_of(core::Status s, const core::MoveRequest& r) {
  if (s == core::Status::no_solution && r.profile == core::ProfileKind::fastest && !r.robust &&
      r.shaper == core::ShaperKind::none) {
    const std::size_t modes = r.mode_count;
    std::string why = "no family found a move that leaves ";
    why += modes == 1 ? "the mode" : "all " + std::to_string(modes) + " modes";
    why += " at rest within the limits";
    if (modes >= 3) {
      // ZV for each of three modes is 8 impulses: 8 copies of the time-optimal move's 7 segments;
      // the joint ZV shaper's n + 1 copies fit for three modes, where it exists.
      why += " (time-optimal * ZV for every mode needs more than the " + std::to_string(core::kFastestSegments) +
             " segments a fastest move holds, the joint ZV shaper for these modes has no design with positive "
             "impulses that fits them, and the bang-bang and bang-coast searches found none: fewer modes may plan)";
    }
    return why;
  }
  if (s == core::Status::no_solution && r.profile == core::ProfileKind::fastest && r.robust &&
      r.shaper == core::ShaperKind::none) {
    char pct[32];
    std::snprintf(pct, sizeof pct, "%g", *r.robust);
    return std::string("no family found a move within the limits that keeps every mode's residual within 5 % over +-") +
           pct + " % of its frequency (the shaped moves with the widest bands, time-optimal * two- or three-hump EI, " +
           "need more than the " + std::to_string(core::kFastestSegments) +
           " segments a fastest move holds or have no design for this damping, and the bang-coast search found "
           "none): a smaller --robust may plan, and --profile jerk-limited --shaper ei2 or ei3 (about +-36 % or "
           "+-48 % of an undamped mode) shapes the time-optimal move without that limit";
  }
  if (s == core::Status::non_positive_omega && !r.has_mode()) {
    return std::string{"required: --profile "} + core::to_string(r.profile) +
           (r.shaper != core::ShaperKind::none ? " with a shaper" : "") + " designs the move for a mode (rad/s)";
  }
  if (s == core::Status::missing_time_or_limits && r.time) {
    std::string missing;
    for (const auto& [name, given] : {std::pair{"--vmax", r.limits.vmax.has_value()}, std::pair{"--amax", r.limits.amax.has_value()},
                                      std::pair{"--jmax", r.limits.jmax.has_value()}}) {
      if (!given) missing += (missing.empty() ? "" : ", ") + std::string{name};
    }
    return std::string{"--profile "} + core::to_string(r.profile) + " needs its limits; a move time alone does not " +
           "define it: give " + missing + " (with --time: the move of that duration within them)";
  }
  return core::describe(s);
}

}  // namespace settle::plant
