// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/status.hpp"

#include "settle/plant/limits.hpp"

namespace settle::plant {

// describe() spells the bounds out for humans; keep it in step with limits.hpp.
static_assert(kMaxSamples == 10'000'000 && kMaxModes == 64 && kMaxSimulatedTime == 3600.0);

namespace {
constexpr const char* kSimStatusCodes[] = {SETTLE_PLANT_STATUSES(SETTLE_ENUM_CODE)};
constexpr const char* kSimStatusTexts[] = {SETTLE_PLANT_STATUSES(SETTLE_ENUM_TEXT)};
}  // namespace

const char* to_string(SimStatus s) noexcept { return core::enum_text(kSimStatusCodes, s, "unknown"); }

const char* describe(SimStatus s) noexcept { return core::enum_text(kSimStatusTexts, s, "unknown status"); }

}  // namespace settle::plant
