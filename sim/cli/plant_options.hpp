#pragma once
// Command-line options that describe a plant (what is true about the machine), shared by every
// settle command that runs one: --plant sdof|beam|belt|modes and each kind's parameters, and the
// drive model options of the simulated drive.
#include <set>
#include <string>

#include "move_options.hpp"
#include "settle/sim/drive_axis.hpp"
#include "settle/sim/modal_plant.hpp"

namespace settle::cli {

extern const std::set<std::string> kPlantValueOptions;  // includes the repeatable --mode

// Builds the plant; the defaults are the papers' (Table 1 of seed 000 with 3 modes, seed 001's
// m-k-c system, Table III of seed 004).
[[nodiscard]] bool parse_plant(const Args& args, sim::ModalPlant& plant, RequestError& err);

extern const std::set<std::string> kDriveValueOptions;
// --period-us --counts-per-unit --load-counts-per-unit --interp linear|cubic --drive ideal|servo
// --bandwidth HZ --servo-damping Z. Counts default by plant kind (1 µm for sdof and beam; 2^16
// per motor revolution and 1e6 per platform radian for the belt).
[[nodiscard]] bool parse_drive(const Args& args, const sim::ModalPlant& plant, sim::DriveAxisConfig& cfg,
                               std::uint32_t& period_us, RequestError& err);

}  // namespace settle::cli
