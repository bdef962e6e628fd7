// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a CSP drive does with the setpoints it is streamed, as physics: the target received
// before SYNC k is applied at SYNC k and reached one period later, linearly interpolated (or by
// a cubic through the previous setpoints), optionally through a position loop of finite
// bandwidth, and the mechanical plant behind it is advanced exactly over each period (see
// docs/drive.md). Used by the simulated drive node on the bus and, without any bus, as the
// offline reference the end-to-end checks compare against: the same code, the same numbers.
#include <cstdint>
#include <random>

#include "settle/core/axis_scale.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/plant/status.hpp"

namespace settle::testbed {

enum class Interpolation : std::uint8_t { linear, cubic };

struct DriveModel {
  bool servo{false};         // false: ideal position-following drive
  double bandwidth_hz{30.0}; // servo: natural frequency of the position loop
  double damping{0.7};       // servo: its damping ratio
};

struct DriveAxisConfig {
  core::AxisScale scale{};           // base (motor) position counts per m or rad, and the SYNC period
  double load_counts_per_unit{1e6};  // load position counts per output unit (m, or rad of platform)
  Interpolation interpolation{Interpolation::linear};
  DriveModel model{};
  // The load encoder's white noise: standard deviation in load counts, added before quantisation
  // (0: a perfect encoder), from a generator seeded with noise_seed (`settle identify --noise`).
  double load_noise_counts{0.0};
  std::uint64_t noise_seed{1};
};

struct AxisFeedback {
  std::int32_t position_actual{0};  // counts, base
  std::int32_t velocity_actual{0};  // counts/s, base
  std::int32_t load_position{0};    // counts, load (plant output)
};

class DriveAxis {
 public:
  // `plant` is the machine behind the drive; it starts at rest with the base at `start_counts`.
  [[nodiscard]] static plant::SimStatus make(const DriveAxisConfig& cfg, const plant::ModalPlant& plant, std::int32_t start_counts,
                                      DriveAxis& out);

  // One SYNC period with the target applied at its start. Returns the feedback at its end.
  [[nodiscard]] plant::SimStatus step(std::int32_t target_counts);
  // One period without a new target: the base holds where it is (drive disabled or stopped).
  [[nodiscard]] plant::SimStatus hold();

  [[nodiscard]] const AxisFeedback& feedback() const noexcept { return fb_; }
  [[nodiscard]] const plant::ModalPlant& plant() const noexcept { return plant_; }
  [[nodiscard]] const DriveAxisConfig& config() const noexcept { return cfg_; }
  // Output position (m or rad) of the load, unquantised.
  [[nodiscard]] double load_position() const { return plant_.position(); }
  [[nodiscard]] double base_position() const { return plant_.base().p; }

 private:
  [[nodiscard]] plant::SimStatus advance_to(double x_new);
  void update_feedback();

  DriveAxisConfig cfg_{};
  plant::ModalPlant plant_{};
  plant::ModalPlant servo_{};     // the position loop, when modelled: an sdof driven by the reference
  double x_prev_{0.0};     // last two applied targets (units), for the interpolation
  double x_prev2_{0.0};
  AxisFeedback fb_{};
  std::mt19937_64 noise_rng_{1};
};

}  // namespace settle::testbed
