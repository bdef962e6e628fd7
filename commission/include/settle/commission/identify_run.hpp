// SPDX-License-Identifier: Apache-2.0
#pragma once
// `settle identify` as a library call: the servo loop streams an excitation (a planned,
// limit-respecting move, then a hold) to a drive over CAN, the drive's feedback frames (position
// actual, TPDO1; load-side position, TPDO2) are recorded, and the modes are estimated from them
// alone (identify_modes): the master never reads the plant's parameters. run_identify(spec, bus)
// -> IdentifyRunReport; the reporters (text, the CSV behind --png) are beside it (the JSON document
// is the CLI's: app/io/modes_json.hpp).
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "settle/commission/identify.hpp"
#include "settle/plant/csv_columns.hpp"
#include "settle/testbed/stream.hpp"

namespace settle::commission {

struct IdentifyRunSpec {
  testbed::StreamSpec stream{};  // move: the excitation; settle_time_s: the hold recorded after it
  IdentifyOptions options{};
};

struct IdentifyRunReport {
  std::string failure;       // non-empty: nothing was identified, and why (one line)
  std::string failure_code;  // drive_not_enabled, no_load_feedback, feedback_incomplete, response_too_small, ...
  testbed::StreamReport stream{};
  double period_s{0.0};
  std::vector<std::int32_t> motor;  // the record the estimate comes from: position actual, counts
  std::vector<std::int32_t> load;   // load-side position, load counts
  IdentifyResult result{};
  [[nodiscard]] bool ok() const noexcept { return failure.empty() && result.status == IdentifyStatus::ok; }
};

// Streams spec.stream.axes.front().move over `bus`, then spec.stream.settle_time_s at rest, and identifies.
[[nodiscard]] IdentifyRunReport run_identify(const IdentifyRunSpec& spec, testbed::ClockedBus& bus);

// The text summary: a line per mode with its intervals, the excitation and the fit.
void write_identify_text(const IdentifyRunSpec& spec, const IdentifyRunReport& r, std::FILE* out);
// t_s, measured_deflection_<u>, fitted_deflection_<u>: the load's deflection (rigid motion
// removed) per sample, in the user's position unit `u` (a label: nothing is scaled); and
// frequency_hz, measured_amplitude_<u>, fitted_amplitude_<u>: the magnitude of their discrete
// Fourier transforms over the free response (plant/csv_columns.hpp). False when writing failed or
// there is no fit.
[[nodiscard]] bool write_identify_time_csv(const IdentifyRunSpec& spec, const IdentifyRunReport& r, plant::PositionUnit u,
                                           std::FILE* out);
[[nodiscard]] bool write_identify_spectrum_csv(const IdentifyRunSpec& spec, const IdentifyRunReport& r,
                                               plant::PositionUnit u, std::FILE* out);

}  // namespace settle::commission
