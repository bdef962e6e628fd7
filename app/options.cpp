// SPDX-License-Identifier: Apache-2.0
#include "options.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <map>
#include <set>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "io/json.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/core/profile.hpp"
#include "settle/plant/beam.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/commission/identify.hpp"
#include "settle/commission/identify_excitation.hpp"
#include "settle/plant/move_vocabulary.hpp"

namespace settle::app {

namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// A default as --help shows it: %g when that reads back as the same double, else the fewest
// significant digits that do.
std::string shown(double v) {
  char buf[32];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

std::vector<std::string> profile_names() {
  const auto names = core::profile_names();
  return {names.begin(), names.end()};
}

std::vector<std::string> shaper_names() {
  std::vector<std::string> names;
  for (const plant::ShaperName& s : plant::shaper_names()) names.emplace_back(s.name);
  return names;
}

OptionSpec real(std::string name, std::string unit, std::string def, Range r, std::string help) {
  return {.name = std::move(name), .kind = Kind::real, .unit = std::move(unit), .def = std::move(def),
          .help = std::move(help), .range = r};
}
OptionSpec integer(std::string name, std::string unit, std::string def, Range r, std::string help) {
  return {.name = std::move(name), .kind = Kind::integer, .unit = std::move(unit), .def = std::move(def),
          .help = std::move(help), .range = r};
}
OptionSpec text(std::string name, std::string def, std::string help, std::string value_name) {
  return {.name = std::move(name), .kind = Kind::text, .unit = "", .def = std::move(def), .help = std::move(help),
          .value_name = std::move(value_name)};
}
OptionSpec choice(std::string name, std::string def, std::vector<std::string> choices, std::string help) {
  return {.name = std::move(name), .kind = Kind::choice, .unit = "", .def = std::move(def), .help = std::move(help),
          .choices = std::move(choices)};
}
OptionSpec flag(std::string name, std::string help) {
  return {.name = std::move(name), .kind = Kind::flag, .unit = "", .def = "", .help = std::move(help)};
}

// " (used only by profile A, B; shaper S)", or " (not used by profile C)" when most profiles use
// design parameter p; "" when every profile does.
std::string used_by(core::Param p) {
  std::string not_using;
  std::size_t users = 0;
  core::for_each_profile([&](auto kind) {
    if (core::profile_params(kind.value).contains(p)) {
      ++users;
    } else {
      not_using += (not_using.empty() ? "" : ", ") + std::string{core::to_string(kind.value)};
    }
  });
  if (users == core::kProfileCount) return "";
  if (2 * users > core::kProfileCount) return " (not used by " + plant::users_text(not_using, "") + ")";
  return " (used only by " + plant::users_text(plant::profiles_using(p), plant::shapers_using(p)) + ")";
}

// An option whose default depends on the --timing preset: `o.def` under sim, `drive` under drive.
OptionSpec timed(OptionSpec o, std::string drive) {
  o.timing_drive = std::move(drive);
  return o;
}

// The rows, then --timing (after --bus, where it is read first), whose help lists what each preset
// sets, taken from the rows themselves: each value is stated once, in its own row.
std::vector<OptionSpec> with_timing(const std::vector<OptionSpec>& rows, const std::string& who) {
  std::string sim, drive;
  for (const OptionSpec& o : rows) {
    if (o.timing_drive.empty()) continue;
    sim += (sim.empty() ? "" : ", ") + o.name + " " + o.def;
    drive += (drive.empty() ? "" : ", ") + o.name + " " + o.timing_drive;
  }
  std::vector<OptionSpec> v = rows;
  const auto at = std::find_if(v.begin(), v.end(), [](const OptionSpec& o) { return o.name == "--bus"; });
  v.insert(at == v.end() ? v.begin() : at + 1,
           choice("--timing", "sim", {"sim", "drive"},
                  "the timeouts of " + who + ": 'sim' for the simulated drive and the master on one non-real-time, "
                  "loaded host (" + sim + "), 'drive' for a real drive on a real-time bus (" + drive +
                  "); each of these options given overrides its preset value"));
  return v;
}

// ---- the option table ------------------------------------------------------------------------

const std::vector<OptionSpec> kOutput = {
    flag("--json", "print one JSON object on stdout (errors too)"),
};

const std::vector<OptionSpec> kMove = [] {
  std::vector<OptionSpec> v = {
      choice("--profile", "", profile_names(),
             "the motion profile (required); fastest: the shortest of several searched families under the "
             "limits, a local search (docs/fastest.md: within 0.1 % of an independent optimiser on 295 of "
             "295 random problems); the plan says whether its move is proven the shortest there is (LP "
             "duality: 256 of those 300 plans are); an option below that neither it nor --shaper uses is refused "
             "(each says which use it)"),
      real("--distance", "m or rad", "", plant::move_range::distance, "signed move distance (required)"),
      real("--time", "s", "", plant::move_range::time, "move time of the unshaped profile (or give limits)"),
      real("--vmax", "unit/s", "", plant::move_range::vmax, "velocity limit"),
      real("--amax", "unit/s^2", "", plant::move_range::amax, "acceleration limit"),
      real("--jmax", "unit/s^3", "", plant::move_range::jmax, "jerk limit"),
      {.name = "--omega", .kind = Kind::real, .unit = "rad/s", .def = "the plant's fundamental (simulate, stream)",
       .help = "natural frequency the move is designed for (repeat for more modes: --profile fastest)",
       .range = plant::move_range::omega, .repeatable = true, .max_repeats = core::kMaxModes},
      {.name = "--zeta", .kind = Kind::real, .unit = "", .def = "0 (simulate, stream: the plant's)",
       .help = "damping ratio the move is designed for (one per --omega, in order, when several)",
       .range = plant::move_range::zeta, .repeatable = true, .max_repeats = core::kMaxModes},
      real("--robust", "%", "", plant::move_range::robust,
           "keep every mode's residual <= 5 % of a step's over omega (1 +- PCT/100)"),
      {.name = "--gammas", .kind = Kind::list, .unit = "", .def = "", .help = "pseudo-polynomial exponents G1,G2,... "
       "(required where used)", .range = plant::move_range::gamma, .min_items = 1, .max_items = 8,
       .value_name = "G1,G2,..."},
      {.name = "--y", .kind = Kind::list, .unit = "", .def = "computed", .help = "fractions Y1/L,Y2/L,Y3/L of the "
       "ramp + cycloid + versine command, instead of its design for the mode", .range = plant::move_range::y, .min_items = 3, .max_items = 3, .value_name = "Y1,Y2,Y3"},
      choice("--shaper", "none", shaper_names(), "input shaper convolved with the profile"),
      real("--vtol", "", "0.05", plant::move_range::vtol, "vibration tolerance of the EI shapers"),
  };
  // The design parameters: each row names the registry's parameter it gives, and its help which
  // profiles and shapers use it, both from core's registry.
  for (OptionSpec& o : v) {
    for (std::size_t i = 0; i < core::kParamCount; ++i) {
      const auto p = static_cast<core::Param>(i);
      if (p == core::Param::modes || o.name != std::string{"--"} + core::to_string(p)) continue;
      o.param = p;
      o.help += used_by(p);
    }
  }
  return v;
}();

}  // namespace

OptionGroup move_options() { return kMove; }

namespace {

// plan, sample, simulate: the move group whose distance, limits and mode also take one value per
// axis (--axes N, docs/multi_axis.md), and the coordination's own options.
const std::vector<OptionSpec> kMoveAxes = [] {
  std::vector<OptionSpec> v = kMove;
  for (OptionSpec& o : v) {
    o.per_axis = o.name == "--distance" || o.name == "--vmax" || o.name == "--amax" || o.name == "--jmax" ||
                 o.name == "--omega" || o.name == "--zeta";
  }
  return v;
}();
const std::vector<OptionSpec> kAxes = {
    integer("--axes", "", "1 (one axis, no coordination)", {1.0, static_cast<double>(core::kMaxAxes)},
            "coordinate N axes that start and end together: --distance, --omega, --zeta take N comma-separated "
            "values, --vmax, --amax, --jmax one or N (docs/multi_axis.md)"),
    choice("--sync", "path", {"path", "time"},
           "with --axes: 'path' (a straight line; every axis shaped for every axis's mode) or 'time' (each axis "
           "its own move on its own mode, one common duration; reports the deviation from the line)"),
};

// plan, sample, simulate, plant, identify: the unit of the positions they write (help's Motion group).
const std::vector<OptionSpec> kUnit = {
    choice("--unit", "m", {"m", "rad"},
           "the unit --distance and every position are in: it only names the CSV columns (position_m, "
           "velocity_m_per_s, ...; docs/csv.md) and the JSON's unit, it scales nothing; simulate and plant: "
           "for --plant modes (sdof and beam are in m, belt in rad, and refuse another)"),
};

// settle tune: the move's own options, taken from the move group (one row per option).
const std::vector<OptionSpec> kTuneMove = [] {
  std::vector<OptionSpec> v;
  for (const OptionSpec& o : kMove) {
    if (o.name == "--distance" || o.name == "--time" || o.name == "--vmax" || o.name == "--amax" || o.name == "--jmax") {
      v.push_back(o);
    }
  }
  return v;
}();

const std::vector<OptionSpec> kTune = {
    text("--modes-from", "", "the modes and their confidence intervals: the JSON `settle identify --json` prints "
                             "(at most 1 MiB, at most 4 modes)", "FILE"),
    {.name = "--mode", .kind = Kind::list, .unit = "rad/s, -, -", .def = "", .help = "a mode OMEGA,ZETA[,GAIN] "
     "instead of --modes-from (repeatable; needs --uncertainty PCT)", .range = {0.0, 0.0}, .min_items = 2,
     .max_items = 3, .repeatable = true, .max_repeats = 4,
     .item_ranges = {{1e-2, 1e6}, {0.0, 1.0, false, true}, {-1e6, 1e6}}, .value_name = "OMEGA,ZETA[,GAIN]"},
    real("--residual-max", "fraction of the unshaped residual", "0.05", {0.0, 1.0, true, true},
         "largest residual allowed anywhere in the band, relative to what an unshaped step of --distance leaves "
         "on the same mode"),
    text("--uncertainty", "ci", "the band searched: 'ci' (the intervals of --modes-from) or PCT, a percentage in "
                                "(0, 90] (also written +-PCT): omega x (1 +- PCT/100)", "ci|PCT"),
    real("--zeta-pm", "", "0.01", {0.0, 0.5}, "with --uncertainty PCT: zeta's band is zeta +- this (clipped to [0, 0.99])"),
    text("--png", "", "draw residual against frequency error for the chosen plan and the faster plans it beat "
                      "(needs gnuplot)", "FILE"),
    flag("--verbose", "list every alternative in the text report, also those not checked (slower than the chosen "
                      "plan) and not planned; without it they are counted in one line (--json always lists all)"),
};

const std::vector<OptionSpec> kPlanFrom = {
    text("--plan-from", "", "the plan `settle tune --json` or `settle plan --json` wrote: exactly that move (no move options with it)", "FILE"),
};

const std::vector<OptionSpec> kExport = {
    choice("--scalar", "float", {"double", "float", "fixed"},
           "the tables' numbers: the move's pieces in double or float, or core::fixed's integer motion"),
    text("--name", "settle_plan", "the header's C++ namespace: a C++ identifier, at most 64 characters", "N"),
    real("--counts-per-unit", "counts/unit", "1e6", {1e-3, 1e9}, "the axis's position scale"),
    integer("--period-us", "us", "1000", {100.0, 100000.0}, "the servo period the stream ticks at"),
};

// The plants' defaults as --help shows them: the plant library's own (parse_plant falls back on
// the same structs), never restated here.
const plant::SdofParams kSdof{};
const plant::BeamOptions kBeam{};
const plant::BeltParams kBelt{};

const std::vector<OptionSpec> kPlant = {
    choice("--plant", "beam", {"sdof", "beam", "belt", "modes"}, "the plant behind the drive"),
    real("--mass", "kg", shown(kSdof.mass), {1e-6, 1e6}, "sdof: mass"),
    real("--stiffness", "N/m", shown(kSdof.stiffness), {1e-6, 1e12}, "sdof: spring stiffness"),
    real("--damping", "N s/m", shown(kSdof.damping), {0.0, 1e9}, "sdof: damping coefficient (must leave zeta < 1)"),
    real("--length", "m", shown(kBeam.params.length), {1e-3, 100.0}, "beam: length"),
    real("--modulus", "Pa", shown(kBeam.params.modulus), {1.0, 1e13}, "beam: Young's modulus"),
    real("--thickness", "m", shown(kBeam.params.thickness), {1e-6, 10.0}, "beam: thickness (bending direction)"),
    real("--width", "m", shown(kBeam.params.width), {1e-6, 10.0}, "beam: width"),
    real("--beam-mass", "kg", shown(kBeam.params.beam_mass), {1e-6, 1e6}, "beam: mass of the beam"),
    real("--tip-mass", "kg", shown(kBeam.params.tip_mass), {0.0, 1e6}, "beam: tip mass"),
    integer("--modes", "", std::to_string(kBeam.modes), {1.0, static_cast<double>(plant::kMaxBeamModes)}, "beam: number of modes"),
    real("--modal-damping", "", shown(kBeam.modal_damping), {0.0, 1.0, false, true}, "beam: damping ratio of every mode"),
    real("--inertia", "kg m^2", shown(kBelt.inertia), {1e-6, 1e6}, "belt: platform inertia"),
    real("--belt-stiffness", "N/m", shown(kBelt.belt_stiffness), {1e-6, 1e12}, "belt: stiffness of each branch"),
    real("--belt-damping", "N s/m", shown(kBelt.belt_damping), {0.0, 1e9}, "belt: damping of each branch (must leave zeta < 1)"),
    real("--pulley-r", "m", shown(kBelt.pulley_r), {1e-4, 100.0}, "belt: motor pulley radius"),
    real("--pulley-R", "m", shown(kBelt.pulley_R), {1e-4, 100.0}, "belt: platform pulley radius"),
    real("--ratio", "", shown(kBelt.ratio), {1e-4, 1e4}, "belt: gear ratio z"),
    {.name = "--mode", .kind = Kind::list, .unit = "rad/s, -, -", .def = "", .help = "modes: one mode "
     "OMEGA,ZETA[,GAIN] (GAIN 1 when left out, as tune's --mode; required for --plant modes; repeatable)",
     .range = {0.0, 0.0}, .min_items = 2,
     .max_items = 3, .repeatable = true, .max_repeats = kMaxModes,
     .item_ranges = {{1e-2, 1e6}, {0.0, 1.0, false, true}, {-1e6, 1e6}}, .value_name = "OMEGA,ZETA[,GAIN]"},
};

const std::vector<OptionSpec> kDrive = {
    integer("--period-us", "us", "1000", {100.0, 100000.0}, "SYNC / drive period"),
    real("--counts-per-unit", "counts/unit", "1e6 (belt: 65536/2pi)", {1e-3, 1e9}, "motor position scale"),
    real("--load-counts-per-unit", "counts/unit", "1e6", {1e-3, 1e9}, "load position scale"),
    choice("--interp", "linear", {"linear", "cubic"}, "the drive's interpolation between setpoints"),
    choice("--drive", "ideal", {"ideal", "servo"}, "drive model: ideal tracking or a 2nd-order position loop"),
    real("--bandwidth", "Hz", "30", {1e-2, 1e3}, "servo drive: position loop natural frequency"),
    real("--servo-damping", "", "0.7", {0.0, 1.0, true, true}, "servo drive: position loop damping ratio"),
};

const std::vector<OptionSpec> kSample = {
    real("--dt", "s", "", {0.0, kMaxSeconds, true}, "sample period (required); at most 2e6 samples"),
};

// plan and sample: the move drawn.
const std::vector<OptionSpec> kMoveFigure = {
    text("--png", "", "draw the move to FILE: position, velocity, acceleration and jerk against time, each peak "
                      "dashed (gnuplot; the samples in <stem>.csv, every --dt for sample, 2000 over the move for "
                      "plan; one axis; at most 1e6 samples)",
         "FILE"),
};

const std::vector<OptionSpec> kSimulate = {
    text("--csv", "", "write the time history to FILE (at most 1e6 rows)", "FILE"),
    text("--png", "", "draw the move and the response to FILE: positions, the deviation from the final position "
                      "with the settling band, and the tail zoomed to the residual (gnuplot; data in <stem>.csv)",
         "FILE"),
    real("--dt", "s", "1e-4", {1e-7, 1.0}, "simulation grid step; at most 2e6 steps x modes"),
    real("--band", "m or rad", "5 % of an unshaped step's residual", {0.0, 1e6, true}, "settling band"),
    real("--tail", "s", "3 periods of the slowest mode", {0.0, kMaxSeconds},
         "time simulated after the move; move + tail at most 3600 s"),
    flag("--sensitivity", "also report the 5 % insensitivity width on the fundamental mode"),
};

// simulate and stream: a change of the move mid-way (docs/online.md).
const std::vector<OptionSpec> kOnline = {
    real("--halt-at", "s", "", {0.0, kMaxSeconds},
         "halt the move at T s from its start (T within the move): blend to rest within --vmax/--amax/--jmax "
         "(else the move's own peaks; a trapezoid's jerk: amax x omega), its design mode left at rest "
         "(docs/online.md); with --axes N every moving axis at the same T, with --sync path on the line "
         "(docs/multi_axis.md)"),
    text("--retarget-at", "", "at T s from the move's start (T within the move), blend to NEW_DISTANCE "
         "(m or rad, -1e6..1e6) instead, likewise; with --axes N one NEW_DISTANCE per axis, comma-separated; "
         "stream: T rounds to whole periods, at least 3", "T:NEW_DISTANCE[,...]"),
};

// --strict, beside every --eds.
OptionSpec strict_eds() {
  return flag("--strict", "refuse the --eds file at the first deviation the reader tolerates (otherwise each is "
                          "printed on stderr as a warning naming the section and key)");
}

const std::vector<OptionSpec> kStreamRows = {
    text("--bus", "vcan0", "SocketCAN interface, or 'loopback' (in-process drive, virtual time)", "IFACE"),
    choice("--scalar", "double", {"double", "float", "fixed"},
           "the loop's evaluation: the move in double or float, or the integer-only fixed-point plan"),
    integer("--node", "", "1", {1.0, 127.0}, "the drive's CANopen node id"),
    {.name = "--nodes", .kind = Kind::list, .unit = "", .def = "1,2,...,N",
     .help = "with --axes N: the drives' CANopen node ids, one per axis in axis order, distinct whole numbers",
     .range = {1.0, 127.0}, .min_items = 1, .max_items = core::kMaxAxes, .value_name = "N1,N2,..."},
    real("--axis-vmax", "unit/s", "1.5 x the move's peak velocity, or a change's --vmax if higher", {0.0, 1e9, true},
         "the loop's step guard: largest velocity one setpoint step may imply (a halt or retarget whose blend may "
         "go faster is refused)"),
    real("--settle-time", "s", "1", {0.0, 600.0, true, true}, "time streamed after the move"),
    integer("--rt-priority", "", "0 (no SCHED_FIFO)", {0.0, 99.0}, "SCHED_FIFO priority of the loop"),
    text("--eds", "", "the drive's EDS/DCF: start-up configures and verifies the drive from it (its PDO mapping, "
                      "periods, identity); with --bus loopback the simulated drive is the one it describes", "FILE"),
    strict_eds(),
    text("--load-feedback", "", "with --eds: the drive's object that measures the load (or any vibration), "
         "INDEX:SUB (INDEX 0x1000..0xFFFF, SUB 0..255; an INTEGER32 the EDS lets be mapped), mapped into a TPDO; "
         "default: 0x2000:0 on Settle's own drive, else none (residual, PRV and at-rest are then not measured); "
         "with --bus loopback another vendor's simulated drive serves its load position there",
         "INDEX:SUB"),
    choice("--pm-qos", "on", {"on", "off"},
           "hold /dev/cpu_dma_latency at 0 us while the loop runs on a CAN interface (CPUs stay out of deep "
           "idle states: lower wake-up latency, more power)"),
    timed(integer("--heartbeat-ms", "ms", "2000", {10.0, 10000.0}, "the drive's heartbeat timeout at the loop"), "500"),
    integer("--bitrate", "bit/s", "1000000", {10000.0, 1000000.0},
            "the bus's classic CAN bit rate: a SYNC period must hold the SYNC and every axis's PDOs with "
            "worst-case bit stuffing, else refused (docs/multi_axis.md)"),
    timed(integer("--sdo-timeout-ms", "ms", "5000", {1.0, 60000.0}, "timeout of each start-up SDO"), "1000"),
    timed(integer("--feedback-timeout-periods", "periods", "250", {0.0, 65535.0},
                  "SYNCs in a row without the drive's feedback before the loop halts the axis (0 = off)"),
          "10"),
    text("--log", "", "write the loop's tick log as CSV to FILE", "FILE"),
    text("--candump", "", "write every frame the loop sends and receives as a candump log to FILE", "FILE"),
    text("--feedback-log", "", "write commanded and measured motion per period as CSV to FILE", "FILE"),
};
const std::vector<OptionSpec> kStream = with_timing(kStreamRows, "the loop");

// The simulated drive's load encoder noise: settle plant's, and settle identify's in-process drive.
const std::vector<OptionSpec> kLoadNoise = {
    real("--noise", "load counts", "0", {0.0, 1e6},
         "white noise on the simulated drive's load-side feedback, standard deviation (identify: --bus loopback)"),
    integer("--seed", "", "1", {0.0, 4294967295.0}, "seed of --noise"),
};

// settle identify: the rows it shares with stream (where and how the loop runs), taken from
// kStream so that each is declared once, and its own: the excitation and the estimator.
std::vector<OptionSpec> rows_of(const std::vector<OptionSpec>& from, std::initializer_list<std::string_view> names) {
  std::vector<OptionSpec> v;
  for (const std::string_view n : names) {
    for (const OptionSpec& o : from) {
      if (o.name == n) v.push_back(o);
    }
  }
  return v;
}
const std::vector<OptionSpec> kIdentifyLoop =
    rows_of(kStream, {"--bus", "--node", "--eds", "--strict", "--load-feedback", "--timing", "--heartbeat-ms", "--sdo-timeout-ms",
                      "--feedback-timeout-periods", "--rt-priority", "--pm-qos", "--candump"});
const std::vector<OptionSpec> kIdentify = {
    integer("--max-modes", "", "3", {1.0, static_cast<double>(commission::kMaxIdentifyModes)},
            "the most modes to identify (fewer are reported when fewer stand out of the noise)"),
    real("--distance", "m or rad", "0.01", {0.0, 1e3, true}, "excitation: distance of its jerk-limited move"),
    real("--vmax", "unit/s", "0.1", {0.0, 1e6, true}, "excitation: velocity limit"),
    real("--amax", "unit/s^2", "5", {0.0, 1e9, true}, "excitation: acceleration limit"),
    real("--jmax", "unit/s^3", "5000", {0.0, 1e12, true},
         "excitation: jerk limit (amax / jmax is its jerk phase: shorter excites higher modes)"),
    integer("--train", "", std::to_string(commission::kDefaultTrainRoundTrips), {0.0, static_cast<double>(commission::kMaxTrainRoundTrips)},
            "excitation: round trips of the move before the last one, with varied gaps (more acceleration steps: "
            "heavily damped modes are measured better; 0: the move alone)"),
    real("--hold", "s", "4", {0.5, 600.0}, "excitation: time recorded at rest after the move (the free response); with the move at most 120 000 periods"),
    text("--png", "", "draw the measured response and the fitted model (time and frequency) to FILE (gnuplot)",
         "FILE"),
};

const std::vector<OptionSpec> kPlantNodeRows = {
    text("--bus", "vcan0", "SocketCAN interface", "IFACE"),
    integer("--node", "", "1", {1.0, 127.0}, "this drive's CANopen node id"),
    integer("--heartbeat-ms", "ms", "100", {10.0, 10000.0}, "heartbeat producer period"),
    timed(integer("--sync-loss-periods", "periods", "250", {1.0, 255.0}, "SYNC/RPDO periods tolerated before a fault"),
          "3"),
    text("--eds", "hal/eds/settle_drive.eds",
         "the drive to simulate: its objects, identity, defaults and PDO mappings (hal/eds has four); "
         "--heartbeat-ms and --sync-loss-periods (or --timing), when given, override its 0x1017 and 0x2001",
         "FILE"),
    strict_eds(),
    text("--load-feedback", "", "with --eds of another vendor's drive: the object this drive serves its load "
         "position in, INDEX:SUB (0x2000:0 or 0x2002..0x5FFF, an INTEGER32 the EDS lets be mapped: the master's "
         "--load-feedback); default none (it reports no load position)",
         "INDEX:SUB"),
    text("--log", "", "write one CSV row per SYNC to FILE", "FILE"),
    real("--duration", "s", "0 (until SIGINT/SIGTERM)", {0.0, 604800.0}, "run time"),
};
const std::vector<OptionSpec> kPlantNode = with_timing(kPlantNodeRows, "the drive");

// settle drive: the bus and node every subcommand talks to, the object read or written.
const std::vector<OptionSpec> kDriveBus = {
    text("--bus", "vcan0", "SocketCAN interface, or 'loopback' (the simulated drive in this process)", "IFACE"),
    integer("--timeout-ms", "ms", "1000", {1.0, 60000.0}, "timeout of each SDO request (scan: of each batch; nmt: the wait for the heartbeat)"),
    text("--eds", "", "the drive's EDS/DCF: read/write take --type from it, info names the mapped objects, config "
                      "applies what streaming needs (required there); with --bus loopback the simulated drive is the "
                      "one it describes", "FILE"),
    strict_eds(),
};
const std::vector<OptionSpec> kDriveNodeId = {
    integer("--node", "", "1", {1.0, 127.0}, "the drive's CANopen node id"),
};
const std::vector<OptionSpec> kDriveObject = [] {
  OptionSpec index = integer("--index", "", "", {1.0, 65535.0}, "the object's index, e.g. 0x6041 (required)");
  index.hex = true;
  index.value_name = "INDEX";
  OptionSpec sub = integer("--sub", "", "0", {0.0, 255.0}, "the object's sub-index");
  sub.hex = true;
  return std::vector<OptionSpec>{
      index, sub,
      choice("--type", "", {"u8", "u16", "u32", "i8", "i16", "i32", "string"},
             "the object's data type (required unless --eds or CiA 301/402 gives it; refused when they give "
             "another): unsigned/signed 8/16/32-bit integer, or a string"),
  };
}();
const std::vector<OptionSpec> kDriveValue = {
    text("--value", "", "the value to write (required): an integer in the range of --type (or 0x hex), or the "
                        "string's text", "V"),
};

const std::vector<OptionSpec> kReproduce = {
    text("--out", "", "write the experiment's CSV files and PNG figures to DIR", "DIR"),
};

const std::vector<OptionSpec> kDemo = {
    text("--bus", "vcan0",
         "SocketCAN interface for the drive and loop processes, or 'loopback' (one process per run, virtual time)",
         "IFACE"),
    text("--out", "demo", "write every run's JSON, logs, CSV and the plots to DIR", "DIR"),
    flag("--list", "print the paper scenarios and exit (with --json: with the constants they derive from)"),
};

const std::string kDriveNotes =
    "With --bus loopback the simulated drive (hal's DriveNode: the --eds drive, or the default configuration) runs in "
    "this process. "
    "Exit 1 when the bus cannot be opened, the drive does not answer within --timeout-ms, or it aborts the "
    "transfer (the CiA 301 abort code and its meaning are printed), or (write) the value reads back different.";

const std::vector<CommandSpec> kCommands = {
    {.name = "plan", .summary = "plan a move and print it (text or --json)", .usage = "",
     .groups = {kMoveAxes, kUnit, kAxes, kMoveFigure, kOutput},
     .example = "settle plan --profile scurve --distance 0.1 --time 0.5 --omega 22"},
    {.name = "sample",
     .summary = "plan a move and print position, velocity, acceleration, jerk every --dt (CSV, or --json)",
     .usage = "",
     .groups = {kMoveAxes, kUnit, kAxes, kPlanFrom, kSample, kMoveFigure, kOutput},
     .notes = "Bounds: at most 2e6 samples (move duration / --dt); the move at most 3600 s.",
     .example = "settle sample --profile scurve --distance 0.1 --time 0.5 --omega 22 --dt 0.001"},
    {.name = "simulate",
     .summary = "run a move on a plant (sdof, beam, belt, modes): residual, PRV, energy",
     .usage = "",
     .groups = {kMoveAxes, kUnit, kAxes, kPlant, kSimulate, kOnline, kOutput},
     .notes = "Bounds: move + tail at most 3600 s; grid steps ((move + tail) / --dt) x modes at most 2e6; with --csv "
              "at most 1e6 rows; at most 64 --mode.",
     .example = "settle simulate --plant beam --profile scurve --distance 0.07 --time 0.228 --omega 22.05"},
    {.name = "reproduce",
     .summary = "rerun a paper's experiment (000, 001, 004) as tables, CSV and plots",
     .usage = "000|001|004",
     .groups = {kReproduce, kOutput},
     .positional_choices = {"000", "001", "004"},
     .example = "settle reproduce 004 --out figures"},
    {.name = "plant",
     .summary = "run the simulated CiA 402 drive with a plant behind it on a CAN bus",
     .usage = "",
     .groups = {kPlantNode, kUnit, kPlant, kDrive, kLoadNoise, kOutput},
     .notes = "Exit 1 when the bus cannot be opened or the drive faulted.",
     .example = "settle plant --bus vcan0 --plant modes --mode 25,0.02,1 --mode 70,0.05,4"},
    {.name = "stream",
     .summary = "stream a move to a drive over CAN and measure the residual vibration",
     .usage = "",
     .groups = {kStream, kPlanFrom, kMoveAxes, kAxes, kPlant, kDrive, kOnline, kOutput},
     .notes = "Bounds: move + settle time at most 3600 s and at most 1e6 periods (5 s start-up included); "
              "setpoints must fit in 32-bit counts. With --axes N: nodes 1..N (or --nodes), every axis on its own "
              "copy of the plant options' plant, all started on the same SYNC; not with --node or --plan-from; "
              "--halt-at and --retarget-at change every axis in the same period; --log and --feedback-log are axis 1's. Exit 1 when the bus cannot be "
              "opened or the move did not complete.",
     .example = "settle stream --bus loopback --plant beam --profile scurve --distance 0.07 --time 0.228 "
                "--omega 22.05 --axis-vmax 1"},
    {.name = "tune",
     .summary = "the fastest plan whose residual stays within --residual-max over the modes' uncertainty band",
     .usage = "",
     .groups = {kTuneMove, kTune, kOutput},
     .notes = "Give --modes-from or --mode, and --time or limits (--vmax, --amax, --jmax). Every registered profile "
              "is tried alone and with ZV, ZVD, EI and the two- and three-hump EI composed over the modes, designed at the nominal modes and "
              "retuned within the band (docs/tuning.md). Bounds: at most 4 modes; a search too fine to bound "
              "(omega_hi x move duration too large) is refused (too_much_work). No plan within the bound: exit 2, "
              "no_feasible_plan.",
     .example = "settle tune --mode 12.566,0.03 --uncertainty 10 --distance 0.1 --time 0.5"},
    {.name = "export",
     .summary = "print a plan file's move as a C++ header of constant tables that firmware streams without the planner",
     .usage = "",
     .groups = {kPlanFrom, kExport, kOutput},
     .notes = "--plan-from is required. The header (docs/export.md) includes settle/core/exported_plan.hpp and "
              "defines, in namespace --name, kPlan and Stream: Stream{kPlan, origin}.next(last) gives one target "
              "in counts per tick; with --json the header is the \"header\" string of one JSON object. Bounds: the "
              "move at most 2^30 periods, its distance within 32-bit counts. Exit 1 when the header cannot be "
              "written.",
     .example = "settle export --plan-from tune.json --scalar float --name pick_move"},
    {.name = "identify",
     .summary = "excite the axis through the loop and the bus, and estimate the machine's modes from the drive's feedback",
     .usage = "",
     .groups = {kIdentifyLoop, kUnit, kIdentify, kLoadNoise, kPlant, kDrive, kOutput},
     .notes = "The excitation is one jerk-limited move of --distance within --vmax/--amax/--jmax, then --hold s at "
              "rest; it lasts at most 600 s, the record (excitation + hold) holds at most 120 000 "
              "samples (2 min at --period-us 1000), and it must fit 32-bit counts. The plant options describe "
              "the simulated drive's machine (--bus loopback); the estimate uses only the drive's frames. "
              "Exit 1 when the drive never enables, no load-side feedback is mapped, the feedback is incomplete, or "
              "the response is too small to fit (noise-dominated).",
     .example = "settle identify --bus loopback --plant modes --mode 25,0.02,1 --mode 70,0.05,4"},
    {.name = "drive info",
     .summary = "read a drive's identity, strings and PDO configuration over SDO",
     .usage = "",
     .groups = {kDriveBus, kDriveNodeId, kOutput},
     .notes = kDriveNotes,
     .example = "settle drive info --bus loopback"},
    {.name = "drive read",
     .summary = "read one object of a drive's dictionary over SDO",
     .usage = "",
     .groups = {kDriveBus, kDriveNodeId, kDriveObject, kOutput},
     .notes = kDriveNotes,
     .example = "settle drive read --bus loopback --index 0x6041"},
    {.name = "drive write",
     .summary = "write one object of a drive's dictionary over SDO, then read it back",
     .usage = "",
     .groups = {kDriveBus, kDriveNodeId, kDriveObject, kDriveValue, kOutput},
     .notes = kDriveNotes,
     .example = "settle drive write --bus loopback --index 0x6065 --value 10000"},
    {.name = "drive config",
     .summary = "configure and verify what streaming needs, from the drive's EDS (--eds), and print what changed",
     .usage = "",
     .groups = {kDriveBus, kDriveNodeId, kOutput},
     .notes = "Runs the master's start-up: device type and identity checked, mode, periods, heartbeat and PDO "
              "mapping written, each write read back; the drive is left pre-operational. Exit 1 when the drive "
              "cannot stream (the object is named), does not answer, aborts, or a written value reads back "
              "different.",
     .example = "settle drive config --bus loopback --eds settle_drive.eds"},
    {.name = "drive nmt",
     .summary = "send a CiA 301 NMT command to one node and report the state its heartbeat then carries",
     .usage = "start|stop|preop|reset|reset-comm",
     .groups = {kDriveBus, kDriveNodeId, kOutput},
     .positional_choices = {"start", "stop", "preop", "reset", "reset-comm"},
     .positional_name = "command",
     .notes = "start (0x01) operational, stop (0x02) stopped, preop (0x80) pre-operational, reset (0x81) reset "
              "node, reset-comm (0x82) reset communication. One node only: --node 0 (all nodes) is refused, "
              "since one node's heartbeat cannot confirm what every node did. After sending, waits at most "
              "--timeout-ms for the node's heartbeat (0x700 + node) to carry the new state (a reset: its "
              "boot-up message). No heartbeat in that time (producer heartbeat 0x1017 off): exit 0, the state "
              "reported not confirmed. Exit 1 when the bus cannot be opened, or the node's heartbeats go on "
              "carrying another state.",
     .example = "settle drive nmt stop --bus loopback --node 1"},
    {.name = "drive scan",
     .summary = "list the node ids 1..127 that answer an SDO read of 0x1000, with their device types",
     .usage = "",
     .groups = {kDriveBus, kOutput},
     .notes = "Asks 16 nodes at a time, each batch waiting at most --timeout-ms; with --bus loopback the simulated "
              "drive is node 1. Exit 1 when the bus cannot be opened.",
     .example = "settle drive scan --bus loopback"},
    {.name = "demo",
     .summary = "stream every paper scenario to the simulated drive and verify the machine ends at rest",
     .usage = "",
     .groups = {kDemo, kOutput},
     .notes = "Runs settle plant and settle stream as processes (tools/demo brings vcan0 up first). Exit 1 when the "
              "bus cannot be opened or a scenario did not complete.",
     .example = "settle demo --bus vcan0 --out demo-out"},
};

const OptionSpec kHelp = flag("--help", "print this help and exit");

std::string value_name(const OptionSpec& o) {
  if (!o.value_name.empty()) return o.value_name;
  switch (o.kind) {
    case Kind::real: return "NUM";
    case Kind::integer: return "INT";
    case Kind::text: return "TEXT";
    case Kind::choice: return "NAME";
    case Kind::list: return "LIST";
    case Kind::flag: return "";
  }
  return "";
}

std::string range_text(const OptionSpec& o, const Range& r) {
  if (o.kind == Kind::integer) return num(r.lo) + ".." + num(r.hi);
  return r.text();
}

// What a valid value looks like, for help and for error messages.
std::string expectation(const OptionSpec& o) {
  const std::string unit = o.unit.empty() ? "" : " " + o.unit;
  switch (o.kind) {
    case Kind::real: return "a number in " + range_text(o, o.range) + unit;
    case Kind::integer: return "a whole number in " + range_text(o, o.range) + unit + (o.hex ? " (or 0x hex)" : "");
    case Kind::text: return "a non-empty " + value_name(o);
    case Kind::choice: {
      std::string s = "one of ";
      for (std::size_t i = 0; i < o.choices.size(); ++i) s += (i ? ", " : "") + o.choices[i];
      return s;
    }
    case Kind::list: {
      std::string s = o.min_items == o.max_items ? std::to_string(o.min_items)
                                                 : std::to_string(o.min_items) + " to " + std::to_string(o.max_items);
      s += " comma-separated numbers";
      if (o.item_ranges.empty()) {
        s += ", each in " + o.range.text();
      } else {
        s += " in ";
        for (std::size_t i = 0; i < o.item_ranges.size(); ++i) s += (i ? ", " : "") + o.item_ranges[i].text();
      }
      if (!o.unit.empty()) s += " (" + o.unit + ")";
      return s;
    }
    case Kind::flag: return "no value";
  }
  return "";
}

// ---- parsing -------------------------------------------------------------------------------

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

bool looks_like_number(const std::string& s) {
  double v = 0.0;
  return parse_real(s, v);
}

bool fail_with(RequestError& err, std::string code, const std::string& param, std::string message) {
  err = {std::move(code), param, std::move(message)};
  return false;
}

// A hexadecimal integer "0x1A2b" (hex options only); false when `v` is not one.
bool parse_hex(const std::string& v, long long& out) {
  if (v.size() < 3 || v[0] != '0' || (v[1] != 'x' && v[1] != 'X')) return false;
  unsigned long long u = 0;
  const auto [p, ec] = std::from_chars(v.data() + 2, v.data() + v.size(), u, 16);
  if (ec != std::errc{} || p != v.data() + v.size() || u > 0x7FFF'FFFF'FFFF'FFFFULL) return false;
  out = static_cast<long long>(u);
  return true;
}

// One number of option `o` in `r`: the parser's check, and check_value's.
bool check_number(const OptionSpec& o, const std::string& v, const Range& r, double& x, const std::string& want,
                  RequestError& err) {
  const std::string& n = o.name;
  if (o.kind == Kind::integer) {
    long long i = 0;
    if (!parse_integer(v, i) && !(o.hex && parse_hex(v, i))) {
      double d = 0.0;
      if (!parse_real(v, d)) return fail_with(err, "bad_number", n, n + ": '" + v + "' is not a number" + want);
      if (!std::isfinite(d)) return fail_with(err, "non_finite_input", n, n + ": '" + v + "' is not finite" + want);
      if (d == std::floor(d) && !r.contains(d)) {
        return fail_with(err, "out_of_range", n, n + ": " + v + " is out of range" + want);
      }
      return fail_with(err, "not_an_integer", n, n + ": '" + v + "' is not a whole number" + want);
    }
    x = static_cast<double>(i);
  } else {
    if (!parse_real(v, x)) return fail_with(err, "bad_number", n, n + ": '" + v + "' is not a number" + want);
    if (!std::isfinite(x)) return fail_with(err, "non_finite_input", n, n + ": '" + v + "' is not finite" + want);
  }
  if (!r.contains(x)) return fail_with(err, "out_of_range", n, n + ": " + v + " is out of range" + want);
  return true;
}

}  // namespace

struct Parser {
  const CommandSpec& c;
  std::vector<const OptionSpec*> specs;
  ParsedArgs& out;
  RequestError& err;

  const OptionSpec* find(std::string_view name) const {
    for (const OptionSpec* s : specs) {
      if (s->name == name) return s;
    }
    return nullptr;
  }

  bool fail(std::string code, std::string param, std::string message) {
    err = {std::move(code), std::move(param), std::move(message)};
    return false;
  }

  void unknown(const std::string& name) {
    const std::string near = nearest_option(c, name);
    fail("bad_option", name,
         name + ": unknown option for settle " + c.name + (near.empty() ? "" : " (did you mean " + near + "?)"));
  }

  // Checks one value of option `o` and records it.
  bool validate(const OptionSpec& o, const std::string& v) {
    const std::string& n = o.name;
    const std::string want = "; expected " + expectation(o);
    switch (o.kind) {
      case Kind::flag: return true;
      case Kind::text:
        if (v.empty()) return fail("missing_value", n, n + ": needs a non-empty value" + want);
        out.raw_[n].push_back(v);
        return true;
      case Kind::choice:
        if (std::find(o.choices.begin(), o.choices.end(), v) == o.choices.end()) {
          return fail("unknown_" + n.substr(2), n, n + ": unknown " + n.substr(2) + " '" + v + "'" + want);
        }
        out.raw_[n].push_back(v);
        return true;
      case Kind::real:
        if (o.per_axis && v.find(',') != std::string::npos) return per_axis(o, v, want);
        [[fallthrough]];
      case Kind::integer: {
        double x = 0.0;
        if (!number(o, v, o.range, x, want)) return false;
        out.raw_[n].push_back(v);
        out.numbers_[n].push_back(x);
        if (o.per_axis) out.lists_[n].push_back({x});
        return true;
      }
      case Kind::list: {
        std::vector<double> items;
        const auto range_of = [&](std::size_t i) -> const Range& {
          return o.item_ranges.empty() ? o.range : o.item_ranges[i];
        };
        if (!comma_numbers(o, v, o.max_items, "too many items", range_of, want, items)) return false;
        if (items.size() < o.min_items) return fail("bad_list", n, n + ": too few items in '" + v + "'" + want);
        out.raw_[n].push_back(v);
        out.lists_[n].push_back(std::move(items));
        return true;
      }
    }
    return true;
  }

  // A per-axis real given as a comma list of up to kMaxAxes numbers, each in the option's range:
  // recorded as a list only (a single number is recorded as a number and as a list of one).
  bool per_axis(const OptionSpec& o, const std::string& v, const std::string& want) {
    std::vector<double> items;
    const std::string too_many = "more than " + std::to_string(core::kMaxAxes) + " values";
    if (!comma_numbers(o, v, core::kMaxAxes, too_many, [&](std::size_t) -> const Range& { return o.range; }, want,
                       items)) {
      return false;
    }
    out.raw_[o.name].push_back(v);
    out.lists_[o.name].push_back(std::move(items));
    return true;
  }

  // The comma-separated numbers of `v`: no empty item, at most `max_items` (else "<too_many> in
  // 'v'"), item i checked in range_of(i).
  template <typename RangeOf>
  bool comma_numbers(const OptionSpec& o, const std::string& v, std::size_t max_items, const std::string& too_many,
                     RangeOf&& range_of, const std::string& want, std::vector<double>& items) {
    const std::string& n = o.name;
    std::size_t b = 0;
    while (true) {
      const std::size_t e = v.find(',', b);
      const std::string item = v.substr(b, e == std::string::npos ? std::string::npos : e - b);
      if (item.empty()) return fail("bad_list", n, n + ": empty item in '" + v + "'" + want);
      if (items.size() >= max_items) return fail("bad_list", n, n + ": " + too_many + " in '" + v + "'" + want);
      double x = 0.0;
      if (!number(o, item, range_of(items.size()), x, want)) return false;
      items.push_back(x);
      if (e == std::string::npos) break;
      b = e + 1;
    }
    return true;
  }

  bool number(const OptionSpec& o, const std::string& v, const Range& r, double& x, const std::string& want) {
    return check_number(o, v, r, x, want, err);
  }

  // What the command line says, option by option, in the order given.
  struct Given {
    std::vector<std::string> order;                        // option names, once per occurrence
    std::map<std::string, std::vector<std::string>> values;  // each option's values, in order
    std::string positional;
    bool have_positional{false};
  };

  // The command line, read in stages: --json and --help first (they change how anything else is
  // reported), then the tokens, how often each option was given, each value, the positional
  // argument, and the table's defaults for what was not given.
  ParseOutcome run(int argc, char** argv) {
    for (int i = 0; i < argc; ++i) {
      if (std::string_view{argv[i]} == "--json") out.json_ = true;
    }
    for (int i = 0; i < argc; ++i) {
      const std::string_view a = argv[i];
      if (a == "--help" || a == "-h") {
        std::fputs(command_help(c).c_str(), stdout);
        return ParseOutcome::help_printed;
      }
    }
    Given given;
    if (!tokenise(argc, argv, given) || !check_repeats(given) || !validate_all(given) || !take_positional(given)) {
      return ParseOutcome::error;
    }
    apply_defaults();
    return ParseOutcome::ok;
  }

  // The tokens, in command-line order: "--name value" or "--name=value" (a value that starts with
  // '-', "-inf" or "-1e3", is a value unless it is one of the command's options), a flag, or the
  // positional argument. Unknown options, a missing value and a value given to a flag are found
  // here, in command-line order.
  bool tokenise(int argc, char** argv, Given& given) {
    std::string last_option;
    for (int i = 0; i < argc; ++i) {
      const std::string a = argv[i];
      if (a.size() > 2 && a.rfind("--", 0) == 0) {
        const std::size_t eq = a.find('=');
        const std::string name = a.substr(0, eq);
        const OptionSpec* o = find(name);
        if (o == nullptr) {
          unknown(name);
          return false;
        }
        last_option = name;
        given.order.push_back(name);
        if (o->kind == Kind::flag) {
          if (eq != std::string::npos) return fail("bad_option", name, name + ": takes no value");
          continue;
        }
        std::string value;
        if (eq != std::string::npos) {
          value = a.substr(eq + 1);
        } else {
          const bool next_is_option = i + 1 < argc && std::string_view{argv[i + 1]}.rfind("--", 0) == 0 &&
                                      find(std::string{argv[i + 1]}.substr(0, std::string{argv[i + 1]}.find('='))) != nullptr;
          if (i + 1 >= argc || next_is_option) {
            return fail("missing_value", name, name + ": needs a value; expected " + expectation(*o));
          }
          value = argv[++i];
        }
        if (value.empty()) {  // "--x=": say what is wrong with the empty value
          validate(*o, value);
          return false;
        }
        given.values[name].push_back(value);
      } else if (a.size() > 1 && a[0] == '-' && !looks_like_number(a)) {
        unknown(a);
        return false;
      } else if (!c.positional_choices.empty() && !given.have_positional && last_option.empty()) {
        given.have_positional = true;
        given.positional = a;
      } else {
        std::string who = last_option.empty() ? "--" + c.name : last_option;  // one word: "--drive-scan"
        std::replace(who.begin(), who.end(), ' ', '-');
        return fail("bad_option", who, who + ": unexpected argument '" + a + "' after it");
      }
    }
    return true;
  }

  // Each option given at most once unless repeatable, and a repeatable one at most max_repeats times.
  bool check_repeats(const Given& given) {
    std::map<std::string, std::size_t> seen;
    for (const std::string& name : given.order) {
      const OptionSpec& o = *find(name);
      const std::size_t k = seen[name]++;
      if (k == 1 && !o.repeatable) {
        return fail("duplicate_option", name, name + ": given more than once (it takes one value)");
      }
      if (o.repeatable && k >= o.max_repeats) {
        return fail("too_many_values", name, name + ": at most " + std::to_string(o.max_repeats) + " allowed");
      }
    }
    return true;
  }

  // Every value of each option, the options in the order first given; a flag is recorded as given.
  bool validate_all(Given& given) {
    std::set<std::string> done;
    for (const std::string& name : given.order) {
      if (!done.insert(name).second) continue;  // already validated all its values
      const OptionSpec& o = *find(name);
      if (o.kind == Kind::flag) {
        out.raw_[name].push_back("");
        continue;
      }
      for (const std::string& v : given.values[name]) {
        if (!validate(o, v)) return false;
      }
    }
    return true;
  }

  bool take_positional(const Given& given) {
    if (c.positional_choices.empty()) return true;
    const std::string& what = c.positional_name;
    if (!given.have_positional) {
      return fail("missing_" + what, what, what + ": required (settle " + c.name + " " + c.usage + " [options])");
    }
    if (std::find(c.positional_choices.begin(), c.positional_choices.end(), given.positional) ==
        c.positional_choices.end()) {
      return fail("unknown_" + what, what, what + ": unknown " + what + " '" + given.positional + "' (" + c.usage + ")");
    }
    out.positional_ = given.positional;
    return true;
  }

  // The table's default of every option not given, under the --timing preset in force.
  void apply_defaults() {
    const OptionSpec* timing = find("--timing");
    const std::string preset = out.has("--timing") ? out.raw_["--timing"].front() : timing ? timing->def : "sim";
    for (const OptionSpec* o : specs) {
      if (out.has(o->name) || o->kind == Kind::flag) continue;
      out.defaults_[o->name] = preset == "drive" && !o->timing_drive.empty() ? o->timing_drive : o->def;
    }
  }
};

const char* counts_reach_exceeded(double reach, double counts_per_unit, double load_counts_per_unit) {
  const double span = std::fabs(reach) * 2.0 + 1.0;
  if (span * counts_per_unit > 2e9) return "--counts-per-unit";
  if (span * load_counts_per_unit > 2e9) return "--load-counts-per-unit";
  return nullptr;
}

std::string format_number(double v) { return num(v); }

bool check_value(const OptionSpec& o, const std::string& value, double& number, RequestError& err) {
  if (o.kind != Kind::real && o.kind != Kind::integer) {
    if (!value.empty()) return true;
    return fail_with(err, "missing_value", o.name, o.name + ": needs a non-empty value; expected " + expectation(o));
  }
  return check_number(o, value, o.range, number, "; expected " + expectation(o), err);
}

std::string OptionSpec::describe() const {
  std::string s = help;
  std::string meta;
  if (!unit.empty() && kind == Kind::text) meta += "unit " + unit;
  if (!def.empty()) meta += (meta.empty() ? "" : "; ") + std::string{"default "} + def;
  if (!timing_drive.empty()) meta += " (--timing drive: " + timing_drive + ")";
  if (kind != Kind::flag && kind != Kind::text) meta += (meta.empty() ? "" : "; ") + expectation(*this);
  if (repeatable) meta += "; at most " + std::to_string(max_repeats);
  if (per_axis) meta += "; with --axes N: one per axis, comma-separated";
  if (!meta.empty()) s += " [" + meta + "]";
  return s;
}

std::span<const CommandSpec> commands() { return kCommands; }

const CommandSpec* find_command(std::string_view name) {
  for (const CommandSpec& c : kCommands) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

std::vector<const OptionSpec*> options_of(const CommandSpec& c) {
  std::vector<const OptionSpec*> v;
  for (const OptionGroup& g : c.groups) {
    for (const OptionSpec& o : g) v.push_back(&o);
  }
  v.push_back(&kHelp);
  return v;
}

std::string nearest_option(const CommandSpec& c, std::string_view given) {
  std::string best;
  std::size_t best_d = 0;
  for (const OptionSpec* o : options_of(c)) {
    const std::size_t d = edit_distance(given, o->name);
    if (best.empty() || d < best_d) {
      best = o->name;
      best_d = d;
    }
  }
  // Close enough to be a typo: at most a third of the name changed.
  return best_d <= std::max<std::size_t>(2, given.size() / 3) ? best : std::string{};
}

// `text` broken at spaces into lines of at most `width` columns (a word longer than that stands
// alone), joined by "\n" + `indent`.
std::string wrap(std::string_view text, std::size_t width, std::string_view indent = "") {
  std::string out;
  std::size_t line = 0;
  while (!text.empty()) {
    const std::size_t space = text.find(' ');
    const std::string_view word = text.substr(0, space);
    text = space == std::string_view::npos ? std::string_view{} : text.substr(space + 1);
    if (word.empty()) continue;
    if (line > 0 && line + 1 + word.size() > width) {
      out += "\n";
      out += indent;
      line = indent.size();
    } else if (line > 0) {
      out += ' ';
      ++line;
    }
    out += word;
    line += word.size();
  }
  return out;
}

// The heading of each option group in --help, so that a command's options read by topic.
std::string group_title(const OptionGroup& g) {
  const std::pair<const std::vector<OptionSpec>*, const char*> titles[] = {
      {&kMoveAxes, "Motion"},         {&kTuneMove, "Motion"},       {&kUnit, "Motion"},       {&kAxes, "Several axes"},
      {&kPlanFrom, "Plan file"},      {&kSample, "Samples"},        {&kSimulate, "Simulation"},
      {&kMoveFigure, "Figure"},
      {&kOnline, "Halt and retarget"}, {&kPlant, "Plant (the simulated machine)"},
      {&kDrive, "Drive (period, scales, model)"},                    {&kLoadNoise, "Load feedback noise"},
      {&kStream, "Bus and loop"},     {&kIdentifyLoop, "Bus and loop"}, {&kIdentify, "Excitation and estimate"},
      {&kPlantNode, "Bus and drive node"}, {&kTune, "Tuning"},       {&kExport, "Export"},
      {&kDriveBus, "Bus"},            {&kDriveNodeId, "Node"},      {&kDriveObject, "Object"},
      {&kDriveValue, "Value"},        {&kReproduce, "Experiment"},  {&kDemo, "Demo"},
      {&kOutput, "Output"}};
  for (const auto& [group, title] : titles) {
    if (group->data() == g.data()) return title;
  }
  return "Options";
}

std::string command_help(const CommandSpec& c) {
  // CLI11 lays the options out in a column kColumn wide and indents a description's further lines
  // to it; the descriptions are wrapped here so that no line passes kHelpColumns.
  constexpr std::size_t kColumn = 34;
  CLI::App app{wrap(c.summary, kHelpColumns), "settle " + c.name};
  app.set_help_flag("-h,--help", kHelp.help);
  std::string dummy;
  for (const OptionGroup& g : c.groups) {
    const std::string title = group_title(g);
    for (const OptionSpec& o : g) {
      const std::string text = wrap(o.describe(), kHelpColumns - kColumn);
      if (o.kind == Kind::flag) {
        app.add_flag(o.name)->description(text)->group(title);
      } else {
        app.add_option(o.name, dummy, text)->type_name(value_name(o))->group(title);
      }
    }
  }
  if (!c.positional_choices.empty()) {
    app.add_option(c.positional_name, dummy, "the " + c.positional_name + ": " + c.usage)->required();
  }
  std::string footer = wrap(c.notes, kHelpColumns);
  if (!c.example.empty()) {
    // A long example continues with a backslash, so that it still pastes into a shell as one line.
    std::string example = wrap(c.example, kHelpColumns - 6, "      ");
    for (std::size_t at = example.find('\n'); at != std::string::npos; at = example.find('\n', at + 3)) {
      example.replace(at, 1, " \\\n");
    }
    footer += "\n\nExample:\n  " + example;
  }
  app.footer(footer);
  app.get_formatter()->column_width(kColumn);
  return app.help();
}

std::string program_help() {
  std::string s = "usage: settle <command> [options]\n       settle --version\n\ncommands:\n";
  for (const CommandSpec& c : kCommands) {
    char line[256];
    std::snprintf(line, sizeof line, "  %-12s %s\n", c.name.c_str(), c.summary.c_str());
    s += line;
  }
  s += "\nrun 'settle <command> --help' or 'settle help <command>' for a command's options,\n"
       "each with its unit, default and valid range. Exit status: 0 success, 1 runtime failure,\n"
       "2 bad request (one line on stderr naming the option; with --json an error object).\n";
  return s;
}

ParseOutcome parse_command(const CommandSpec& c, int argc, char** argv, ParsedArgs& out, RequestError& err) {
  Parser p{c, options_of(c), out, err};
  return p.run(argc, argv);
}

int parse_or_exit(std::string_view command, int argc, char** argv, ParsedArgs& out) {
  const CommandSpec* c = find_command(command);
  RequestError err;
  switch (parse_command(*c, argc, argv, out, err)) {
    case ParseOutcome::ok: return -1;
    case ParseOutcome::help_printed: return 0;
    case ParseOutcome::error: break;
  }
  return report_bad_request(err, out.json());
}

bool parse_real(const std::string& s, double& out) {
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0])) != 0) return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0') return false;
  out = v;
  return true;
}

bool parse_integer(const std::string& s, long long& out) {
  long long v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || p != s.data() + s.size() || s.empty()) return false;
  out = v;
  return true;
}

double ParsedArgs::real(const std::string& name, double fallback) const { return real(name).value_or(fallback); }

std::optional<double> ParsedArgs::real(const std::string& name) const {
  const auto it = numbers_.find(name);
  if (it == numbers_.end() || it->second.empty()) return std::nullopt;
  return it->second.front();
}

std::vector<double> ParsedArgs::reals(const std::string& name) const {
  const auto it = numbers_.find(name);
  return it == numbers_.end() ? std::vector<double>{} : it->second;
}

long long ParsedArgs::integer(const std::string& name, long long fallback) const {
  const auto v = real(name);
  return v ? static_cast<long long>(*v) : fallback;
}

// The table's default of an option not given, as a number; a default that is not one (required,
// or prose such as "1.5 x the move's peak velocity") is a call site's mistake.
namespace {
double table_number(const std::map<std::string, std::string>& defaults, const std::string& name) {
  const auto it = defaults.find(name);
  double v = 0.0;
  if (it == defaults.end() || !parse_real(it->second, v)) {
    throw std::logic_error("settle: option " + name + " has no numeric default in the option table");
  }
  return v;
}
}  // namespace

long long ParsedArgs::integer(const std::string& name) const {
  if (const auto v = real(name)) return static_cast<long long>(*v);
  return static_cast<long long>(table_number(defaults_, name));
}

double ParsedArgs::real_or_default(const std::string& name) const {
  if (const auto v = real(name)) return *v;
  return table_number(defaults_, name);
}

std::string ParsedArgs::text_or_default(const std::string& name) const {
  if (const auto v = text(name)) return *v;
  const auto it = defaults_.find(name);
  if (it == defaults_.end() || it->second.empty()) {
    throw std::logic_error("settle: option " + name + " has no default in the option table");
  }
  return it->second;
}

std::string ParsedArgs::text(const std::string& name, const std::string& fallback) const {
  return text(name).value_or(fallback);
}

std::optional<std::string> ParsedArgs::text(const std::string& name) const {
  const auto it = raw_.find(name);
  if (it == raw_.end() || it->second.empty()) return std::nullopt;
  return it->second.front();
}

std::vector<double> ParsedArgs::list(const std::string& name) const {
  const auto it = lists_.find(name);
  if (it == lists_.end() || it->second.empty()) return {};
  return it->second.front();
}

std::vector<std::vector<double>> ParsedArgs::lists(const std::string& name) const {
  const auto it = lists_.find(name);
  if (it == lists_.end()) return {};
  return it->second;
}

int report_failure(std::string_view command, const std::string& code, const std::string& message, bool json) {
  if (json) {
    Json j;
    j["status"] = "error";
    j["error"] = code;
    j["message"] = message;
    print_json(j);
  } else {
    std::string msg = message;
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    std::fprintf(stderr, "settle %.*s: %s [%s]\n", static_cast<int>(command.size()), command.data(), msg.c_str(),
                 code.c_str());
  }
  return 1;
}

int report_bad_request(const RequestError& err, bool json) {
  if (json) {
    Json j;
    j["status"] = "error";
    j["error"] = err.code;
    j["parameter"] = err.param;
    j["message"] = err.message;
    print_json(j);
  } else {
    std::string msg = err.message;
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    std::fprintf(stderr, "settle: error: %s [%s]\n", msg.c_str(), err.code.c_str());
  }
  return 2;
}

}  // namespace settle::app
