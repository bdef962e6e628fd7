// SPDX-License-Identifier: Apache-2.0
#pragma once
// What an end-to-end run is compared with: the offline replay of a streamed move (the same
// integer setpoints through the same DriveAxis, no bus), and the residual vibration estimated
// the same way from both: the largest |load - final| over the samples after the last setpoint.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "settle/core/move.hpp"
#include "settle/testbed/drive_axis.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/status.hpp"

namespace settle::testbed {

// The loop's integer targets for a move, tick by tick, ending exactly on origin + D. Refuses a zero
// period (non_positive_step), a scale that is not positive and finite (non_positive_scale) and a
// move of more than kMaxSamples setpoints at this period (too_many_samples) before allocating.
[[nodiscard]] plant::SimStatus stream_setpoints(const core::Move<double>& move, const core::AxisScale& scale,
                                         std::int32_t origin, std::vector<std::int32_t>& out);

struct Replay {
  std::vector<AxisFeedback> feedback;    // at the end of every period: the setpoints', then the window's
  std::size_t move_periods{0};           // how many of them carried the move's setpoints
  std::vector<std::int32_t> load_after;  // load counts at the end of each period from the last setpoint on
  double final_load{0.0};                // where the load settles (output units)
  double step_residual{0.0};             // for PRV: what an unshaped step of the same distance leaves
};

// Runs the setpoints through a fresh DriveAxis at rest at `origin`, then `window` periods holding
// the last one. At most kMaxSamples periods in all (too_many_samples, checked before allocating).
[[nodiscard]] plant::SimStatus replay_stream(const DriveAxisConfig& cfg, const plant::ModalPlant& plant, std::int32_t origin,
                                      std::span<const std::int32_t> setpoints, std::size_t window, Replay& out);

// Where the replay's feedback appears in a measured feedback sequence: the first offset at which
// every replayed position_actual equals the measured one. An exact match means each setpoint was
// applied once and in order, and that the samples are aligned period for period.
[[nodiscard]] std::optional<std::size_t> align_feedback(std::span<const std::int32_t> measured_positions,
                                                        const Replay& replay) noexcept;

struct SampledResidual {
  double amplitude{0.0};    // output units, at the first sample
  double prv_percent{0.0};
  std::size_t samples{0};
  double fit_rms{0.0};      // rms of what the modal fit leaves unexplained (quantisation, ~0.3 count)
};

// Residual vibration from load samples taken every dt once the base is at rest: a least-squares
// fit of the plant's free response, sum_j e^(-zeta_j w_j t)(A_j cos wd_j t + B_j sin wd_j t), and
// sum_j sqrt(A_j^2 + B_j^2) at the first sample: the literature's amplitude (the envelope, not the
// sampled peaks, which come after some decay). Modes above the sampling's Nyquist are left out.
// Too few samples for the fit leave the amplitude 0. The fit's matrix (samples x 2 per mode) is
// at most kMaxFitEntries (too_many_samples, checked before allocating).
[[nodiscard]] plant::SimStatus fitted_residual(std::span<const std::int32_t> load_counts, double load_counts_per_unit,
                                        double final_load, double dt, const plant::ModalPlant& plant, double step_residual,
                                        SampledResidual& out);

}  // namespace settle::testbed
