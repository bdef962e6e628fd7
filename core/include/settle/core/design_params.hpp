// SPDX-License-Identifier: Apache-2.0
#pragma once
// The parameters a move request may carry beyond its distance, and sets of them. Each profile of
// the registry (profiles/registry.hpp, its descriptor's `params`) and each shaper (shaper.hpp,
// shaper_params) states here which of them it uses: the one statement the planner's needs_mode
// and the refusal of a parameter the move would ignore (the CLI's options, the Python keywords)
// are both read from.
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace settle::core {

enum class Param : std::uint8_t {
  time,    // a move time
  vmax,    // a velocity limit: met (time-optimal under it) or checked (with a time)
  amax,    // an acceleration limit, likewise
  jmax,    // a jerk limit, likewise
  omega,   // the first design mode's natural frequency
  zeta,    // its damping ratio
  modes,   // more than one design mode
  gammas,  // pseudo-polynomial exponents
  y,       // ramp-versine fractions Y1/L..Y3/L given instead of computed
  robust,  // a band of frequencies the residual stays small over
  vtol,    // an EI shaper's vibration tolerance
};
inline constexpr std::size_t kParamCount = 11;

// The request field's name ("time", "vmax", ...; "modes" for several omegas): the Python keyword,
// and the CLI option without its dashes (--omega is both omega and modes).
[[nodiscard]] constexpr const char* to_string(Param p) noexcept {
  constexpr const char* names[kParamCount] = {"time",  "vmax",  "amax",   "jmax",   "omega", "zeta",
                                              "modes", "gammas", "y", "robust", "vtol"};
  const auto i = static_cast<std::size_t>(p);
  return i < kParamCount ? names[i] : "unknown";
}

class ParamSet {
 public:
  constexpr ParamSet() noexcept = default;
  // ParamSet{Param::time, Param::vmax}: the parameters listed (not std::initializer_list, which the
  // freestanding core does not include).
  template <typename... P>
    requires(sizeof...(P) > 0 && (std::is_same_v<P, Param> && ...))
  constexpr ParamSet(P... ps) noexcept : bits_{static_cast<std::uint16_t>((0u | ... | bit(ps)))} {}
  [[nodiscard]] constexpr bool contains(Param p) const noexcept { return (bits_ & bit(p)) != 0; }
  [[nodiscard]] constexpr bool empty() const noexcept { return bits_ == 0; }
  [[nodiscard]] constexpr ParamSet operator|(ParamSet o) const noexcept { return from(bits_ | o.bits_); }
  // The parameters of this set that `o` does not hold.
  [[nodiscard]] constexpr ParamSet operator-(ParamSet o) const noexcept { return from(bits_ & ~o.bits_); }
  [[nodiscard]] constexpr bool operator==(const ParamSet&) const noexcept = default;

 private:
  static constexpr std::uint16_t bit(Param p) noexcept {
    return static_cast<std::uint16_t>(1u << static_cast<unsigned>(p));
  }
  static constexpr ParamSet from(unsigned bits) noexcept {
    ParamSet s;
    s.bits_ = static_cast<std::uint16_t>(bits);
    return s;
  }
  std::uint16_t bits_{0};
};

// A profile whose use of some parameters depends on another: given `given`, `unused` are not used
// (ramp-versine: its fractions given, it designs for no mode). A profile without one has the
// default, which drops nothing.
struct ParamOverride {
  Param given{Param::time};
  ParamSet unused{};
};

}  // namespace settle::core
