// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/csv_columns.hpp"

#include <algorithm>
#include <stdexcept>

namespace settle::plant {

const char* to_string(PositionUnit u) noexcept { return u == PositionUnit::rad ? "rad" : "m"; }

std::optional<PositionUnit> parse_position_unit(std::string_view text) noexcept {
  if (text == "m") return PositionUnit::m;
  if (text == "rad") return PositionUnit::rad;
  return std::nullopt;
}

std::string motion_suffix(PositionUnit u, int derivative) {
  static constexpr const char* kPer[] = {"", "_per_s", "_per_s2", "_per_s3"};
  if (derivative < 0 || derivative > 3) throw std::logic_error("motion_suffix: derivative outside 0..3");
  return std::string{to_string(u)} + kPer[derivative];
}

std::string_view energy_suffix(PlantKind kind, PositionUnit u) noexcept {
  if (kind != PlantKind::modes) return "j";
  return u == PositionUnit::rad ? "j_per_kg_m2" : "j_per_kg";
}

namespace {
bool word_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}
}  // namespace

std::string identifier(std::string_view text) {
  std::string s{text};
  std::replace_if(s.begin(), s.end(), [](char c) { return !word_char(c); }, '_');
  return s;
}

std::string column(std::string_view quantity, std::string_view unit) {
  if (std::find(kUnitSuffixes.begin(), kUnitSuffixes.end(), unit) == kUnitSuffixes.end()) {
    throw std::logic_error("column: unit suffix '" + std::string{unit} + "' is not in kUnitSuffixes");
  }
  if (quantity.empty() || (quantity.front() >= '0' && quantity.front() <= '9') ||
      !std::all_of(quantity.begin(), quantity.end(), word_char)) {
    throw std::logic_error("column: quantity '" + std::string{quantity} + "' is not an identifier");
  }
  return std::string{quantity} + "_" + std::string{unit};
}

}  // namespace settle::plant
