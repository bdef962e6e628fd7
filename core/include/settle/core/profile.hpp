#pragma once
// Any core profile behind one value type, so that the servo loop, the simulator and the CLI can
// hold "a move" without templates leaking into them. A closed set: dispatch is a switch, no
// virtual calls, no heap.
#include <cstdint>
#include <variant>

#include "settle/core/kinematics.hpp"
#include "settle/core/piecewise_jerk.hpp"
#include "settle/core/pseudo_poly.hpp"
#include "settle/core/ramp_cycloid.hpp"
#include "settle/core/ramp_versine.hpp"

namespace settle::core {

enum class ProfileKind : std::uint8_t {
  scurve,         // ramp-cycloid S-curve, seed 000
  scurve_damped,  // ramp-cycloid + versine, exact for a damped mode (ours)
  ramp_versine,   // ramp + cycloid + versine position command, seeds 001/002
  pseudopoly,     // pseudo-polynomial, seed 004
  poly345,        // 3-4-5 polynomial (pseudopoly with gamma = 3, 4, 5)
  trapezoid,      // trapezoidal velocity
  jerk_limited,   // classic 7-phase jerk-limited S-curve
};

[[nodiscard]] const char* to_string(ProfileKind k) noexcept;
// Parses the CLI names (scurve, scurve-damped, ramp-versine, pseudopoly, poly345, trapezoid,
// jerk-limited). Returns false for an unknown name and leaves `out` untouched.
[[nodiscard]] bool parse_profile_kind(const char* name, ProfileKind& out) noexcept;

template <typename T>
class Profile {
 public:
  using Variant = std::variant<PiecewiseJerk<T>, RampCycloid<T>, RampVersine<T>, PseudoPoly<T>>;

  Profile() = default;  // a zero-length move of zero distance
  Profile(ProfileKind kind, const Variant& v) noexcept : kind_{kind}, v_{v} {}
  template <typename U>
  explicit Profile(const Profile<U>& o) noexcept : kind_{o.kind()} {
    o.visit([this](const auto& p) { assign(p); });
  }

  [[nodiscard]] ProfileKind kind() const noexcept { return kind_; }
  [[nodiscard]] const Variant& variant() const noexcept { return v_; }

  // Calls f with the concrete profile. std::visit is avoided on purpose: it may throw
  // bad_variant_access, and core is built without exceptions.
  template <typename F>
  decltype(auto) visit(F&& f) const noexcept {
    switch (v_.index()) {
      case 1: return f(*std::get_if<1>(&v_));
      case 2: return f(*std::get_if<2>(&v_));
      case 3: return f(*std::get_if<3>(&v_));
      default: return f(*std::get_if<0>(&v_));
    }
  }

  [[nodiscard]] Sample<T> at(T t) const noexcept {
    return visit([t](const auto& p) { return p.at(t); });
  }
  [[nodiscard]] T duration() const noexcept {
    return visit([](const auto& p) { return p.duration(); });
  }
  [[nodiscard]] T distance() const noexcept {
    return visit([](const auto& p) { return p.distance(); });
  }

 private:
  template <typename U, template <typename> class P>
  void assign(const P<U>& p) noexcept {
    v_ = P<T>{p};
  }

  ProfileKind kind_{ProfileKind::trapezoid};
  Variant v_{};
};

}  // namespace settle::core
