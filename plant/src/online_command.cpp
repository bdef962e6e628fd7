// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/online_command.hpp"

namespace settle::plant {

OnlineChangeCommand::OnlineChangeCommand(const core::Move<double>& move, double t_switch, const core::Blend& blend)
    : move_{move}, t_switch_{t_switch}, blend_{blend} {}

BaseState OnlineChangeCommand::sample(double t, bool left) const {
  // The switch itself is continuous in p, v, a: either side may answer there.
  if (left ? t <= t_switch_ : t < t_switch_) return left ? move_.at_left(t) : move_.at(t);
  const double u = t - t_switch_;
  if (left ? u > blend_.duration() : u >= blend_.duration()) return {blend_.end_position(), 0.0, 0.0};
  // Blend segments are cubics: p, v, a are continuous across their boundaries.
  const core::Sample<double> s = blend_.at(u);
  return {s.p, s.v, s.a};
}

void OnlineChangeCommand::breakpoints(std::vector<double>& out) const {
  std::vector<double> m;
  move_.breakpoints(m);
  for (double t : m) {
    if (t < t_switch_) out.push_back(t);
  }
  out.push_back(t_switch_);
  for (std::size_t k = 1; k <= core::kBlendSegments; ++k) {
    out.push_back(t_switch_ + static_cast<double>(k) * blend_.segment_length());
  }
}

core::Status OnlineChangeCommand::plan(const core::Move<double>& move, double t_switch,
                                       const std::vector<core::Mode>& modes, const core::OnlineLimits& limits,
                                       std::optional<double> target, core::OnlinePlan& out) {
  core::OnlineRequest r{};
  core::Status st = core::online_request(move, t_switch, modes.data(), modes.size(), limits, target, r);
  if (st == core::Status::ok) st = core::plan_online(r, out);
  return st;
}

core::Status OnlineChangeCommand::plan(const core::Move<double>& move, double t_switch,
                                       const std::vector<core::Mode>& modes, const core::OnlineLimits& limits,
                                       std::optional<double> target, core::Blend& out) {
  core::OnlineRequest r{};
  core::Status st = core::online_request(move, t_switch, modes.data(), modes.size(), limits, target, r);
  if (st == core::Status::ok) st = core::plan_online(r, out);
  return st;
}

}  // namespace settle::plant
