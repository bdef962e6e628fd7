// SPDX-License-Identifier: Apache-2.0
#include "settle/core/status.hpp"

namespace settle::core {

namespace {
constexpr const char* kStatusCodes[] = {SETTLE_CORE_STATUSES(SETTLE_ENUM_CODE)};
constexpr const char* kStatusTexts[] = {SETTLE_CORE_STATUSES(SETTLE_ENUM_TEXT)};
}  // namespace

const char* to_string(Status s) noexcept { return core::enum_text(kStatusCodes, s, "unknown"); }

const char* describe(Status s) noexcept { return core::enum_text(kStatusTexts, s, "unknown status"); }

}  // namespace settle::core
