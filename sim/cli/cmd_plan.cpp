#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "json.hpp"
#include "move_options.hpp"

namespace settle::cli {

namespace {

using Fields = std::vector<std::pair<std::string, double>>;

// The numbers that define each profile, named as in SEEDS.md, shared by text and JSON output.
Fields profile_fields(const core::Profile<double>& prof) {
  Fields f;
  prof.visit([&](const auto& p) {
    using P = std::decay_t<decltype(p)>;
    if constexpr (std::is_same_v<P, core::RampCycloid<double>>) {
      const auto& q = p.params();
      f = {{"tau", q.tau},
           {"cruise", q.cruise},
           {"A", q.amplitude},
           {"A2", q.amplitude * q.c2},
           {"c2", q.c2},
           {"c3", q.c3}};
    } else if constexpr (std::is_same_v<P, core::RampVersine<double>>) {
      const auto& q = p.params();
      f = {{"tau", q.tau}, {"Y1", q.y1}, {"Y2", q.y2}, {"Y3", q.y3}};
    } else if constexpr (std::is_same_v<P, core::PseudoPoly<double>>) {
      const auto& q = p.params();
      for (std::size_t i = 0; i < q.count; ++i) f.emplace_back("gamma" + std::to_string(i), q.gammas[i]);
      for (std::size_t i = 0; i < q.count; ++i) f.emplace_back("C" + std::to_string(i), q.coeffs[i]);
    } else {
      const auto& q = p.params();
      for (std::size_t i = 0; i < q.count; ++i) {
        f.emplace_back("segment" + std::to_string(i) + "_duration", q.durations[i]);
        f.emplace_back("segment" + std::to_string(i) + "_jerk", q.jerk[i]);
      }
    }
  });
  return f;
}

void print_json(const core::Move<double>& m) {
  JsonWriter w{stdout};
  w.begin_object()
      .field("status", "ok")
      .field("profile", core::to_string(m.profile().kind()))
      .field("distance", m.distance())
      .field("duration", m.duration())
      .field("profile_duration", m.profile().duration());
  w.key("params").begin_object();
  for (const auto& [k, v] : profile_fields(m.profile())) w.field(k, v);
  w.end_object();
  const auto& pk = m.peaks();
  w.key("peaks")
      .begin_object()
      .field("velocity", pk.v)
      .field("acceleration", pk.a)
      .field("jerk", pk.j)
      .field("velocity_step", pk.velocity_step)
      .field("acceleration_step", pk.acceleration_step)
      .end_object();
  w.key("shaper").begin_object().key("impulses").begin_array();
  for (std::size_t i = 0; i < m.shaper().count; ++i) {
    w.begin_object().field("amplitude", m.shaper().amp[i]).field("time", m.shaper().time[i]).end_object();
  }
  w.end_array().end_object().end_object().finish();
}

void print_text(const core::Move<double>& m) {
  std::printf("profile      %s\n", core::to_string(m.profile().kind()));
  std::printf("distance     %.9g\n", m.distance());
  std::printf("duration     %.9g s (profile %.9g s + shaper %.9g s)\n", m.duration(), m.profile().duration(),
              m.shaper().duration());
  for (const auto& [k, v] : profile_fields(m.profile())) std::printf("  %-22s %.9g\n", k.c_str(), v);
  const auto& pk = m.peaks();
  auto show = [](double v) { return std::isfinite(v) ? std::to_string(v) : std::string{"inf (impulse)"}; };
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
  const Args args{argc, argv, kMoveValueOptions, kMoveFlagOptions};
  const bool json = args.flag("--json");
  if (!args.ok()) return report_bad_request({"bad_option", args.error_param(), args.error()}, json);
  core::MoveRequest req{};
  RequestError err;
  if (!parse_move_request(args, req, err)) return report_bad_request(err, json);
  core::Move<double> move{};
  if (!plan_move(req, move, err)) return report_bad_request(err, json);
  if (json) {
    print_json(move);
  } else {
    print_text(move);
  }
  return kExitOk;
}

}  // namespace settle::cli
