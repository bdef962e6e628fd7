// SPDX-License-Identifier: Apache-2.0
#pragma once
// One list per status enum: each layer's statuses are written once, as an X-macro list of
// (enumerator, sentence) pairs, and the enum, its stable snake_case codes (to_string) and its
// sentences (describe) are all made from that list, as the profile registry makes its tables.
//
//   #define SETTLE_THING_STATUSES(X) X(ok, "ok") X(too_big, "the thing is too big")
//   enum class ThingStatus : std::uint8_t { SETTLE_THING_STATUSES(SETTLE_ENUM_ENUMERATOR) };
//   constexpr const char* kCodes[] = {SETTLE_THING_STATUSES(SETTLE_ENUM_CODE)};   // "ok", "too_big"
//   constexpr const char* kTexts[] = {SETTLE_THING_STATUSES(SETTLE_ENUM_TEXT)};
//   const char* to_string(ThingStatus s) noexcept { return core::enum_text(kCodes, s, "unknown"); }
//
// Freestanding: no heap, no exceptions.
#include <cstddef>

#define SETTLE_ENUM_ENUMERATOR(name, text) name,
#define SETTLE_ENUM_CODE(name, text) #name,
#define SETTLE_ENUM_TEXT(name, text) text,

namespace settle::core {

// table[e] for an enumerator of the list the table was made from; `fallback` for any other value
// (a cast from a number that no enumerator has).
template <typename E, std::size_t N>
[[nodiscard]] constexpr const char* enum_text(const char* const (&table)[N], E e, const char* fallback) noexcept {
  const auto i = static_cast<std::size_t>(e);
  return i < N ? table[i] : fallback;
}

}  // namespace settle::core
