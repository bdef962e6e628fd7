// SPDX-License-Identifier: Apache-2.0
#pragma once
// The modes document: what `settle identify --json` prints and `settle tune --modes-from` (and the
// demo's commissioning verdict) reads back. Each mode states omega once, with its damping, gain and
// intervals: {"omega","zeta","gain","omega_ci":[lo,hi],"zeta_ci":[lo,hi],"gain_sd"}.
#include <string>
#include <vector>

#include "io/json.hpp"
#include "options.hpp"
#include "settle/commission/uncertain_mode.hpp"

namespace settle::app {

// Modes files are read whole, so their size is bounded first (bytes).
inline constexpr std::size_t kMaxModesFileBytes = 1 << 20;

// The "modes" array of the document, in the order given.
[[nodiscard]] Json modes_json(const std::vector<commission::UncertainMode>& modes);

// One entry of the "modes" array: omega in [0.01, 1e6] rad/s, zeta in [0, 1), gain (optional, 1 if
// absent) in [-1e6, 1e6]; with `with_intervals` also omega_ci (0 < lo <= omega <= hi) and zeta_ci
// (lo <= zeta <= hi < 1; a lo below 0 is read as 0), else the intervals are left at 0. False with
// `why` ("." + the key and what it must be) when the entry does not hold them.
[[nodiscard]] bool mode_from_json(const Json& m, bool with_intervals, commission::UncertainMode& out,
                                  std::string& why);

// The modes of a document `settle identify --json` printed, read from `path` (at most
// kMaxModesFileBytes, at most `max_modes` modes, each as mode_from_json reads it). Errors are
// bad_modes_file (or the file's own, such as cannot_read) naming `option`.
[[nodiscard]] bool read_modes_file(const std::string& path, const std::string& option, bool with_intervals,
                                   std::size_t max_modes, std::vector<commission::UncertainMode>& out,
                                   RequestError& err);

}  // namespace settle::app
