// SPDX-License-Identifier: Apache-2.0
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "figure_option.hpp"
#include "io/json.hpp"
#include "io/plan_json.hpp"
#include "move_options.hpp"
#include "settle/plant/move_vocabulary.hpp"

namespace settle::app {

namespace {

void print_text(const core::Move<double>& m, const Json& shortest) {
  std::printf("profile      %s\n", core::to_string(m.profile().kind()));
  if (const std::string f = plant::profile_family(m.profile()); !f.empty()) std::printf("family       %s\n", f.c_str());
  std::printf("distance     %.9g\n", m.distance());
  std::printf("duration     %.9g s (profile %.9g s + shaper %.9g s)\n", m.duration(), m.profile().duration(),
              m.shaper().duration());
  for (const auto& [k, v] : plant::profile_params(m.profile())) std::printf("  %-22s %.9g\n", k.c_str(), v);
  const auto& pk = m.peaks();
  auto show = [](double v) { return std::isfinite(v) ? std::to_string(v) : std::string{"unbounded (impulse)"}; };
  std::printf("peak |v|     %s\npeak |a|     %s\npeak |j|     %s\n", show(pk.v).c_str(), show(pk.a).c_str(),
              show(pk.j).c_str());
  if (pk.velocity_step) std::printf("note         the command steps in velocity at start and end\n");
  if (pk.acceleration_step) std::printf("note         the command steps in acceleration\n");
  if (!shortest.is_null()) {
    if (shortest["proven"].get<bool>()) {
      std::printf("shortest     proven (LP duality; docs/fastest.md)\n");
    } else if (!shortest["at"].is_null()) {
      std::printf("shortest     not proven: %s at %.9g s\n", shortest["reason"].get<std::string>().c_str(),
                  shortest["at"].get<double>());
    } else {
      std::printf("shortest     not proven: %s\n", shortest["reason"].get<std::string>().c_str());
    }
  }
  if (!m.shaper().is_identity()) {
    std::printf("shaper       %zu impulses\n", m.shaper().count);
    for (std::size_t i = 0; i < m.shaper().count; ++i) {
      std::printf("  A=%.9f at t=%.9g s\n", m.shaper().amp[i], m.shaper().time[i]);
    }
  }
}

void print_axes_text(const core::MultiAxisPlan& p, const Json& j) {
  std::printf("axes         %zu (sync %s)\n", p.count(), core::to_string(p.sync()));
  std::printf("duration     %.9g s (every axis)\n", p.duration());
  std::printf("line dev.    %.6e (largest distance from the straight line, axis units)\n",
              j["line_deviation"].get<double>());
  if (p.sync() == core::SyncMode::path) {
    std::printf("path         s(t) from 0 to 1, shaped for %zu mode%s:", p.path_mode_count(),
                p.path_mode_count() == 1 ? "" : "s");
    for (std::size_t k = 0; k < p.path_mode_count(); ++k) {
      std::printf(" (omega %.7g, zeta %.5g)", p.path_mode(k).omega, p.path_mode(k).zeta);
    }
    std::printf("\n");
    print_text(p.path(), Json(nullptr));
  }
  for (std::size_t i = 0; i < p.count(); ++i) {
    const auto& pk = p.peaks(i);
    auto show = [](double v) { return std::isfinite(v) ? std::to_string(v) : std::string{"unbounded"}; };
    std::printf("axis %zu       distance %.9g  peak |v| %s  |a| %s  |j| %s  line dev. %.3e\n", i + 1, p.distance(i),
                show(pk.v).c_str(), show(pk.a).c_str(), show(pk.j).c_str(),
                j["axis"][i]["line_deviation"].get<double>());
    if (p.sync() == core::SyncMode::time) print_text(p.axis_move(i), Json(nullptr));
  }
}

// A plan's output: refused (exit 2) unless every number in it is finite, then JSON or text.
template <typename PrintText>
int emit(const ParsedArgs& args, const Json& j, PrintText&& print_text_output) {
  if (!all_finite(j)) {
    return report_bad_request({"non_finite_result", "--distance", "--distance: the plan has a non-finite number"},
                              args.json());
  }
  if (args.json()) {
    print_json(j);
  } else {
    print_text_output();
  }
  return kExitOk;
}

// settle plan --axes N: the coordinated move (docs/multi_axis.md).
int plan_axes_command(const ParsedArgs& args) {
  core::MultiAxisRequest req{};
  RequestError err;
  if (!parse_axes_request(args, req, err)) return report_bad_request(err, args.json());
  core::MultiAxisPlan plan{};
  if (!plan_axes(req, plan, err)) return report_bad_request(err, args.json());
  const Json j = axes_json(plan, req);
  return emit(args, j, [&] { print_axes_text(plan, j); });
}

}  // namespace

int cmd_plan(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("plan", argc, argv, args); rc >= 0) return rc;
  std::optional<FigurePath> png;
  if (const int rc = parse_png_option(args, png); rc >= 0) return rc;
  if (wants_axes(args)) {
    if (png) return refuse_png_with_axes(args);
    return plan_axes_command(args);
  }
  core::MoveRequest req{};
  RequestError err;
  if (!parse_move_request(args, req, err)) return report_bad_request(err, args.json());
  core::Move<double> move{};
  if (!plan_move(req, move, err)) return report_bad_request(err, args.json());
  Json j = plan_json(move);
  j["request"] = request_json(req);  // what --plan-from plans again (stream, sample, export)
  if (Json s = shortest_json(move, req); !s.is_null()) j["shortest"] = s;
  if (png && all_finite(j)) {
    // 2000 samples over the move: every switch of a jerk table stays visible.
    const double dt = move.duration() > 0.0 ? move.duration() / 2000.0 : 1e-3;
    if (const int rc = write_move_png(args, move, dt, "plan", *png); rc != kExitOk) return rc;
  }
  return emit(args, j, [&] { print_text(move, j.contains("shortest") ? j["shortest"] : Json(nullptr)); });
}

}  // namespace settle::app
