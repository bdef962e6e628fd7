#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "json.hpp"
#include "plan_json.hpp"
#include "move_options.hpp"
#include "settle/sim/move_vocabulary.hpp"

namespace settle::cli {

namespace {

void print_text(const core::Move<double>& m) {
  std::printf("profile      %s\n", core::to_string(m.profile().kind()));
  if (const std::string f = sim::profile_family(m.profile()); !f.empty()) std::printf("family       %s\n", f.c_str());
  std::printf("distance     %.9g\n", m.distance());
  std::printf("duration     %.9g s (profile %.9g s + shaper %.9g s)\n", m.duration(), m.profile().duration(),
              m.shaper().duration());
  for (const auto& [k, v] : sim::profile_params(m.profile())) std::printf("  %-22s %.9g\n", k.c_str(), v);
  const auto& pk = m.peaks();
  auto show = [](double v) { return std::isfinite(v) ? std::to_string(v) : std::string{"unbounded (impulse)"}; };
  std::printf("peak |v|     %s\npeak |a|     %s\npeak |j|     %s\n", show(pk.v).c_str(), show(pk.a).c_str(),
              show(pk.j).c_str());
  if (pk.velocity_step) std::printf("note         the command steps in velocity at start and end\n");
  if (pk.acceleration_step) std::printf("note         the command steps in acceleration\n");
  if (!m.shaper().is_identity()) {
    std::printf("shaper       %zu impulses\n", m.shaper().count);
    for (std::size_t i = 0; i < m.shaper().count; ++i) {
      std::printf("  A=%.9f at t=%.9g s\n", m.shaper().amp[i], m.shaper().time[i]);
    }
  }
}

}  // namespace

int cmd_plan(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("plan", argc, argv, args); rc >= 0) return rc;
  core::MoveRequest req{};
  RequestError err;
  if (!parse_move_request(args, req, err)) return report_bad_request(err, args.json());
  core::Move<double> move{};
  if (!plan_move(req, move, err)) return report_bad_request(err, args.json());
  const Json j = plan_json(move);
  if (!all_finite(j)) {
    return report_bad_request({"non_finite_result", "--distance", "--distance: the plan has a non-finite number"},
                              args.json());
  }
  if (args.json()) {
    print_json(j);
  } else {
    print_text(move);
  }
  return kExitOk;
}

}  // namespace settle::cli
