// SPDX-License-Identifier: Apache-2.0
#include "eds_option.hpp"

#include <algorithm>
#include <cctype>
#include <optional>
#include <cstdio>

#include "commands.hpp"
#include "settle/hal/eds_semantics.hpp"

namespace settle::app {

int load_eds_option(const ParsedArgs& args, const std::string& command, std::span<const std::uint8_t> nodes,
                    EdsOption& out) {
  out = EdsOption{};
  const auto path = args.text("--eds");
  if (!path) return -1;
  const bool json = args.json();
  const bool strict = args.has("--strict");
  hal::eds::LoadResult r = hal::eds::load(*path);
  const auto refuse = [&](const std::string& why) {
    return report_bad_request({"bad_eds", "--eds", "--eds: " + why}, json);
  };
  if (!r.description) return refuse(r.error);
  out.warnings = std::move(r.warnings);
  for (const std::uint8_t node : nodes) {
    hal::eds::Semantics s = hal::eds::check_semantics(*r.description, node);
    if (s.refusal) return refuse(*path + ": " + hal::eds::to_string(*s.refusal));
    for (hal::eds::Problem& w : s.warnings) {
      // The same warning for every node of a multi-axis run is printed once.
      const bool known = std::any_of(out.warnings.begin(), out.warnings.end(), [&](const hal::eds::Problem& p) {
        return p.line == w.line && p.section == w.section && p.key == w.key && p.message == w.message;
      });
      if (!known) out.warnings.push_back(std::move(w));
    }
  }
  if (strict && !out.warnings.empty()) {
    return refuse(*path + ": " + hal::eds::to_string(out.warnings.front()) + " (--strict: a tolerated deviation refuses the file; " +
                  std::to_string(out.warnings.size()) + " in all)");
  }
  for (const hal::eds::Problem& w : out.warnings) {
    std::fprintf(stderr, "settle %s: --eds warning: %s: %s (tolerated; --strict refuses it)\n", command.c_str(),
                 path->c_str(), hal::eds::to_string(w).c_str());
  }
  out.description = std::make_shared<const hal::eds::Description>(std::move(*r.description));
  return -1;
}

int parse_load_feedback(const ParsedArgs& args, const hal::eds::Description* eds, testbed::LoadFeedback& out) {
  out = testbed::LoadFeedback{};
  const auto text = args.text("--load-feedback");
  if (!text) return -1;
  const auto refuse = [&](const std::string& why) {
    return report_bad_request({"bad_load_feedback", "--load-feedback", "--load-feedback: " + why}, args.json());
  };
  const std::size_t colon = text->find(':');
  const auto number = [](const std::string& t) -> std::optional<long long> {
    if (t.empty() || t.size() > 8) return std::nullopt;
    const bool hex = t.size() > 2 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X');
    const std::string digits = hex ? t.substr(2) : t;
    if (digits.empty()) return std::nullopt;
    for (const char c : digits) {
      if (!(hex ? std::isxdigit(static_cast<unsigned char>(c)) : std::isdigit(static_cast<unsigned char>(c)))) {
        return std::nullopt;
      }
    }
    return std::stoll(digits, nullptr, hex ? 16 : 10);
  };
  const auto index = colon == std::string::npos ? std::nullopt : number(text->substr(0, colon));
  const auto sub = colon == std::string::npos ? std::nullopt : number(text->substr(colon + 1));
  if (!index || !sub) return refuse("'" + *text + "' is not INDEX:SUB (such as 0x2100:1)");
  if (*index < 0x1000 || *index > 0xFFFF) return refuse("INDEX must be 0x1000..0xFFFF");
  if (*sub > 255) return refuse("SUB must be 0..255");
  char name[32];
  std::snprintf(name, sizeof name, "0x%04X:%u", static_cast<unsigned>(*index), static_cast<unsigned>(*sub));
  if (eds == nullptr) {
    return refuse(std::string{"needs --eds: the drive's description must say "} + name + " exists and can be mapped");
  }
  const hal::eds::Entry* e = eds->find(static_cast<std::uint16_t>(*index), static_cast<std::uint8_t>(*sub));
  if (e == nullptr) return refuse(std::string{"the drive's EDS has no "} + name);
  if (e->data_type != hal::eds::data_type::i32) {
    return refuse(std::string{"the drive's EDS gives "} + name + " (" + e->name +
                  ") another data type than INTEGER32 (counts)");
  }
  if (!e->readable() || !e->pdo_mappable) {
    return refuse(std::string{"the drive's EDS does not let "} + name + " (" + e->name + ") be mapped to a TPDO");
  }
  out.index = static_cast<std::uint16_t>(*index);
  out.sub = static_cast<std::uint8_t>(*sub);
  return -1;
}

}  // namespace settle::app
