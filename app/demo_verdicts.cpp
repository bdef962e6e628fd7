// SPDX-License-Identifier: Apache-2.0
#include "demo_verdicts.hpp"

#include <cmath>
#include <limits>

namespace settle::app {

namespace {

// A double NaN: the NAN macro is a float, and assigning it promotes it.
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double number_or_nan(const Json& j, const char* key) {
  return j.contains(key) && j.at(key).is_number() ? j.at(key).get<double>() : kNaN;
}

// The residual a run measured over CAN; NaN when it has none, or its run failed (its figures are
// then not a measurement).
double measured_residual(const std::optional<Json>& run) {
  return run && run->value("status", "") == "ok" ? number_or_nan(*run, "residual_can") : kNaN;
}

}  // namespace

ResidualVerdict compare_residuals(const std::optional<Json>& method, const std::optional<Json>& baseline) {
  const double rm = measured_residual(method), rb = measured_residual(baseline);
  // NaN (a run without a measured residual) compares false: never "less".
  return ResidualVerdict{rb / rm, rm < rb};
}

ScalarCheck check_scalar(const std::optional<Json>& r, const std::optional<Json>& d) {
  ScalarCheck c;
  if (!r || !d || d->value("status", "") != "ok") {
    c.why = "no result";
    return c;
  }
  if (r->value("evaluation", "") != "ok") {
    c.why = "refused the move (" + r->value("evaluation", std::string{"-"}) + ")";
    return c;
  }
  const double percent = number_or_nan(*r, "residual_vs_double_percent");
  const double counts = number_or_nan(*r, "residual_vs_double_load_counts");
  if (r->value("status", "") != "ok" || !std::isfinite(percent) || !std::isfinite(counts)) {
    c.why = r->value("outcome", std::string{"-"}) + ", its residual not measured";
    return c;
  }
  c.agrees = percent <= kScalarResidualPercent || counts <= kScalarResidualCounts;
  return c;
}

}  // namespace settle::app
