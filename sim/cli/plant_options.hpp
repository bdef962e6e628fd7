#pragma once
// The --plant options shared by `settle simulate` and the drive+plant node (`settle plant`):
// which plant and its physical parameters, parsed into a sim::PlantSpec, with a bad value or a
// bad combination reported by the option's name like every other settle error.
#include <set>
#include <string>

#include "move_options.hpp"
#include "settle/sim/modal_plant.hpp"

namespace settle::cli {

// --plant and every parameter option of every plant (the parser rejects the ones that do not
// apply to the chosen plant). --mode is repeatable.
extern const std::set<std::string> kPlantValueOptions;

// Fills `spec` from the options (defaults: Table 1 beam, seed 001 sdof, Table III belt) and
// builds it; false with `err` naming the option on a malformed value or rejected parameter.
[[nodiscard]] bool parse_plant(const Args& args, sim::PlantSpec& spec, sim::ModalPlant& plant, RequestError& err);

}  // namespace settle::cli
