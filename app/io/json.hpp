// SPDX-License-Identifier: Apache-2.0
#pragma once
// The CLI's JSON output (nlohmann-json, keys in insertion order). A document is printed only when
// every number in it is finite: JSON has no infinity, and the CLI never reports success with a
// non-finite result. A value that may legitimately be absent (a peak that is a Dirac impulse, a
// settling time that never comes) is put in as null by the caller, on purpose.
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace settle::app {

using Json = nlohmann::ordered_json;

// True when no number in `j` is NaN or infinite.
[[nodiscard]] inline bool all_finite(const Json& j) {
  if (j.is_number_float()) return std::isfinite(j.get<double>());
  if (j.is_structured()) {
    for (const auto& v : j) {
      if (!all_finite(v)) return false;
    }
  }
  return true;
}

// The deepest nesting of arrays and objects a document Settle reads may have. Its own files nest
// four levels; a crafted file nested a hundred thousand deep would reach code that recurses once
// per level (copies, comparisons of the parsed value) and overflow the stack, so it is refused
// before it is parsed.
inline constexpr std::size_t kMaxJsonDepth = 32;

// The deepest nesting of `text`'s arrays and objects outside strings, counted up to `stop` (a
// linear scan, no parse: what kMaxJsonDepth is checked with before nlohmann parses anything).
[[nodiscard]] inline std::size_t json_nesting_depth(std::string_view text, std::size_t stop = kMaxJsonDepth + 1) noexcept {
  std::size_t depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > deepest) deepest = depth;
      if (deepest >= stop) return deepest;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

// A number, or null when it is not finite (for values documented as possibly absent).
[[nodiscard]] inline Json finite_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// One line on `out`; strings that are not valid UTF-8 (a hostile path) are printed with U+FFFD.
inline void print_json(const Json& j, std::FILE* out = stdout) {
  const std::string s = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::fprintf(out, "%s\n", s.c_str());
}

}  // namespace settle::app
