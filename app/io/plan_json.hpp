// SPDX-License-Identifier: Apache-2.0
#pragma once
// A planned move as `settle plan --json` prints it, the request that plans its profile again, and
// the way back: a plan file (`settle tune --json` output) read into the very same Move, for
// `settle stream --plan-from` and `settle sample --plan-from`.
#include <string>

#include "io/json.hpp"
#include "options.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/core/planner.hpp"

namespace settle::app {

// Every number the plan reports. A peak that is an impulse (a velocity or acceleration step) is
// null, and flagged; any other non-finite number makes the plan unreportable (all_finite).
[[nodiscard]] Json plan_json(const core::Move<double>& m);

// A `fastest` move's proof of being the shortest of its problem (core::certify_fastest,
// docs/fastest.md "A certificate of the shortest move"): {"proven", "reason", "at" (s, null when
// proven), "gap"}; null for any other profile or a shaped move.
[[nodiscard]] Json shortest_json(const core::Move<double>& m, const core::MoveRequest& r);

// Peaks as plan_json reports them (an impulse null, and flagged).
[[nodiscard]] Json peaks_json(const core::Peaks<double>& pk);

// A coordinated move (`settle plan --axes N --json`, docs/multi_axis.md): the common duration, the
// largest deviation from the straight line, the path (path sync) and every axis's distance, mode,
// limits, peaks and deviation (time sync: its own plan too).
[[nodiscard]] Json axes_json(const core::MultiAxisPlan& p, const core::MultiAxisRequest& r);

// The fields of a request that plan an unshaped profile: profile, distance, whichever of time,
// vmax, amax, jmax it has, and its modes as one list ("modes": [{"omega", "zeta"}, ...], in order).
[[nodiscard]] Json request_json(const core::MoveRequest& r);

// Plan files are read whole, so their size is bounded first (bytes).
inline constexpr std::size_t kMaxPlanFileBytes = 1 << 20;

// Reads a file of at most `max_bytes` into `out`; false (with err naming `option`) when it cannot
// be read or is larger.
[[nodiscard]] bool read_bounded_file(const std::string& path, const std::string& option, std::size_t max_bytes,
                                     std::string& out, RequestError& err);

// What read_json_object_file reads: a document `name` ("plan file") that `producer` writes
// ("settle tune --json"), at most `max_bytes` long; its errors carry `code` and name the option.
struct JsonDocumentKind {
  const char* name;
  const char* producer;
  const char* code;
  std::size_t max_bytes;
};

// A file of that kind, read whole (bounded), its nesting checked before anything parses it, parsed
// as one JSON object (its fields, "status" first, are the caller's to check). false, with err naming
// `option`, otherwise.
[[nodiscard]] bool read_json_object_file(const std::string& path, const std::string& option, const JsonDocumentKind& kind,
                                         Json& out, RequestError& err);

// The move a plan file (settle plan --json, settle tune --json) describes: its "request" is planned
// again; its shaper is designed again — from the request (plan) or from "candidate" (tune) — and
// must equal the file's "shaper.impulses"; the result must reproduce the file's profile, params,
// distance and duration (else plan_mismatch: the file was edited or made by a different Settle).
// Errors name `option`.
[[nodiscard]] bool load_plan_file(const std::string& path, const std::string& option, core::Move<double>& out,
                                  RequestError& err);

}  // namespace settle::app
