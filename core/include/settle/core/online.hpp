#pragma once
// Online changes of a running move: `halt` (come to rest as fast as the limits allow) and
// `retarget` (go to a new target), from any state mid-move, leaving every design mode at rest.
// The derivation (mode memory, the conditions on the blend, the solver) is in docs/online.md.
// Freestanding: no heap, no exceptions; a plan costs a few microseconds on a host.
#include <array>
#include <cstddef>
#include <optional>

#include "settle/core/kinematics.hpp"
#include "settle/core/move.hpp"
#include "settle/core/move_request.hpp"  // Mode: one (omega, zeta), the same a request designs for
#include "settle/core/status.hpp"

namespace settle::core {

// Up to this many modes (omega, zeta) are brought to rest by one blend.
inline constexpr std::size_t kMaxOnlineModes = 4;
// A blend is this many constant-jerk segments of equal length.
inline constexpr std::size_t kBlendSegments = 24;

struct OnlineLimits {
  double vmax{0.0};  // units/s, > 0
  double amax{0.0};  // units/s^2, > 0
  double jmax{0.0};  // units/s^3, > 0
};

// The mode memory of a command x(t) that started at rest at t = 0, for the mode with poles
// lambda = -zeta omega +- i omega_d:  Q(t) = -int_0^t e^{lambda (t - s)} x'(s) ds  (complex).
// The command leaves the mode at rest at T (x'(T) = x''(T) = 0) exactly when Q(T) = 0, whatever
// the mode's input coupling (docs/online.md).
struct ModeMemory {
  double re{0.0};
  double im{0.0};
};

// Q(t) of a planned move, from its exact piecewise closed form (piece.hpp) where the profile has
// one, by Gauss-Legendre quadrature otherwise (the pseudo-polynomial). t is on the move's clock.
[[nodiscard]] ModeMemory mode_memory(const Move<double>& m, double t, const Mode& mode) noexcept;

// Where a blend starts and what it must achieve.
struct OnlineRequest {
  Sample<double> start{};               // p, v, a of the command at the switch (j is not used)
  std::array<Mode, kMaxOnlineModes> modes{};
  std::array<ModeMemory, kMaxOnlineModes> memory{};  // Q of each mode at the switch
  std::size_t mode_count{0};
  OnlineLimits limits{};
  std::optional<double> target;  // retarget: the final position; none: halt wherever it stops
};

// A blend: kBlendSegments constant-jerk segments of length h from the switch state to rest.
// Its clock starts at the switch (u = 0); past its end it is at rest on its final position.
class Blend {
 public:
  Blend() = default;
  Blend(const Sample<double>& start, double h, const std::array<double, kBlendSegments>& jerk) noexcept;

  [[nodiscard]] Sample<double> at(double u) const noexcept;
  [[nodiscard]] double duration() const noexcept { return h_ * static_cast<double>(kBlendSegments); }
  [[nodiscard]] double segment_length() const noexcept { return h_; }
  [[nodiscard]] double jerk(std::size_t k) const noexcept { return j_[k]; }
  [[nodiscard]] Sample<double> start() const noexcept { return {p_[0], v_[0], a_[0], 0.0}; }
  // Position at rest at the end (units, on the running move's position scale).
  [[nodiscard]] double end_position() const noexcept { return p_end_; }
  // Exact peaks of |v|, |a|, |j| over the blend (a is piecewise linear, v piecewise quadratic).
  [[nodiscard]] Peaks<double> peaks() const noexcept;

 private:
  double h_{0.0};
  std::array<double, kBlendSegments + 1> p_{}, v_{}, a_{};
  std::array<double, kBlendSegments> j_{};
  double p_end_{0.0};
};

// Plans the fastest blend (within its family, docs/online.md) that meets the request within the
// limits. A failed plan leaves `out` untouched.
[[nodiscard]] Status plan_online(const OnlineRequest& req, Blend& out) noexcept;

// Convenience: the request of a halt (target none) or a retarget (target = new distance from the
// move's start) of the running move `m` at time t on its clock, for the given modes.
[[nodiscard]] Status online_request(const Move<double>& m, double t, const Mode* modes, std::size_t mode_count,
                                    const OnlineLimits& limits, std::optional<double> target,
                                    OnlineRequest& out) noexcept;

}  // namespace settle::core
