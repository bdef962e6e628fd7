// SPDX-License-Identifier: Apache-2.0
// settle demo: the README's main job (tools/demo runs it). Lists the paper scenarios, or streams
// each of them through `settle plant` and `settle stream` processes (demo.hpp) and prints the
// tables: whether each machine ended at rest, measured over CAN against the offline replay.
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "commands.hpp"
#include "commissioning.hpp"
#include "demo.hpp"
#include "io/json.hpp"
#include "options.hpp"
#include "paper_scenarios.hpp"

namespace settle::app {

namespace {

void print_list(const PaperScenarios& s, const CommissioningScenario& c) {
  std::printf("beam first mode %.9g rad/s; mass-spring-damper %.9g rad/s, zeta %.9g; belt exponents optimised from 3,4,5:",
              s.beam_omega1, s.sdof_omega, s.sdof_zeta);
  for (std::size_t i = 0; i < s.gammas_optimised.size(); ++i) std::printf("%s%.9g", i ? "," : " ", s.gammas_optimised[i]);
  std::printf("\n\n%-16s %-28s %-9s %s\n", "id", "label", "axis vmax", "options (plant, then move)");
  for (const PaperScenario& p : s.scenarios) {
    std::string args;
    for (const auto* v : {&p.plant, &p.move}) {
      for (const std::string& a : *v) args += (args.empty() ? "" : " ") + a;
    }
    std::printf("%-16s %-28s %-9g %s\n", p.id.c_str(), p.label.c_str(), p.axis_vmax, args.c_str());
  }
  std::string plant;
  for (const auto* v : {&c.plant, &c.noise}) {
    for (const std::string& a : *v) plant += (plant.empty() ? "" : " ") + a;
  }
  std::string tune;
  for (const std::string& a : c.tune) tune += (tune.empty() ? "" : " ") + a;
  std::printf("\n%s: identify against settle plant %s; tune %s; stream the tuned plan\n", c.id.c_str(), plant.c_str(),
              tune.c_str());
}

}  // namespace

int cmd_demo(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("demo", argc, argv, args); rc >= 0) return rc;
  const bool json = args.json();
  PaperScenarios scenarios;
  if (const plant::SimStatus st = paper_scenarios(scenarios); st != plant::SimStatus::ok) {
    std::fprintf(stderr, "settle demo: the scenario table could not be derived: %s\n", describe(st));
    return kExitFailure;
  }
  CommissioningScenario commissioning;
  if (const plant::SimStatus st = commissioning_scenario(commissioning); st != plant::SimStatus::ok) {
    std::fprintf(stderr, "settle demo: the commissioning scenario could not be derived: %s\n", describe(st));
    return kExitFailure;
  }
  if (args.flag("--list")) {
    if (json) {
      Json j = to_json(scenarios);
      j["commissioning"] = to_json(commissioning);
      print_json(j);
    } else {
      print_list(scenarios, commissioning);
    }
    return kExitOk;
  }
  // The processes run this very executable, wherever it was started from.
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) {
    std::fprintf(stderr, "settle demo: cannot find its own executable (/proc/self/exe): %s\n", ec.message().c_str());
    return kExitFailure;
  }
  const DemoSpec spec{self.string(), args.text_or_default("--bus"), args.text_or_default("--out")};
  DemoReport report;
  std::string why;
  if (!run_demo(spec, scenarios, commissioning, report, why)) {
    std::fprintf(stderr, "settle demo: %s\n", why.c_str());
    return kExitFailure;
  }
  if (json) {
    print_json(demo_json(report));
  } else {
    print_demo(report, stdout);
  }
  return report.ok() ? kExitOk : kExitFailure;
}

}  // namespace settle::app
