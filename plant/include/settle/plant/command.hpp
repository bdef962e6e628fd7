// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a plant is driven with in an offline simulation: a base motion known at any instant, with
// both one-sided values where it is not smooth, and the list of those instants. The simulator puts
// every breakpoint on its grid, so a velocity step or a kink is integrated exactly, not smeared.
#include <cstddef>
#include <vector>

#include "settle/core/move.hpp"
#include "settle/plant/base_motion.hpp"

namespace settle::plant {

class Command {
 public:
  Command() = default;
  Command(const Command&) = default;
  Command& operator=(const Command&) = default;
  virtual ~Command() = default;

  // From this instant on the base rests at final_position().
  [[nodiscard]] virtual double duration() const = 0;
  [[nodiscard]] virtual double final_position() const = 0;
  // Right and left limits of position, velocity and acceleration. Before 0 the base rests at 0.
  [[nodiscard]] virtual BaseState at(double t) const = 0;
  [[nodiscard]] virtual BaseState at_left(double t) const = 0;
  // Instants in [0, duration()] where position, velocity or acceleration may jump or a piece
  // ends (0 and duration() included). Appended to `out`, unsorted.
  virtual void breakpoints(std::vector<double>& out) const = 0;
};

// Any planned core move, shaped or not.
class MoveCommand final : public Command {
 public:
  explicit MoveCommand(const core::Move<double>& m);
  [[nodiscard]] double duration() const override { return move_.duration(); }
  [[nodiscard]] double final_position() const override { return move_.distance(); }
  [[nodiscard]] BaseState at(double t) const override { return sample(t, false); }
  [[nodiscard]] BaseState at_left(double t) const override { return sample(t, true); }
  void breakpoints(std::vector<double>& out) const override;
  [[nodiscard]] const core::Move<double>& move() const noexcept { return move_; }

 private:
  [[nodiscard]] BaseState sample(double t, bool left) const;
  core::Move<double> move_;
  std::vector<double> profile_breaks_;  // of the unshaped profile, relative to its start
};

// Another command times a constant: one axis of a path-synchronised coordinated move, D_i s(t)
// (core/multi_axis.hpp). Holds a reference: `base` must outlive it.
class ScaledCommand final : public Command {
 public:
  ScaledCommand(const Command& base, double scale) : base_{&base}, k_{scale} {}
  [[nodiscard]] double duration() const override { return base_->duration(); }
  [[nodiscard]] double final_position() const override { return k_ * base_->final_position(); }
  [[nodiscard]] BaseState at(double t) const override { return scaled(base_->at(t)); }
  [[nodiscard]] BaseState at_left(double t) const override { return scaled(base_->at_left(t)); }
  void breakpoints(std::vector<double>& out) const override { base_->breakpoints(out); }

 private:
  [[nodiscard]] BaseState scaled(const BaseState& s) const { return {k_ * s.p, k_ * s.v, k_ * s.a}; }
  const Command* base_;
  double k_;
};

// A position step shaped by impulses: y(t) = distance * sum_{t_i <= t} A_i. The classic input
// shaping experiment (the staircase a ZV/ZVD/EI shaper makes of a step).
class StepsCommand final : public Command {
 public:
  StepsCommand(double distance, const core::Shaper<double>& shaper) : distance_{distance}, shaper_{shaper} {}
  [[nodiscard]] double duration() const override { return shaper_.duration(); }
  [[nodiscard]] double final_position() const override;
  [[nodiscard]] BaseState at(double t) const override;
  [[nodiscard]] BaseState at_left(double t) const override;
  void breakpoints(std::vector<double>& out) const override;

 private:
  double distance_;
  core::Shaper<double> shaper_;
};

// Sahinkaya's inverse-dynamics input for the base-driven mass-spring-damper (seed 001's
// comparison): the output is to follow a polynomial x(t) of duration T (the cubic 3s^2 - 2s^3 of
// Sahinkaya's paper, or the smoother 3-4-5), and the command is what the nominal model needs for
// that: y = x + w with 2 zeta w_n w' + w_n^2 w = x'', w(0) = 0. After T, w decays with time
// constant 2 zeta / w_n and never ends: the command is cut (steps to rest) once |w| is below
// tail_cutoff x D (default 1e-16). Where it ends therefore depends on that cut-off; a residual
// referred back to a fixed time does not (reproduce.hpp, referred_residual_001). With the cubic,
// x'' steps at both ends and so does the command's velocity.
class InverseDynamicsCommand final : public Command {
 public:
  static constexpr double kDefaultTailCutoff = 1e-16;
  // degree: 3 (cubic) or 5 (3-4-5); 0 < tail_cutoff < 1 (outside: the default).
  InverseDynamicsCommand(double distance, double time, double omega, double zeta, int degree = 5,
                         double tail_cutoff = kDefaultTailCutoff);
  [[nodiscard]] double duration() const override { return end_; }
  [[nodiscard]] double final_position() const override { return d_; }
  [[nodiscard]] BaseState at(double t) const override { return sample(t, false); }
  [[nodiscard]] BaseState at_left(double t) const override { return sample(t, true); }
  void breakpoints(std::vector<double>& out) const override;

 private:
  [[nodiscard]] BaseState sample(double t, bool left) const;
  [[nodiscard]] double x_derivative(int k, double t) const;  // of the 3-4-5 output
  [[nodiscard]] double wp_derivative(int k, double t) const; // particular solution for w
  double d_, t_, omega_, kappa_;  // kappa = 2 zeta / omega: zeta enters only through it
  int degree_;
  double wp0_{0.0}, w_end_{0.0}, end_{0.0};
};

// Left/right samples of a core profile at t (relative to the profile's own start), exact at its
// segment boundaries; used by MoveCommand and exposed for tests.
[[nodiscard]] BaseState profile_sample(const core::Profile<double>& p, double t, bool left);
void profile_breakpoints(const core::Profile<double>& p, std::vector<double>& out);

}  // namespace settle::plant
