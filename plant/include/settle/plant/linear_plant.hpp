// SPDX-License-Identifier: Apache-2.0
#pragma once
// A linear plant in state-space form driven by the commanded base motion, integrated exactly over
// each step for a polynomial base motion (augmented-matrix exponential), so that integration error
// can never masquerade as residual vibration. This is the call a simulated drive makes per SYNC.
//
//   x' = A x + B [y, y', y'']^T        outputs  z = C x + D [y, y', y'']^T
//
// A jump of the base position or velocity between steps (a velocity step of seed 001, the kink of
// a linearly interpolated setpoint stream, a position step of a shaped step) is applied exactly as
// the impulse it is: x(0+) = x(0-) + (B1 + A B2) dy + B2 dv.
#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "settle/plant/base_motion.hpp"
#include "settle/plant/limits.hpp"
#include "settle/plant/status.hpp"

namespace settle::plant {

class LinearPlant {
 public:
  LinearPlant() = default;

  // b has three columns (base position, velocity, acceleration); so has d. Fails on inconsistent
  // sizes, more than kMaxStates states (too_many_modes) or non-finite entries and leaves `out`
  // untouched.
  [[nodiscard]] static SimStatus make(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c,
                                      const Eigen::MatrixXd& d, LinearPlant& out);

  // At rest with the base held at y: x = -A^-1 B0 y (0 when the base position does not drive x).
  void reset(double base_position = 0.0, double time = 0.0);
  // Any state, e.g. to resume a run or to test the integrator from given initial conditions.
  void set_state(const Eigen::VectorXd& x, const BaseState& base, double time);

  // Advances by exactly dt with the base following `base` (local time 0..dt). The base state at the
  // step's start is taken from the polynomial; a difference from where the previous step left the
  // base is applied as an impulse (see above).
  [[nodiscard]] SimStatus advance(double dt, const BasePolynomial& base);
  // Moves the base instantly to `to`, applying the impulse of the jump; advance() does this itself
  // at each step's start. Use it for a jump at the very end of a command.
  void jump_base(const BaseState& to);

  [[nodiscard]] Eigen::Index states() const noexcept { return a_.rows(); }
  [[nodiscard]] Eigen::Index outputs() const noexcept { return c_.rows(); }
  [[nodiscard]] const Eigen::VectorXd& state() const noexcept { return x_; }
  [[nodiscard]] const BaseState& base() const noexcept { return base_; }
  [[nodiscard]] double time() const noexcept { return t_; }
  [[nodiscard]] double output(Eigen::Index row) const;
  [[nodiscard]] const Eigen::MatrixXd& a() const noexcept { return a_; }
  [[nodiscard]] const Eigen::MatrixXd& b() const noexcept { return b_; }
  [[nodiscard]] const Eigen::MatrixXd& c() const noexcept { return c_; }
  [[nodiscard]] const Eigen::MatrixXd& d() const noexcept { return d_; }

  // The equilibrium state for the base held still at y.
  [[nodiscard]] Eigen::VectorXd rest_state(double y) const;
  // Amplitude of the free motion of output `row` that the current state leaves if the base stops
  // where it is now: sum over the eigenvalues l_k of |C v_k w_k^T (x - x_rest)|. For one
  // underdamped mode this is sqrt(e^2 + ((e' + zeta w e)/wd)^2), the residual of SEEDS.md.
  [[nodiscard]] double free_amplitude(Eigen::Index row) const;

  // The exact one-step maps for a base polynomial of `degree`: x(dt) = Phi x(0) + Gamma c.
  struct Transition {
    double dt{0.0};
    int chain{0};          // columns of gamma: polynomial coefficients c[0..chain-1]
    Eigen::MatrixXd phi;   // states x states
    Eigen::MatrixXd gamma; // states x chain, already scaled to act on coefficients
    // [Phi | Gamma] row-major: one contiguous dot product per state is the whole step.
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> packed;
  };
  [[nodiscard]] const Transition& transition(double dt, int degree);

 private:
  Eigen::MatrixXd a_, b_, c_, d_;
  Eigen::VectorXd jump_y_;  // B1 + A B2: the state jump per unit base position jump
  Eigen::VectorXd x_;
  BaseState base_{};
  double t_{0.0};
  // Steps of a drive node all have one dt; a sampled profile adds a few odd ones at its
  // breakpoints. A handful of cached transitions covers both without recomputing exponentials.
  std::vector<Transition> cache_;
  std::size_t evict_{0};
  std::size_t last_{0};  // the entry the previous step used: almost always the next one's
  // Eigen-decomposition for free_amplitude, computed on first use.
  mutable bool modal_ready_{false};
  mutable Eigen::MatrixXcd v_, w_;
};

}  // namespace settle::plant
