// SPDX-License-Identifier: Apache-2.0
#pragma once
// The three papers' streaming scenarios, defined once: `settle demo` streams each of them (and
// lists them with --list --json), and the end-to-end tests (tests/e2e) read that list. Each is the
// pair of `settle plant` / `settle stream` option vectors that runs it, with every constant derived
// here from the same code and constants `settle reproduce` uses (the beam's first mode, the
// mass-spring-damper's frequency and damping, seed 004's optimised exponents).
#include <cstddef>
#include <string>
#include <vector>

#include "io/json.hpp"
#include "settle/plant/status.hpp"

namespace settle::app {

// One of the three papers, as the demo names it: its authors and subject, the machine and move,
// and the two commands its scenarios compare.
struct Paper {
  std::string title;     // "Özokutan, Karadağ, Kapucu & Kütük: ramp-cycloid S-curve for ..."
  std::string machine;   // "a cantilever beam with a tip mass, moved 0.07 m; residual at the tip"
  std::string method;    // the paper's command ("S-curve")
  std::string baseline;  // what it is compared with ("3-4-5 polynomial")
};

struct PaperScenario {
  std::string id;                  // "000-scurve-0.8": a file and ctest name
  std::string label;               // "beam 0.228 s, S-curve": the run's name in the demo's tables
  std::size_t paper{0};            // index into PaperScenarios::papers
  bool baseline{false};            // the paper's baseline command (else its method)
  std::string when;                // the move time, said for a person: "0.8 × the beam's period (0.228 s)"
  std::string unit;                // the residual's unit: "m" or "rad"
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
  std::vector<Paper> papers;              // seeds 000, 001 and 004, in that order
  std::vector<PaperScenario> scenarios;   // in the demo table's order: per paper and move time,
                                          // the method, then its baseline
};

// Derives the constants and builds the table (a few milliseconds: the seed-004 optimiser runs
// once). On failure `out` is untouched.
[[nodiscard]] plant::SimStatus paper_scenarios(PaperScenarios& out);

// The table as `settle demo --list --json` prints it.
[[nodiscard]] Json to_json(const PaperScenarios& s);

}  // namespace settle::app
