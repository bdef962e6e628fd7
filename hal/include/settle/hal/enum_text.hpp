// SPDX-License-Identifier: Apache-2.0
#pragma once
// hal's status enums are made as core's are (settle/core/enum_text.hpp): one X-macro list per enum of
// (enumerator, sentence), from which the enum, its snake_case codes and its sentences are all made.
// core and hal stay independent of each other (neither includes the other), so hal has this copy of
// the three list macros and the lookup. The macros are spelled exactly as core's: a translation unit
// that includes both headers (runtime) gets the same definition twice, which C++ allows only when
// the two are token for token the same: a copy that drifted is diagnosed ("redefined") there.
// Freestanding: no heap, no exceptions.
#include <cstddef>

#define SETTLE_ENUM_ENUMERATOR(name, text) name,
#define SETTLE_ENUM_CODE(name, text) #name,
#define SETTLE_ENUM_TEXT(name, text) text,

namespace settle::hal {

// table[e] for an enumerator of the list the table was made from; `fallback` for any other value.
template <typename E, std::size_t N>
[[nodiscard]] constexpr const char* enum_text(const char* const (&table)[N], E e, const char* fallback) noexcept {
  return static_cast<std::size_t>(e) < N ? table[static_cast<std::size_t>(e)] : fallback;
}

}  // namespace settle::hal
