// SPDX-License-Identifier: Apache-2.0
#pragma once
// The profile registry: every profile core knows, one include and one line each. Everything that
// enumerates profiles is generated from SETTLE_CORE_PROFILES: the ProfileKind enum, the shapes
// Profile<T> can hold and its visit (profile.hpp), the planner's dispatch (planner.cpp), the
// names the CLI and the Python module parse and list, and the tests that run every profile
// (tests/core/test_registry.cpp). docs/adding-a-profile.md walks through adding one.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>
#include <utility>

#include "settle/core/move_request.hpp"
#include "settle/core/profiles/fastest.hpp"
#include "settle/core/profiles/jerk_limited.hpp"
#include "settle/core/profiles/poly345.hpp"
#include "settle/core/profiles/pseudopoly.hpp"
#include "settle/core/profiles/ramp_versine.hpp"
#include "settle/core/profiles/scurve.hpp"
#include "settle/core/profiles/scurve_damped.hpp"
#include "settle/core/profiles/trapezoid.hpp"

// X(enumerator, descriptor): the enumerator names the ProfileKind, the descriptor (a struct in the
// profile's header) gives its name, shape, planner hook and example request. The order is the
// enum's, the CLI's listing and the JSON's; scurve stays first (MoveRequest's default).
#define SETTLE_CORE_PROFILES(X)            \
  X(scurve, ScurveProfile)                 \
  X(scurve_damped, ScurveDampedProfile)    \
  X(ramp_versine, RampVersineProfile)      \
  X(pseudopoly, PseudopolyProfile)         \
  X(poly345, Poly345Profile)               \
  X(trapezoid, TrapezoidProfile)           \
  X(jerk_limited, JerkLimitedProfile)      \
  SETTLE_CORE_PROFILE_FASTEST(X)

// `fastest` holds a table of up to 47 constant-jerk segments (a PiecewiseJerk<T, 47>), and a
// Profile is as large as its largest shape: with it a Move<double> is 3008 bytes instead of 1088
// and a Move<float> 2520 instead of 640 (arm-none-eabi, Cortex-M4F; 2240 and 1816 at 31 segments). Built with
// SETTLE_CORE_FASTEST=1 for the Cortex-M4F, every image that holds a move (golden, evaluators,
// servo, servo_fixed, servo_eval, servo_size) overflows its stack under QEMU (lockup); only hello
// runs (docs/fastest.md, "Limits"). On M-profile cores it is therefore left out of the registry
// unless SETTLE_CORE_FASTEST=1 is defined. A drive does not need it to
// follow such a move: the master (Linux, host or aarch64) plans it and streams its setpoints. It is
// the last line, so the other kinds keep their values on every target.
#ifndef SETTLE_CORE_FASTEST
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
#define SETTLE_CORE_FASTEST 0
#else
#define SETTLE_CORE_FASTEST 1
#endif
#endif
#if SETTLE_CORE_FASTEST
#define SETTLE_CORE_PROFILE_FASTEST(X) X(fastest, FastestProfile)
#else
#define SETTLE_CORE_PROFILE_FASTEST(X)
#endif

namespace settle::core {

enum class ProfileKind : std::uint8_t {
#define SETTLE_PROFILE_ENUMERATOR(id, Descriptor) id,
  SETTLE_CORE_PROFILES(SETTLE_PROFILE_ENUMERATOR)
#undef SETTLE_PROFILE_ENUMERATOR
};

inline constexpr std::size_t kProfileCount = 0
#define SETTLE_PROFILE_COUNT(id, Descriptor) +1
    SETTLE_CORE_PROFILES(SETTLE_PROFILE_COUNT)
#undef SETTLE_PROFILE_COUNT
    ;

// ProfileOf<K>::type is kind K's descriptor.
template <ProfileKind K>
struct ProfileOf;
#define SETTLE_PROFILE_OF(id, Descriptor) \
  template <>                             \
  struct ProfileOf<ProfileKind::id> {     \
    using type = Descriptor;              \
  };
SETTLE_CORE_PROFILES(SETTLE_PROFILE_OF)
#undef SETTLE_PROFILE_OF
template <ProfileKind K>
using profile_t = typename ProfileOf<K>::type;

// Calls f(std::integral_constant<ProfileKind, K>{}) for every registered kind K, in order.
template <typename F>
constexpr void for_each_profile(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f(std::integral_constant<ProfileKind, static_cast<ProfileKind>(I)>{}), ...);
  }(std::make_index_sequence<kProfileCount>{});
}

// Calls f(std::integral_constant<ProfileKind, k>{}) for the registered kind equal to k; false
// (and no call) for a value no registry line defines.
template <typename F>
constexpr bool with_profile(ProfileKind k, F&& f) {
  bool found = false;
  for_each_profile([&](auto c) {
    if (c.value == k) {
      found = true;
      f(c);
    }
  });
  return found;
}

inline constexpr const char* kProfileNames[] = {
#define SETTLE_PROFILE_NAME(id, Descriptor) Descriptor::name,
    SETTLE_CORE_PROFILES(SETTLE_PROFILE_NAME)
#undef SETTLE_PROFILE_NAME
};
inline constexpr const char* kProfileSummaries[] = {
#define SETTLE_PROFILE_SUMMARY(id, Descriptor) Descriptor::summary,
    SETTLE_CORE_PROFILES(SETTLE_PROFILE_SUMMARY)
#undef SETTLE_PROFILE_SUMMARY
};

namespace detail {
template <typename P>
constexpr ParamOverride overrides_of() noexcept {
  if constexpr (requires { P::overrides; }) {
    return P::overrides;
  } else {
    return {};
  }
}
}  // namespace detail
inline constexpr ParamSet kProfileParams[] = {
#define SETTLE_PROFILE_PARAMS(id, Descriptor) Descriptor::params,
    SETTLE_CORE_PROFILES(SETTLE_PROFILE_PARAMS)
#undef SETTLE_PROFILE_PARAMS
};
inline constexpr ParamOverride kProfileOverrides[] = {
#define SETTLE_PROFILE_OVERRIDES(id, Descriptor) detail::overrides_of<Descriptor>(),
    SETTLE_CORE_PROFILES(SETTLE_PROFILE_OVERRIDES)
#undef SETTLE_PROFILE_OVERRIDES
};

// Every profile's name, in registry order (what the CLI's --profile and Python's profile= accept).
[[nodiscard]] constexpr std::span<const char* const> profile_names() noexcept { return kProfileNames; }
[[nodiscard]] constexpr bool is_registered(ProfileKind k) noexcept {
  return static_cast<std::size_t>(k) < kProfileCount;
}
// The name of k ("unknown" for a value no registry line defines).
[[nodiscard]] constexpr const char* to_string(ProfileKind k) noexcept {
  return is_registered(k) ? kProfileNames[static_cast<std::size_t>(k)] : "unknown";
}
// One line on what k is, for help texts ("" for an unregistered value).
[[nodiscard]] constexpr const char* summary(ProfileKind k) noexcept {
  return is_registered(k) ? kProfileSummaries[static_cast<std::size_t>(k)] : "";
}
// Every parameter k's hook may read (its descriptor's `params`; empty for an unregistered value).
[[nodiscard]] constexpr ParamSet profile_params(ProfileKind k) noexcept {
  return is_registered(k) ? kProfileParams[static_cast<std::size_t>(k)] : ParamSet{};
}
// What k's hook does not read when a request carries a parameter (its descriptor's `overrides`:
// ramp-versine's mode, given its fractions); one that drops nothing for the other profiles.
[[nodiscard]] constexpr ParamOverride profile_overrides(ProfileKind k) noexcept {
  return is_registered(k) ? kProfileOverrides[static_cast<std::size_t>(k)] : ParamOverride{};
}
// Parses a profile's name. Returns false for an unknown name and leaves `out` untouched.
[[nodiscard]] inline bool parse_profile_kind(const char* name, ProfileKind& out) noexcept {
  if (name == nullptr) return false;
  for (std::size_t i = 0; i < kProfileCount; ++i) {
    if (std::strcmp(name, kProfileNames[i]) == 0) {
      out = static_cast<ProfileKind>(i);
      return true;
    }
  }
  return false;
}

}  // namespace settle::core
