// SPDX-License-Identifier: Apache-2.0
#pragma once
// The three papers' streaming scenarios, defined once: `settle demo` streams each of them (and
// lists them with --list --json), and the end-to-end tests (tests/e2e) read that list. Each is the
// pair of `settle plant` / `settle stream` option vectors that runs it, with every constant derived
// here from the same code and constants `settle reproduce` uses (the beam's first mode, the
// mass-spring-damper's frequency and damping, seed 004's optimised exponents).
#include <string>
#include <vector>

#include "io/json.hpp"
#include "settle/plant/status.hpp"

namespace settle::app {

struct PaperScenario {
  std::string id;                  // "000-scurve-0.8": a file and ctest name
  std::string label;               // "000 beam 0.8 Tn": the demo table's first column
  std::vector<std::string> plant;  // the plant's options (settle plant and settle stream)
  std::vector<std::string> move;   // the move's options (settle stream)
  double axis_vmax{0.0};           // --axis-vmax of settle stream (unit/s)
  double out_scale{0.0};           // the move's size in the units its residual is measured in
};

struct PaperScenarios {
  double beam_omega1{0.0};                // seed 000: the Table 1 beam's first mode (rad/s)
  double sdof_omega{0.0};                 // seed 001: the m-k-c system's natural frequency (rad/s)
  double sdof_zeta{0.0};                  // and its damping ratio
  std::vector<double> gammas_paper;       // seed 004: the published exponents
  std::vector<double> gammas_optimised;   // seed 004: optimised from (3, 4, 5) by the energy optimiser
  std::vector<PaperScenario> scenarios;   // in the demo table's order
};

// Derives the constants and builds the table (a few milliseconds: the seed-004 optimiser runs
// once). On failure `out` is untouched.
[[nodiscard]] plant::SimStatus paper_scenarios(PaperScenarios& out);

// The table as `settle demo --list --json` prints it.
[[nodiscard]] Json to_json(const PaperScenarios& s);

}  // namespace settle::app
