// SPDX-License-Identifier: Apache-2.0
#pragma once
// The plant (what is true about the machine) and the simulated drive, from the validated options
// of the plant and drive groups (options.cpp): --plant sdof|beam|belt|modes and each kind's
// parameters, --period-us, the count scales, the drive model.
#include <cstdint>

#include "options.hpp"
#include "settle/testbed/drive_axis.hpp"
#include "settle/plant/csv_columns.hpp"
#include "settle/plant/modal_plant.hpp"

namespace settle::app {

// Builds the plant; the defaults are the papers' (Table 1 of seed 000 with 3 modes, seed 001's
// m-k-c system, Table III of seed 004).
[[nodiscard]] bool parse_plant(const ParsedArgs& args, plant::ModalPlant& plant, RequestError& err);

// The unit of a plant's positions (it labels, it scales nothing): sdof and beam are in m and belt
// in rad (their parameters say so); --plant modes in --unit's (m when not given). Another --unit
// for sdof, beam or belt is refused (conflicting_options, naming --unit).
[[nodiscard]] bool plant_unit(const ParsedArgs& args, plant::PlantKind k, plant::PositionUnit& out, RequestError& err);

// Counts default by plant kind (1 µm for sdof and beam; 2^16 per motor revolution and 1e6 per
// platform radian for the belt); the period (--period-us) is the scale's.
[[nodiscard]] bool parse_drive(const ParsedArgs& args, const plant::ModalPlant& plant, testbed::DriveAxisConfig& cfg,
                               RequestError& err);

}  // namespace settle::app
