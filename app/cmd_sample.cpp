// SPDX-License-Identifier: Apache-2.0
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "figure_option.hpp"
#include "move_options.hpp"
#include "settle/papers/figures.hpp"

namespace settle::app {

namespace {

constexpr double kMaxFigureSamples = 1e6;  // the rows a --png figure holds (as simulate's)

// The number of samples of a move of `duration` every `dt`, bounded (false with err when over kMaxRows).
bool sample_count(double duration, double dt, long& n, RequestError& err) {
  const double n_real = std::ceil(duration / dt);
  if (!(n_real + 1.0 <= kMaxRows)) {
    err = {"too_many_samples", "--dt", "--dt: " + format_number(n_real + 1.0) +
                                           " samples; at most 2e6 (move duration / --dt)"};
    return false;
  }
  n = static_cast<long>(n_real);
  return true;
}

// settle sample --axes N: t, then position, velocity, acceleration and jerk of every axis
// (columns suffixed _1.._N).
int sample_axes(const ParsedArgs& args, double dt) {
  RequestError err;
  if (args.has("--plan-from")) {
    return report_bad_request({"conflicting_options", "--plan-from",
                               "--plan-from: holds one axis's plan; give no --axes with it"},
                              args.json());
  }
  core::MultiAxisRequest req{};
  core::MultiAxisPlan plan{};
  if (!parse_axes_request(args, req, err) || !plan_axes(req, plan, err)) {
    return report_bad_request(err, args.json());
  }
  long n = 0;
  if (!sample_count(plan.duration(), dt, n, err)) return report_bad_request(err, args.json());
  const std::size_t axes = plan.count();
  auto row = [&](long i, std::vector<double>& r) {
    const double t = std::min(static_cast<double>(i) * dt, plan.duration());
    r.assign(1, t);
    for (std::size_t k = 0; k < axes; ++k) {
      const auto s = plan.at(k, t);
      r.insert(r.end(), {s.p, s.v, s.a, s.j});
    }
  };
  std::vector<double> r;
  for (long i = 0; i <= n; ++i) {
    row(i, r);
    if (!std::all_of(r.begin(), r.end(), [](double x) { return std::isfinite(x); })) {
      return report_bad_request({"non_finite_result", "--profile", "--profile: a sample of this move is not finite"},
                                args.json());
    }
  }
  const plant::PositionUnit unit = position_unit(args);
  const bool json = args.json();
  if (json) {
    // The JSON's column names stay as they were (readers index them); the unit is said once.
    std::vector<std::string> columns{"t"};
    for (std::size_t k = 1; k <= axes; ++k) {
      for (const char* c : {"position_", "velocity_", "acceleration_", "jerk_"}) columns.push_back(c + std::to_string(k));
    }
    std::printf("{\"status\":\"ok\",\"unit\":\"%s\",\"columns\":[", plant::to_string(unit));
    for (std::size_t c = 0; c < columns.size(); ++c) std::printf("%s\"%s\"", c ? "," : "", columns[c].c_str());
    std::printf("],\"rows\":[");
  } else {
    std::vector<std::string> columns = papers::move_columns(unit);
    columns.resize(1);  // t_s, then each axis's four
    for (std::size_t k = 1; k <= axes; ++k) {
      const std::vector<std::string> c = papers::move_columns(unit, static_cast<int>(k));
      columns.insert(columns.end(), c.begin(), c.end());
    }
    std::fputs(papers::csv_header(columns).c_str(), stdout);
  }
  for (long i = 0; i <= n; ++i) {
    row(i, r);
    if (json) {
      std::printf("%s[", i == 0 ? "" : ",");
      for (std::size_t c = 0; c < r.size(); ++c) std::printf("%s%.17g", c ? "," : "", r[c]);
      std::printf("]");
    } else {
      papers::write_sample_row(stdout, r);
    }
  }
  if (json) std::printf("]}\n");
  return kExitOk;
}

}  // namespace

int cmd_sample(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("sample", argc, argv, args); rc >= 0) return rc;
  RequestError err;
  const auto dt = args.real("--dt");
  std::optional<FigurePath> png;
  if (const int rc = parse_png_option(args, png); rc >= 0) return rc;
  if (wants_axes(args)) {
    if (png) return refuse_png_with_axes(args);
    if (!dt) return report_bad_request({"missing_option", "--dt", "--dt: required (sample period, s)"}, args.json());
    return sample_axes(args, *dt);
  }
  core::Move<double> move{};
  if (!move_from_args(args, move, err)) return report_bad_request(err, args.json());
  if (!dt) return report_bad_request({"missing_option", "--dt", "--dt: required (sample period, s)"}, args.json());
  long n = 0;
  if (!sample_count(move.duration(), *dt, n, err)) return report_bad_request(err, args.json());
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
  if (png) {
    if (static_cast<double>(n) + 1.0 > kMaxFigureSamples) {
      return report_bad_request({"too_many_samples", "--png", "--png: " + format_number(static_cast<double>(n) + 1.0) +
                                                                  " samples; a figure takes at most 1e6 (--dt larger)"},
                                args.json());
    }
    if (const int rc = write_move_png(args, move, *dt, "sample", *png); rc != kExitOk) return rc;
  }
  if (args.json()) {
    // Streamed, not built as a document; every number is finite.
    std::printf("{\"status\":\"ok\",\"unit\":\"%s\",\"columns\":[\"t\",\"position\",\"velocity\",\"acceleration\","
                "\"jerk\"],\"rows\":[",
                plant::to_string(position_unit(args)));
    for (long i = 0; i <= n; ++i) {
      const auto r = sample(i);
      std::printf("%s[%.17g,%.17g,%.17g,%.17g,%.17g]", i == 0 ? "" : ",", r[0], r[1], r[2], r[3], r[4]);
    }
    std::printf("]}\n");
    return kExitOk;
  }
  // Every sample was found finite above: the table is written whole.
  return papers::write_move_rows(stdout, move, *dt, position_unit(args))
             ? kExitOk
             : report_failure("sample", "write_failed", "cannot write the samples to stdout", false);
}

}  // namespace settle::app
