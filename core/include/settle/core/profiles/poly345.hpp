// SPDX-License-Identifier: Apache-2.0
#pragma once
// Profile `poly345`: the classic 3-4-5 polynomial, a pseudo-polynomial with exponents 3, 4, 5.
#include "settle/core/profiles/pseudopoly.hpp"

namespace settle::core {

struct Poly345Profile {
  static constexpr const char* name = "poly345";
  static constexpr const char* summary = "3-4-5 polynomial (pseudopoly with gammas 3, 4, 5)";
  template <typename T>
  using Shape = PseudoPoly<T>;
  // Its exponents are fixed: no gammas.
  static constexpr ParamSet params{Param::time, Param::vmax, Param::amax, Param::jmax};
  [[nodiscard]] static Status plan(const MoveRequest& r, PseudoPolyParams& out, Peaks<double>& pk) noexcept {
    static constexpr double k345[3] = {3.0, 4.0, 5.0};
    return detail::plan_pseudopoly(r, k345, 3, out, pk);
  }
  [[nodiscard]] static MoveRequest example() noexcept {
    MoveRequest r{};
    r.distance = 0.2;
    r.time = 1.0;
    return r;
  }
};

}  // namespace settle::core
