#include "online_options.hpp"

#include <cmath>

#include "settle/sim/online_command.hpp"

namespace settle::cli {

namespace {

// "T:D", both strict numbers.
bool split_retarget(const std::string& s, double& t, double& d) {
  const auto colon = s.find(':');
  if (colon == std::string::npos) return false;
  return parse_real(s.substr(0, colon), t) && parse_real(s.substr(colon + 1), d);
}

}  // namespace

bool parse_online_change(const ParsedArgs& args, const core::MoveRequest& req, const core::Move<double>& move,
                         const sim::ModalPlant* plant, double period, std::optional<OnlineChange>& out,
                         RequestError& err) {
  out.reset();
  const bool halt = args.has("--halt-at"), retarget = args.has("--retarget-at");
  if (!halt && !retarget) return true;
  if (halt && retarget) {
    err = {"conflicting_options", "--retarget-at", "--retarget-at: give either --halt-at or --retarget-at, not both"};
    return false;
  }
  OnlineChange c{};
  c.option = halt ? "--halt-at" : "--retarget-at";
  const std::string opt = c.option;
  if (halt) {
    c.at = args.real("--halt-at", 0.0);
  } else {
    double t = 0.0, d = 0.0;
    if (!split_retarget(args.text("--retarget-at", ""), t, d)) {
      err = {"bad_number", opt, opt + ": expected T:NEW_DISTANCE, e.g. 0.2:0.05 (T in s, NEW_DISTANCE in m or rad)"};
      return false;
    }
    if (!std::isfinite(t) || !std::isfinite(d)) {
      err = {"non_finite_input", opt, opt + ": T and NEW_DISTANCE must be finite"};
      return false;
    }
    if (!(std::fabs(d) <= 1e6)) {
      err = {"out_of_range", opt, opt + ": NEW_DISTANCE " + format_number(d) + " is outside -1e6..1e6"};
      return false;
    }
    c.at = t;
    c.target = d;
  }
  if (!(c.at >= 0.0 && c.at <= move.duration())) {
    err = {"out_of_range", opt,
           opt + ": T " + format_number(c.at) + " s is outside the move, 0.." + format_number(move.duration()) + " s"};
    return false;
  }
  if (period > 0.0) {
    c.at = std::fmax(std::nearbyint(c.at / period), 3.0) * period;
    if (!(c.at < move.duration())) {
      err = {"out_of_range", opt,
             opt + ": T rounds to " + format_number(c.at) + " s (whole periods, at least 3), not before the move's end " +
                 format_number(move.duration()) + " s"};
      return false;
    }
  }
  const core::Peaks<double>& pk = move.peaks();
  if (req.omega) {
    c.modes.push_back({*req.omega, req.zeta});
  } else if (plant != nullptr) {
    c.modes.push_back({plant->fundamental().omega, plant->fundamental().zeta});
  }
  c.limits = {req.vmax ? *req.vmax : pk.v, req.amax ? *req.amax : pk.a, req.jmax ? *req.jmax : pk.j};
  if (!std::isfinite(c.limits.vmax) || !std::isfinite(c.limits.amax)) {
    err = {"unsupported_request", opt,
           opt + ": the move steps in velocity (its acceleration is unbounded): no blend can start from it "
                 "with continuous acceleration"};
    return false;
  }
  if (!std::isfinite(c.limits.jmax)) {
    // A step in acceleration (a trapezoid) has no jerk limit to keep: the blend's jerk is held to
    // amax times the fastest mode's omega, the jerk of an acceleration change over 1/omega.
    double w = 0.0;
    for (const core::Mode& md : c.modes) w = std::fmax(w, md.omega);
    c.limits.jmax = c.limits.amax * (w > 0.0 ? w : 1.0);
  }
  const core::Status st =
      sim::OnlineChangeCommand::plan(move, c.at, c.modes, c.limits, c.target, c.blend);
  if (st != core::Status::ok) {
    err = {core::to_string(st), opt,
           opt + ": no blend within the limits from the move's state at " + format_number(c.at) + " s (" +
               core::describe(st) + ")"};
    return false;
  }
  out = c;
  return true;
}

}  // namespace settle::cli
