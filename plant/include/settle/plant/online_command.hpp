// SPDX-License-Identifier: Apache-2.0
#pragma once
// A move changed online (docs/online.md): the running move up to the switch time, then
// the halt or retarget blend core planned from its state there. What `settle simulate --halt-at`
// and `--retarget-at` run on the plant, so that the residual after a change is measured offline.
#include <optional>
#include <vector>

#include "settle/core/online.hpp"
#include "settle/plant/command.hpp"

namespace settle::plant {

class OnlineChangeCommand final : public Command {
 public:
  // The blend is planned by plan() below; this only joins the two.
  OnlineChangeCommand(const core::Move<double>& move, double t_switch, const core::Blend& blend);
  [[nodiscard]] double duration() const override { return t_switch_ + blend_.duration(); }
  [[nodiscard]] double final_position() const override { return blend_.end_position(); }
  [[nodiscard]] BaseState at(double t) const override { return sample(t, false); }
  [[nodiscard]] BaseState at_left(double t) const override { return sample(t, true); }
  void breakpoints(std::vector<double>& out) const override;
  [[nodiscard]] const core::Blend& blend() const noexcept { return blend_; }
  [[nodiscard]] double switch_time() const noexcept { return t_switch_; }

  // Plans the halt (target none) or the retarget of `move` at t_switch for the modes and limits.
  // A halt chooses (core::OnlinePlan): the fastest blend, a blend to the move's end, or finishing
  // the move; the Blend overload refuses the last (halt_finishes_command).
  [[nodiscard]] static core::Status plan(const core::Move<double>& move, double t_switch,
                                         const std::vector<core::Mode>& modes, const core::OnlineLimits& limits,
                                         std::optional<double> target, core::OnlinePlan& out);
  [[nodiscard]] static core::Status plan(const core::Move<double>& move, double t_switch,
                                         const std::vector<core::Mode>& modes, const core::OnlineLimits& limits,
                                         std::optional<double> target, core::Blend& out);

 private:
  [[nodiscard]] BaseState sample(double t, bool left) const;
  MoveCommand move_;
  double t_switch_;
  core::Blend blend_;
};

}  // namespace settle::plant
