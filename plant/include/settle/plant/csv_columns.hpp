// SPDX-License-Identifier: Apache-2.0
#pragma once
// The names of the columns of every CSV file Settle writes (sample, plan and simulate --png, simulate
// --csv, stream --log and --feedback-log, plant --log, identify --png, tune --png, reproduce's time
// histories): each is
// <quantity>_<unit>, the unit one of kUnitSuffixes, the whole name a C/Python identifier, so that
// numpy's genfromtxt(names=True), pandas and csv.DictReader all keep it as written. column() is
// the one place a name is made; docs/csv.md lists the suffixes and what each column holds.
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "settle/plant/modal_plant.hpp"

namespace settle::plant {

// Every unit suffix a column may carry (without the leading underscore).
inline constexpr std::array<std::string_view, 22> kUnitSuffixes = {
    "s",      "us",          // time: seconds, microseconds
    "m",      "m_per_s",     "m_per_s2",  "m_per_s3",     // position unit m and its derivatives
    "rad",    "rad_per_s",   "rad_per_s2", "rad_per_s3",  // position unit rad and its derivatives
    "counts",                // a drive's position counts (0x607A, 0x6064, the load's)
    "counts_per_s",          // counts per second (the velocity Settle's simulated drive sends)
    "drive_velocity_units",  // a drive's velocity actual value (0x606C), in the drive's own unit
    "hz",                    // frequency
    "j",                     // energy, joule (a plant with physical parameters: sdof, beam, belt)
    "j_per_kg",              // energy per kg of modal mass (--plant modes, positions in m)
    "j_per_kg_m2",           // energy per kg m^2 of modal inertia (--plant modes, positions in rad)
    "pct",                   // percent
    "ratio",                 // a dimensionless ratio
    "index",                 // an ordinal: tick, SYNC or period number
    "flag",                  // 0 or 1
    "count",                 // a number of events (frames received so far)
};

// The unit the user's positions are in (--unit; it only labels, it scales nothing).
enum class PositionUnit : unsigned char { m, rad };
[[nodiscard]] const char* to_string(PositionUnit u) noexcept;
// "m" or "rad"; anything else: nullopt.
[[nodiscard]] std::optional<PositionUnit> parse_position_unit(std::string_view text) noexcept;

// The suffix of the position unit's `derivative`-th time derivative (0..3): m, m_per_s, m_per_s2,
// m_per_s3 (or rad...). Throws std::logic_error outside 0..3.
[[nodiscard]] std::string motion_suffix(PositionUnit u, int derivative);

// The suffix of a plant's energies: j where its parameters are physical (sdof, beam, belt), and for
// --plant modes, whose modes carry no mass, the energy per unit modal mass: j_per_kg (positions in
// m) or j_per_kg_m2 (in rad).
[[nodiscard]] std::string_view energy_suffix(PlantKind kind, PositionUnit u) noexcept;

// `text` as a piece of an identifier: every character other than a letter, digit or '_' becomes
// '_' (a tune candidate "scurve+zv" -> "scurve_zv").
[[nodiscard]] std::string identifier(std::string_view text);

// The column `quantity`_`unit`. Throws std::logic_error when `unit` is not in kUnitSuffixes or
// `quantity` is not an identifier (a programming error: every name is fixed in the code).
[[nodiscard]] std::string column(std::string_view quantity, std::string_view unit);

}  // namespace settle::plant
