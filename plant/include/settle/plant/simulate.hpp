// SPDX-License-Identifier: Apache-2.0
#pragma once
// Runs a command on a plant and measures what the input-shaping literature measures: residual
// vibration amplitude and PRV, peak deflection during the move, settling time, final energy.
// The command is followed by quintic Hermite pieces on a grid that contains all its breakpoints
// and each piece is integrated exactly, so the only approximation is the O(dt^6) interpolation.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "settle/plant/command.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/plant/status.hpp"

namespace settle::plant {

// Bounds (limits.hpp): the command's duration plus the recorded tail at most kMaxSimulatedTime
// (too_long, also for a NaN or infinite one), and at most kMaxSamples grid points plus tail steps
// (too_many_samples); both are checked before anything is allocated.
struct SimOptions {
  double dt{1e-4};    // grid step (s); breakpoints are added to it
  double tail{-1.0};  // recorded time after the command ends; < 0: three periods of the slowest mode
  bool record{true};  // keep the time history
  double band{-1.0};  // settling band (output units); < 0: 5 % of the unshaped-step residual
};

struct HistorySample {
  double t{0.0};
  BaseState command{};
  double deflection{0.0};
  double position{0.0};
  double velocity{0.0};
  double acceleration{0.0};
  Energy energy{};
};

// Whether the output settles into its band after the move, from the closed-form free response.
enum class Settling : std::uint8_t {
  settled,         // settling_time is finite
  undamped,        // an undamped mode (zeta = 0) alone swings wider than the band: never settles
  beyond_horizon,  // the decay envelope is still above the band kMaxSettlingTime after the move
                   // (a damping ratio so small, a denormal say, that the decay takes longer)
};
[[nodiscard]] const char* to_string(Settling s) noexcept;

struct SimMetrics {
  double move_end{0.0};            // when the command came to rest (s)
  double distance{0.0};            // command's final position
  double residual_amplitude{0.0};  // sum_j |c_j| amp_j at move_end (output units)
  double step_residual{0.0};       // the same for an unshaped step of the same distance
  double prv_percent{0.0};         // 100 residual / step residual
  std::vector<double> mode_residual;     // per mode, modal units
  std::vector<double> mode_prv_percent;  // per mode
  double peak_deflection{0.0};     // max |deflection| over [0, move_end] (grid samples)
  double final_energy{0.0};        // kinetic + potential at move_end (J)
  double band{0.0};
  double settling_time{0.0};       // from the start until |position - final| <= band for good; +inf unless
  Settling settling{Settling::settled};  // settled
};

struct SimResult {
  SimMetrics metrics;
  std::vector<HistorySample> history;
};

// The sorted grid: multiples of dt up to the command's end, with its breakpoints merged in;
// `is_break` (if given) flags the points where one-sided values may differ. Refuses a dt that is
// not positive and finite (non_positive_step), a command whose duration is NaN, infinite or
// negative (too_long), and a grid of more than kMaxSamples points (too_many_samples), before
// allocating; the outputs are then untouched.
[[nodiscard]] SimStatus command_grid(const Command& cmd, double dt, std::vector<double>& times,
                                     std::vector<char>* is_break = nullptr);

// Drives `plant` (reset at rest at 0) through `cmd` up to its end; calls `on_step` after each
// step if given. The plant is left at the command's end. The grid's bounds are command_grid's.
[[nodiscard]] SimStatus drive(ModalPlant& plant, const Command& cmd, double dt,
                              const std::function<void(const ModalPlant&, const BaseState&)>& on_step = {});

[[nodiscard]] SimStatus simulate(const ModalPlant& plant, const Command& cmd, const SimOptions& opt, SimResult& out);

// Time from the state the plant is in now (base at rest) until its position stays within `band`
// of where it will settle, using the closed-form free response. Always ends, in bounded work:
// status undamped (time +inf) if the undamped modes' amplitudes alone exceed the band;
// beyond_horizon (+inf) if the decay envelope still exceeds it kMaxSettlingTime from now; else
// settled and the time (the envelope is an upper bound, so the answer is found within the horizon).
struct FreeSettling {
  Settling status{Settling::settled};
  double time{0.0};
};
[[nodiscard]] FreeSettling free_settling_time(const ModalPlant& plant, double band);

}  // namespace settle::plant
