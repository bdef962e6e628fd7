// SPDX-License-Identifier: Apache-2.0
#pragma once
// The plants of the three papers, and a user's own list of modes, as one type: a base moved by
// the command and a set of second-order modes excited by the base acceleration. Built on
// LinearPlant (exact stepping); adds what the metrics need per mode and the energies.
//
//   q_j'' + 2 zeta_j w_j q_j' + w_j^2 q_j = g_j y''        deflection = sum_j c_j q_j
//   output position = rigid y + deflection
//
// sdof (seeds 001/002): q = x - y, g = -1, c = 1, rigid = 1 (the mass is driven through spring
// and damper, which in the relative coordinate is exactly a base-acceleration load).
// belt (seed 004): q = alpha = theta - lambda phi_m, g = -lambda, c = 1, rigid = lambda.
// beam (seed 000): q_j modal coordinates, g = Lambda_j, c = phi_j(L), rigid = 1.
#include <cstddef>
#include <string>
#include <vector>

#include "settle/plant/beam.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/linear_plant.hpp"
#include "settle/plant/status.hpp"

namespace settle::plant {

struct Mode {
  double omega{0.0};   // natural frequency (rad/s)
  double zeta{0.0};    // damping ratio, 0 <= zeta < 1
  double gain{1.0};    // g: response to base acceleration
  double output{1.0};  // c: contribution to the deflection
  // Energy of the mode: kinetic 1/2 mass (q' + coupling y')^2, potential 1/2 mass w^2 q^2.
  double mass{1.0};
  double coupling{0.0};
  // Seed 000 only (0 otherwise): the root beta_j; gain is then Lambda_j and output phi_j(L).
  double beta{0.0};
};

enum class PlantKind : unsigned char { sdof, beam, belt, modes };
[[nodiscard]] const char* to_string(PlantKind k) noexcept;

// Defaults: seed 001's system (m = 1 kg, k = 800 N/m, c = 9 N s/m).
struct SdofParams {
  double mass{1.0};
  double stiffness{800.0};
  double damping{9.0};
};

// Defaults: Table III of seed 004. Radii in metres; ratio is z (1:10 -> 0.1).
struct BeltParams {
  double inertia{6.0};           // J (kg m^2)
  double belt_stiffness{9e4};    // k of each branch (N/m)
  double belt_damping{150.0};    // c of each branch (N s/m)
  double pulley_r{0.060};        // r (m)
  double pulley_R{0.180};        // R (m)
  double ratio{0.1};             // z
};
// lambda = z r / R, the motor-to-platform ratio.
[[nodiscard]] double belt_lambda(const BeltParams& p) noexcept;

struct BeamOptions {
  BeamParams params{};
  std::size_t modes{3};
  double modal_damping{0.0};
};

struct Energy {
  double kinetic{0.0};
  double potential{0.0};
};

class ModalPlant {
 public:
  ModalPlant() = default;

  // At most kMaxModes modes (too_many_modes, checked before anything is sized).
  [[nodiscard]] static SimStatus make_modes(const std::vector<Mode>& modes, double rigid_gain, PlantKind kind,
                                            ModalPlant& out);
  [[nodiscard]] static SimStatus make_sdof(const SdofParams& p, ModalPlant& out);
  [[nodiscard]] static SimStatus make_belt(const BeltParams& p, ModalPlant& out);
  [[nodiscard]] static SimStatus make_beam(const BeamOptions& o, ModalPlant& out);

  [[nodiscard]] PlantKind kind() const noexcept { return kind_; }
  [[nodiscard]] const std::vector<Mode>& modes() const noexcept { return modes_; }
  [[nodiscard]] double rigid_gain() const noexcept { return rigid_; }
  // The slowest mode, what a move is designed for when the user does not say.
  [[nodiscard]] const Mode& fundamental() const noexcept { return modes_[fundamental_]; }

  // The stepping interface (see LinearPlant): reset at rest, advance exactly by dt.
  void reset(double base_position = 0.0, double time = 0.0) { lin_.reset(base_position, time); }
  [[nodiscard]] SimStatus advance(double dt, const BasePolynomial& base) { return lin_.advance(dt, base); }
  [[nodiscard]] LinearPlant& linear() noexcept { return lin_; }
  [[nodiscard]] const LinearPlant& linear() const noexcept { return lin_; }
  [[nodiscard]] double time() const noexcept { return lin_.time(); }
  [[nodiscard]] const BaseState& base() const noexcept { return lin_.base(); }

  // Outputs at the current time (output units: m for sdof and beam, rad of platform for belt).
  [[nodiscard]] double deflection() const;
  [[nodiscard]] double position() const;
  [[nodiscard]] double velocity() const;
  [[nodiscard]] double acceleration() const;
  [[nodiscard]] double mode_q(std::size_t j) const;
  [[nodiscard]] double mode_dq(std::size_t j) const;
  [[nodiscard]] Energy energy() const;

  // Residual vibration if the base stopped now: per mode sqrt(q^2 + ((q' + zeta w q)/wd)^2) in
  // modal units, and the deflection's sum_j |c_j| amp_j (the largest excursion it can reach).
  [[nodiscard]] double mode_residual(std::size_t j) const;
  [[nodiscard]] double residual_amplitude() const;
  // What an unshaped position step of `distance` leaves: |g| D / sqrt(1 - zeta^2) per mode
  // (|Lambda| D for an undamped beam mode, D for the undamped sdof).
  [[nodiscard]] double mode_step_residual(std::size_t j, double distance) const;
  [[nodiscard]] double step_residual(double distance) const;

 private:
  PlantKind kind_{PlantKind::modes};
  std::vector<Mode> modes_;
  double rigid_{1.0};
  std::size_t fundamental_{0};
  LinearPlant lin_;
};

// A plant as a user names it (the --plant options of `settle simulate` and `settle plant`): one
// kind and its parameters; the other members are ignored.
struct PlantSpec {
  PlantKind kind{PlantKind::beam};
  SdofParams sdof{};
  BeamOptions beam{};
  BeltParams belt{};
  std::vector<Mode> modes{};  // kind == modes: omega, zeta, gain per mode (output 1, unit mass)
};
[[nodiscard]] SimStatus make_plant(const PlantSpec& spec, ModalPlant& out);

// Output rows of the LinearPlant a ModalPlant builds.
inline constexpr Eigen::Index kRowDeflection = 0;
inline constexpr Eigen::Index kRowPosition = 1;
inline constexpr Eigen::Index kRowVelocity = 2;
inline constexpr Eigen::Index kRowAcceleration = 3;

}  // namespace settle::plant
