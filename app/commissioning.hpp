// SPDX-License-Identifier: Apache-2.0
#pragma once
// The demo's commissioning scenario, defined once: a machine with two modes that only
// the drive process knows (`settle plant --plant modes --mode ...`, its load encoder noisy); the
// master measures them (`settle identify`, from the drive's frames alone), plans the move for
// what it measured (`settle tune --modes-from`) and streams that plan (`settle stream
// --plan-from`) to the same kind of machine. `settle demo` runs it (demo.hpp) and lists it
// (`--list --json`, which the end-to-end test e2e.commissioning reads); the judgement of a run
// (identified against true, the measured PRV) is here too, so the demo and its report agree.
//
// The modes (docs/identification.md, "where that stops"): a mode's deflection is gain / omega^2
// per unit of base acceleration, so with equal gains a mode 2.8 times faster deflects 8 times
// less. The second mode's gain is 4 so that its share of the deflection is about half the first
// one's: both stand some 40 times out of the noise (1 % of the excitation's whole peak load
// deflection, computed here by simulating the excitation on the true plant).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/json.hpp"
#include "settle/commission/uncertain_mode.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/plant/status.hpp"

namespace settle::app {

struct CommissioningScenario {
  std::string id;     // file names and the e2e test's name
  std::string label;  // the table's title
  std::vector<plant::Mode> modes;          // the truth, sorted by omega: only the drive process gets it
  double peak_deflection{0.0};           // the identify excitation's peak load deflection (m)
  double noise_counts{0.0};              // the load encoder's noise: 1 % of that, in load counts
  std::uint64_t seed{0};
  std::vector<std::string> plant;        // --plant modes --mode W,Z,G ... (settle plant; stream measures with it)
  std::vector<std::string> noise;        // --noise N --seed S (settle plant; identify on loopback)
  std::vector<std::string> identify;     // settle identify's own options (the excitation, --max-modes)
  std::vector<std::string> tune;         // settle tune's move and bound (besides --modes-from)
  // The tolerances: omega within 0.5 %, zeta within 0.01; the streamed PRV at most 1 %.
  double omega_tolerance{0.005};
  double zeta_tolerance{0.01};
  double prv_max_percent{1.0};
};

// Builds the scenario (simulates the excitation once for the noise level).
[[nodiscard]] plant::SimStatus commissioning_scenario(CommissioningScenario& out);

// The scenario as `settle demo --list --json` lists it.
[[nodiscard]] Json to_json(const CommissioningScenario& s);

// One identified mode against the true mode it is matched with (the same rank by omega).
struct ModeCheck {
  plant::Mode truth{};
  commission::UncertainMode found{};  // as `settle identify --json` reported it (io/modes_json.hpp)
  double omega_error{0.0};  // relative
  double zeta_error{0.0};   // absolute
  bool within{false};
};

// What the three processes reported, and the verdict.
struct CommissioningResult {
  std::optional<Json> identify;  // settle identify --json
  std::optional<Json> tune;      // settle tune --json
  std::optional<Json> stream;    // settle stream --plan-from --json
  std::optional<Json> plant_identify, plant_stream;  // SocketCAN: settle plant's summaries
  std::string error;             // a step that could not run, or its failure
  std::vector<ModeCheck> modes;  // filled by judge()
  bool modes_ok{false};          // as many modes as the truth, each within the tolerances
  double prv_percent{0.0};       // the stream's PRV measured from the CAN feedback (NaN: none)
  bool prv_ok{false};
  [[nodiscard]] bool ok() const { return error.empty() && modes_ok && prv_ok; }
};

// Fills the checks and the verdict from the JSON documents (an error when one is missing or not ok).
void judge(const CommissioningScenario& s, CommissioningResult& r);

}  // namespace settle::app
