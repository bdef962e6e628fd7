// SPDX-License-Identifier: Apache-2.0
#pragma once
// The demo's two judgements on the runs' JSON (settle stream --json), apart from the processes
// that produce it so that tests can hold them: a paper's method against its baseline, and a
// float or fixed-point run against the double run. A "no" from either fails the demo (exit 1).
#include <optional>
#include <string>

#include "io/json.hpp"

namespace settle::app {

// A paper's method against its baseline at one move time, from their residuals measured over CAN
// (`residual_can` of a run whose `status` is "ok": a failed run's figures are no measurement).
struct ResidualVerdict {
  double ratio{0.0};  // the baseline's residual over the method's (NaN: one not measured)
  bool less{false};   // the method left less residual than its baseline (false when one is missing)
};
[[nodiscard]] ResidualVerdict compare_residuals(const std::optional<Json>& method, const std::optional<Json>& baseline);

// Float or fixed point against double: the residual the run measured over CAN equals the double
// evaluation's within kScalarResidualPercent percent (`residual_vs_double_percent`) or within
// kScalarResidualCounts load counts (`residual_vs_double_load_counts`: the measurement's
// resolution; below one count a one-count setpoint change moves a residual by more than 1 %).
// The setpoint difference is reported, not judged.
inline constexpr double kScalarResidualPercent = 1.0;
inline constexpr double kScalarResidualCounts = 1.0;
struct ScalarCheck {
  bool agrees{false};
  std::string why;  // no result, refused, or not measured ("" when compared)
};
[[nodiscard]] ScalarCheck check_scalar(const std::optional<Json>& run, const std::optional<Json>& double_run);

}  // namespace settle::app
