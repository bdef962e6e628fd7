#include "move_options.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "commands.hpp"
#include "json.hpp"

namespace settle::cli {

const std::set<std::string> kMoveValueOptions = {"--profile", "--distance", "--time", "--vmax",  "--amax", "--jmax",
                                                 "--omega",   "--zeta",     "--gammas", "--y", "--shaper", "--vtol"};
const std::set<std::string> kMoveFlagOptions = {"--json"};

Args::Args(int argc, char** argv, const std::set<std::string>& value_options,
           const std::set<std::string>& flag_options) {
  // Keep scanning after the first error so that a --json anywhere still selects the error format.
  auto fail = [this](const std::string& msg, const std::string& param) {
    if (!error_.empty()) return;
    error_ = msg;
    error_param_ = param;
  };
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    if (value_options.count(a) != 0) {
      if (i + 1 >= argc) {
        fail("option " + a + " needs a value", a);
        break;
      }
      values_.emplace(a, argv[++i]);
    } else if (flag_options.count(a) != 0) {
      flags_.insert(a);
    } else {
      fail("unknown option '" + a + "'", a);
    }
  }
}

std::optional<std::string> Args::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

std::vector<std::string> Args::all(const std::string& name) const {
  std::vector<std::string> out;
  auto [lo, hi] = values_.equal_range(name);
  for (auto it = lo; it != hi; ++it) out.push_back(it->second);
  return out;
}

bool parse_double(const std::string& s, double& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0') return false;
  out = v;
  return true;
}

bool parse_list(const std::string& s, std::vector<double>& out) {
  std::vector<double> v;
  std::stringstream ss{s};
  std::string item;
  while (std::getline(ss, item, ',')) {
    double x = 0.0;
    if (!parse_double(item, x)) return false;
    v.push_back(x);
  }
  if (v.empty()) return false;
  out = std::move(v);
  return true;
}

bool read_number(const Args& a, const char* name, double& out, RequestError& err) {
  const auto s = a.get(name);
  if (!s) return true;
  if (!parse_double(*s, out)) {
    err = {"bad_number", name, std::string{name} + ": '" + *s + "' is not a number"};
    return false;
  }
  return true;
}

namespace {

// The same for options whose absence the planner must see (no default).
bool number_option(const Args& a, const char* name, std::optional<double>& out, RequestError& err) {
  if (!a.get(name)) return true;
  double v = 0.0;
  if (!read_number(a, name, v, err)) return false;
  out = v;
  return true;
}

struct ShaperName {
  const char* name;
  core::ShaperKind kind;
};
constexpr ShaperName kShapers[] = {{"none", core::ShaperKind::none},
                                   {"zv", core::ShaperKind::zv},
                                   {"zvd", core::ShaperKind::zvd},
                                   {"zvdd", core::ShaperKind::zvdd},
                                   {"ei", core::ShaperKind::ei}};

// The option a planner status is about, so the user is told what to change.
const char* param_of(core::Status s, const core::MoveRequest& r) {
  using core::Status;
  switch (s) {
    case Status::non_positive_time:
    case Status::time_too_short_for_vmax:
    case Status::missing_time_or_limits: return "--time";
    case Status::non_positive_limit:
      if (r.vmax && !(*r.vmax > 0.0)) return "--vmax";
      if (r.amax && !(*r.amax > 0.0)) return "--amax";
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
    case Status::bad_shape_parameter: return "--y";
    case Status::vtol_out_of_range: return "--vtol";
    case Status::bad_impulse:
    case Status::shaper_gain_not_unity:
    case Status::too_many_impulses:
    case Status::no_solution: return "--shaper";
    case Status::non_finite_input: {
      const std::pair<const char*, std::optional<double>> opts[] = {
          {"--distance", r.distance}, {"--time", r.time}, {"--vmax", r.vmax}, {"--amax", r.amax},
          {"--jmax", r.jmax},         {"--omega", r.omega}, {"--zeta", r.zeta}, {"--vtol", r.vtol}};
      for (const auto& [name, v] : opts) {
        if (v && !std::isfinite(*v)) return name;
      }
      if (r.y_fractions) return "--y";
      return "--gammas";
    }
    default: return "--profile";
  }
}

}  // namespace

bool parse_move_request(const Args& a, core::MoveRequest& req, RequestError& err) {
  core::MoveRequest r{};
  const auto prof = a.get("--profile");
  if (!prof) {
    err = {"missing_option", "--profile", "--profile is required (scurve, scurve-damped, ramp-versine, pseudopoly, "
                                          "poly345, trapezoid, jerk-limited)"};
    return false;
  }
  if (!core::parse_profile_kind(prof->c_str(), r.profile)) {
    err = {"unknown_profile", "--profile", "--profile: unknown profile '" + *prof + "'"};
    return false;
  }
  std::optional<double> distance, zeta, vtol;
  if (!number_option(a, "--distance", distance, err) || !number_option(a, "--time", r.time, err) ||
      !number_option(a, "--vmax", r.vmax, err) || !number_option(a, "--amax", r.amax, err) ||
      !number_option(a, "--jmax", r.jmax, err) || !number_option(a, "--omega", r.omega, err) ||
      !number_option(a, "--zeta", zeta, err) || !number_option(a, "--vtol", vtol, err)) {
    return false;
  }
  if (!distance) {
    err = {"missing_option", "--distance", "--distance is required"};
    return false;
  }
  r.distance = *distance;
  r.zeta = zeta.value_or(0.0);
  r.vtol = vtol.value_or(0.05);
  if (const auto g = a.get("--gammas")) {
    std::vector<double> v;
    if (!parse_list(*g, v)) {
      err = {"bad_number", "--gammas", "--gammas: expected a comma-separated list of numbers"};
      return false;
    }
    if (v.size() > core::kMaxGammas) {
      err = {core::to_string(core::Status::too_many_gammas), "--gammas",
             "--gammas: at most " + std::to_string(core::kMaxGammas) + " exponents"};
      return false;
    }
    r.gamma_count = v.size();
    for (std::size_t i = 0; i < v.size(); ++i) r.gammas[i] = v[i];
  } else if (r.profile == core::ProfileKind::pseudopoly) {
    err = {"missing_option", "--gammas", "--gammas is required for the pseudopoly profile"};
    return false;
  }
  if (const auto y = a.get("--y")) {
    std::vector<double> v;
    if (!parse_list(*y, v) || v.size() != 3) {
      err = {"bad_number", "--y", "--y: expected three fractions Y1/L,Y2/L,Y3/L"};
      return false;
    }
    r.y_fractions = std::array<double, 3>{v[0], v[1], v[2]};
  }
  if (const auto s = a.get("--shaper")) {
    bool found = false;
    for (const ShaperName& n : kShapers) {
      if (*s == n.name) {
        r.shaper = n.kind;
        found = true;
      }
    }
    if (!found) {
      err = {"unknown_shaper", "--shaper", "--shaper: unknown shaper '" + *s + "' (zv, zvd, zvdd, ei, none)"};
      return false;
    }
  }
  req = r;
  return true;
}

bool plan_move(const core::MoveRequest& req, core::Move<double>& out, RequestError& err) {
  const core::Status st = core::plan(req, out);
  if (st == core::Status::ok) return true;
  const char* p = param_of(st, req);
  err = {core::to_string(st), p, std::string{p} + ": " + core::describe(st)};
  return false;
}

int report_bad_request(const RequestError& err, bool json) {
  if (json) {
    JsonWriter w{stdout};
    w.begin_object()
        .field("status", "error")
        .field("error", err.code)
        .field("parameter", err.param)
        .field("message", err.message)
        .end_object()
        .finish();
  } else {
    std::fprintf(stderr, "settle: error: %s [%s]\n", err.message.c_str(), err.code.c_str());
  }
  return kExitBadRequest;
}

}  // namespace settle::cli
