#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "commands.hpp"
#include "move_options.hpp"

namespace settle::cli {

int cmd_sample(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("sample", argc, argv, args); rc >= 0) return rc;
  RequestError err;
  core::Move<double> move{};
  if (!move_from_args(args, move, err)) return report_bad_request(err, args.json());
  const auto dt = args.real("--dt");
  if (!dt) return report_bad_request({"missing_option", "--dt", "--dt: required (sample period, s)"}, args.json());
  const double n_real = std::ceil(move.duration() / *dt);
  if (!(n_real + 1.0 <= kMaxRows)) {
    return report_bad_request({"too_many_samples", "--dt", "--dt: " + format_number(n_real + 1.0) +
                                                               " samples; at most 2e6 (move duration / --dt)"},
                              args.json());
  }
  const long n = static_cast<long>(n_real);
  // Every sample is computed and checked before the first line is printed (two passes, so that
  // 2e6 samples need no memory).
  auto sample = [&](long i) {
    const double t = std::min(static_cast<double>(i) * *dt, move.duration());
    const auto s = move.at(t);
    return std::array<double, 5>{t, s.p, s.v, s.a, s.j};
  };
  for (long i = 0; i <= n; ++i) {
    for (double x : sample(i)) {
      if (!std::isfinite(x)) {
        return report_bad_request({"non_finite_result", "--profile",
                                   "--profile: a sample of this move is not finite"},
                                  args.json());
      }
    }
  }
  if (args.json()) {
    // Streamed, not built as a document; every number is finite.
    std::printf("{\"status\":\"ok\",\"columns\":[\"t\",\"position\",\"velocity\",\"acceleration\",\"jerk\"],"
                "\"rows\":[");
    for (long i = 0; i <= n; ++i) {
      const auto r = sample(i);
      std::printf("%s[%.17g,%.17g,%.17g,%.17g,%.17g]", i == 0 ? "" : ",", r[0], r[1], r[2], r[3], r[4]);
    }
    std::printf("]}\n");
    return kExitOk;
  }
  std::printf("t,position,velocity,acceleration,jerk\n");
  for (long i = 0; i <= n; ++i) {
    const auto r = sample(i);
    std::printf("%.9g,%.12g,%.12g,%.12g,%.12g\n", r[0], r[1], r[2], r[3], r[4]);
  }
  return kExitOk;
}

}  // namespace settle::cli
