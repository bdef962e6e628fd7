// SPDX-License-Identifier: Apache-2.0
#include "io/modes_json.hpp"

#include <algorithm>
#include <cmath>

#include "io/plan_json.hpp"

namespace settle::app {

Json modes_json(const std::vector<commission::UncertainMode>& modes) {
  Json out = Json::array();
  for (const commission::UncertainMode& m : modes) {
    out.push_back({{"omega", m.omega},
                   {"zeta", m.zeta},
                   {"gain", m.gain},
                   {"omega_ci", {m.omega_lo, m.omega_hi}},
                   {"zeta_ci", {m.zeta_lo, m.zeta_hi}},
                   {"gain_sd", m.gain_sd}});
  }
  return out;
}

bool mode_from_json(const Json& m, bool with_intervals, commission::UncertainMode& out, std::string& why) {
  if (!m.is_object()) {
    why = " is not an object";
    return false;
  }
  auto num = [&](const char* key, double& v) {
    if (!m.contains(key) || !m[key].is_number()) return false;
    v = m[key].get<double>();
    return std::isfinite(v);
  };
  commission::UncertainMode u{};
  if (!num("omega", u.omega) || !(u.omega >= 1e-2 && u.omega <= 1e6)) {
    why = ".omega: a number in [0.01, 1e6] rad/s is required";
    return false;
  }
  if (!num("zeta", u.zeta) || !(u.zeta >= 0.0 && u.zeta < 1.0)) {
    why = ".zeta: a number in [0, 1) is required";
    return false;
  }
  if (m.contains("gain") && (!num("gain", u.gain) || !(std::fabs(u.gain) <= 1e6))) {
    why = ".gain: a number in [-1e6, 1e6]";
    return false;
  }
  if (with_intervals) {
    auto interval = [&](const char* key, double& lo, double& hi) {
      if (!m.contains(key) || !m[key].is_array() || m[key].size() != 2 || !m[key][0].is_number() ||
          !m[key][1].is_number()) {
        return false;
      }
      lo = m[key][0].get<double>();
      hi = m[key][1].get<double>();
      return std::isfinite(lo) && std::isfinite(hi);
    };
    if (!interval("omega_ci", u.omega_lo, u.omega_hi)) {
      why = ".omega_ci: [lo, hi] is required with --uncertainty ci (or give --uncertainty PCT)";
      return false;
    }
    if (!(u.omega_lo > 0.0 && u.omega_lo <= u.omega && u.omega <= u.omega_hi)) {
      why = ".omega_ci: must satisfy 0 < lo <= omega <= hi";
      return false;
    }
    if (!interval("zeta_ci", u.zeta_lo, u.zeta_hi)) {
      why = ".zeta_ci: [lo, hi] is required with --uncertainty ci (or give --uncertainty PCT)";
      return false;
    }
    // A symmetric interval around a small damping ratio may reach below 0: no damping is the least.
    u.zeta_lo = std::max(u.zeta_lo, 0.0);
    if (!(u.zeta_lo <= u.zeta && u.zeta <= u.zeta_hi && u.zeta_hi < 1.0)) {
      why = ".zeta_ci: must satisfy lo <= zeta <= hi < 1";
      return false;
    }
  }
  out = u;
  return true;
}

bool read_modes_file(const std::string& path, const std::string& option, bool with_intervals, std::size_t max_modes,
                     std::vector<commission::UncertainMode>& out, RequestError& err) {
  Json j;
  if (!read_json_object_file(path, option,
                             {"modes file", "settle identify --json", "bad_modes_file", kMaxModesFileBytes}, j, err)) {
    return false;
  }
  auto bad = [&](const std::string& why) {
    err = {"bad_modes_file", option, option + ": " + why};
    return false;
  };
  if (!j.contains("status") || j["status"] != "ok") return bad("\"status\" is not \"ok\" (identification failed?)");
  if (!j.contains("modes") || !j["modes"].is_array()) return bad("no \"modes\" array");
  const Json& modes = j["modes"];
  if (modes.empty()) return bad("\"modes\" is empty: nothing to tune for");
  if (modes.size() > max_modes) {
    return bad("holds " + std::to_string(modes.size()) + " modes; at most " + std::to_string(max_modes));
  }
  std::vector<commission::UncertainMode> list(modes.size());
  for (std::size_t i = 0; i < modes.size(); ++i) {
    std::string why;
    if (!mode_from_json(modes[i], with_intervals, list[i], why)) return bad("modes[" + std::to_string(i) + "]" + why);
  }
  out = std::move(list);
  return true;
}

}  // namespace settle::app
