// SPDX-License-Identifier: Apache-2.0
#pragma once
// Identification of a machine's modes from what its drive reports, sampled once per period: the
// motor position (position actual) and the load-side position. The modes are those of ModalPlant
// (q'' + 2 zeta w q' + w^2 q = g x'', deflection = sum q): natural frequency, damping ratio and
// gain g to the base acceleration, each with a confidence interval. Method: docs/identification.md
// (a matrix pencil on the free response for the candidate modes, then an output-error
// Gauss-Newton/Levenberg-Marquardt fit of the whole record, pruned to the significant modes).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "settle/commission/uncertain_mode.hpp"
#include "settle/core/enum_text.hpp"

namespace settle::commission {

// --max-modes: the estimator looks for 1..kMaxIdentifyModes modes.
inline constexpr std::size_t kMaxIdentifyModes = 6;
// At most this many samples are fitted (2 min at 1 kHz); checked before allocating. The bound is
// the estimator's cost, not its memory: every Levenberg-Marquardt iteration solves a least-squares
// problem over the whole record, and a broad three-mode plant takes ~200 iterations, so the work
// grows as samples x iterations (docs/identification.md, "Cost", has the measurements).
inline constexpr std::size_t kMaxIdentifySamples = 120'000;

// Every status in order (ok first, 0): its enumerator, which is also its code (to_string), and
// the sentence describe() gives. The enum and both tables are made from this list (enum_text.hpp).
#define SETTLE_IDENTIFY_STATUSES(X) \
  X(ok, "identified") \
  /* sizes differ, scales not positive and finite, max_modes out of range */ \
  X(bad_input, "the record is inconsistent (sizes, scales or mode count)") \
  /* more than kMaxIdentifySamples */ \
  X(too_many_samples, "the record has more samples than the estimator takes (120 000)") \
  /* the motor never moved: nothing was excited */ \
  X(no_motion, "the motor never moved: the record excites nothing") \
  /* fewer than kMinFreeSamples after the motor came to rest */ \
  X(free_response_too_short, "fewer than 100 samples were recorded after the motor came to rest") \
  /* no mode stands out of the noise: the response is noise-dominated */ \
  X(response_too_small, \
    "the load-side response is noise-dominated: no mode stands out of the noise (excite harder " \
    "or reduce the noise)")
enum class IdentifyStatus : unsigned char { SETTLE_IDENTIFY_STATUSES(SETTLE_ENUM_ENUMERATOR) };
[[nodiscard]] const char* to_string(IdentifyStatus s) noexcept;  // "response_too_small"
[[nodiscard]] const char* describe(IdentifyStatus s) noexcept;   // one sentence

inline constexpr std::size_t kMinFreeSamples = 100;

struct IdentifyInput {
  double period_s{1e-3};
  double counts_per_unit{1e6};       // motor counts per output unit (m or rad)
  double load_counts_per_unit{1e6};  // load counts per output unit
  std::span<const std::int32_t> motor;  // position actual at the end of each period
  std::span<const std::int32_t> load;   // load-side position at the same instants
};

struct IdentifyOptions {
  std::size_t max_modes{3};        // 1..kMaxIdentifyModes
  // A mode whose peak contribution to the load (|g q| over the record) is below this fraction of
  // the largest mode's is dropped: the share of the deflection, not the gain g, which for the same
  // deflection scales as omega^2 (docs/identification.md).
  double min_relative_deflection{0.0};
  double confidence{0.95};         // of each interval (0.5 .. 0.999)
  // A mode is kept only if its gain is this many standard errors from zero: what keeps noise from
  // being reported as modes.
  double min_significance{8.0};
};

struct IdentifyResult {
  IdentifyStatus status{IdentifyStatus::bad_input};
  std::vector<UncertainMode> modes;  // sorted by omega; intervals at IdentifyOptions::confidence
  std::size_t pencil_order{0};        // the matrix pencil's order (2 per mode, 1 per real pole)
  std::size_t order{0};               // the fitted model's: 2 per identified mode
  double rms_residual{0.0};           // of the final fit, output units
  double noise_rms{0.0};              // estimated from the free response's pencil, output units
  double rigid_gain{0.0};             // load per motor displacement (1 for a direct drive)
  double offset{0.0};                 // load - rigid_gain x motor at rest, output units
  double peak_deflection{0.0};        // largest |load - rigid x motor - offset| the fit explains
  std::size_t motion_start{0};        // first sample with the motor moved
  std::size_t motion_end{0};          // first sample of the free response (motor at rest since)
  std::size_t iterations{0};          // of the nonlinear fit, all rounds
  std::vector<double> fitted_load;    // the final model's load position per sample (output units)
};

// Identifies the modes from the sampled record. The record must contain the motor's motion and
// at least kMinFreeSamples after it came to rest (the free response).
[[nodiscard]] IdentifyResult identify_modes(const IdentifyInput& in, const IdentifyOptions& opt = {});

// The response of a unit-gain mode (g = 1) to a base that moves linearly between the samples
// `x` (what the drive's linear interpolation does): q at each sample, starting at rest. Exact
// for any period (matrix exponential of the piecewise-constant base velocity).
void mode_response(double omega, double zeta, double period_s, std::span<const double> x, std::span<double> q);

}  // namespace settle::commission
