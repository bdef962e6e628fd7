#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include "commands.hpp"
#include "move_options.hpp"

namespace settle::cli {

int cmd_sample(int argc, char** argv) {
  std::set<std::string> values = kMoveValueOptions;
  values.insert("--dt");
  const Args args{argc, argv, values, kMoveFlagOptions};
  const bool json = args.flag("--json");
  if (!args.ok()) return report_bad_request({"bad_option", args.error_param(), args.error()}, json);
  core::MoveRequest req{};
  RequestError err;
  if (!parse_move_request(args, req, err)) return report_bad_request(err, json);
  double dt = 0.0;
  const auto dts = args.get("--dt");
  if (!dts) return report_bad_request({"missing_option", "--dt", "--dt is required (sample period, s)"}, json);
  if (!parse_double(*dts, dt) || !std::isfinite(dt) || !(dt > 0.0)) {
    return report_bad_request({"bad_number", "--dt", "--dt: must be a positive, finite number of seconds"}, json);
  }
  core::Move<double> move{};
  if (!plan_move(req, move, err)) return report_bad_request(err, json);
  const double n_real = std::ceil(move.duration() / dt);
  if (n_real > 1e8) return report_bad_request({"too_many_samples", "--dt", "--dt: more than 1e8 samples"}, json);
  const long n = static_cast<long>(n_real);
  std::printf("t,position,velocity,acceleration,jerk\n");
  for (long i = 0; i <= n; ++i) {
    const double t = std::min(static_cast<double>(i) * dt, move.duration());
    const auto s = move.at(t);
    std::printf("%.9g,%.12g,%.12g,%.12g,%.12g\n", t, s.p, s.v, s.a, s.j);
  }
  return kExitOk;
}

}  // namespace settle::cli
