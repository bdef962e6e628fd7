// SPDX-License-Identifier: Apache-2.0
#pragma once
// Any core profile behind one value type, so that the servo loop, the simulator and the CLI can
// hold "a move" without templates leaking into them. A closed set, generated from the registry
// (profiles/registry.hpp): the variant holds each registered profile's shape once, and dispatch is
// an if-chain over its alternatives, no virtual calls, no heap.
#include <cstddef>
#include <type_traits>
#include <utility>
#include <variant>

#include "settle/core/kinematics.hpp"
#include "settle/core/profiles/registry.hpp"

namespace settle::core {

// Where evaluation is split (profile.hpp's Profile::at, move.hpp's Move::at): the cheap piecewise
// table inline in the caller, the transcendental shapes and the impulse sum out of line, which
// makes a tick's evaluation cost the evaluator's own on a host. On M-profile cores, whose images
// are budgeted in flash, every shape stays in one function (the split copies the table's
// evaluation into each caller: +0.7 KiB in the Cortex-M4F one-axis image). Same results either way.
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
inline constexpr bool kSplitEvaluation = false;
#else
inline constexpr bool kSplitEvaluation = true;
#endif

namespace detail {
template <typename... Ts>
struct TypeList {};
template <typename List, typename T>
struct AppendUnique;
template <typename... Ts, typename T>
struct AppendUnique<TypeList<Ts...>, T> {
  using type = std::conditional_t<(std::is_same_v<T, Ts> || ...), TypeList<Ts...>, TypeList<Ts..., T>>;
};
// The registered profiles' shapes in registry order, each once (two profiles may share a shape).
template <typename T, std::size_t I = 0, typename Acc = TypeList<>>
constexpr auto registered_shapes() {
  if constexpr (I == kProfileCount) {
    return std::type_identity<Acc>{};
  } else {
    using Shape = typename profile_t<static_cast<ProfileKind>(I)>::template Shape<T>;
    return registered_shapes<T, I + 1, typename AppendUnique<Acc, Shape>::type>();
  }
}
template <typename List>
struct VariantOf;
template <typename... Ts>
struct VariantOf<TypeList<Ts...>> {
  using type = std::variant<Ts...>;
};
}  // namespace detail

template <typename T>
class Profile {
 public:
  using Variant = typename detail::VariantOf<typename decltype(detail::registered_shapes<T>())::type>::type;

  Profile() = default;  // a zero-length move of zero distance
  Profile(ProfileKind kind, const Variant& v) noexcept : kind_{kind}, v_{v} {}
  template <typename U>
  explicit Profile(const Profile<U>& o) noexcept {
    convert_from(o);
  }
  // Becomes `o` converted to T, its shape built in place (no temporary shape or variant).
  template <typename U>
  void convert_from(const Profile<U>& o) noexcept {
    kind_ = o.kind();
    o.visit([this](const auto& p) { this->template assign<U>(p); });
  }

  // Makes this profile a Shape of kind `kind` built from `arg` (its Params, or a Shape to copy),
  // constructing only that alternative in place: no temporary variant, no copy of the largest
  // shape's bytes (the planner's hot path).
  template <typename Shape, typename Arg>
  const Shape& emplace(ProfileKind kind, const Arg& arg) noexcept {
    kind_ = kind;
    return v_.template emplace<Shape>(arg);
  }

  [[nodiscard]] ProfileKind kind() const noexcept { return kind_; }
  [[nodiscard]] const Variant& variant() const noexcept { return v_; }

  // Calls f with the concrete shape. One branch per alternative, generated: the last alternative
  // is reached only when index() names it (a variant has no index past its last alternative, and
  // cannot become valueless without exceptions). std::visit is avoided on purpose: it may throw
  // bad_variant_access, and core is built without exceptions.
  template <typename F>
  decltype(auto) visit(F&& f) const noexcept {
    return visit_from<0>(f);
  }

  // Split (kSplitEvaluation): a shape whose evaluation is a few multiply-adds (kInlineEvaluation:
  // the piecewise-jerk table) is tested first and evaluated here, inline in the caller; the others
  // (sine, cosine, pow) are called out of line, so that this dispatch stays small enough to inline
  // into Move::at and the stepper, whose per-tick cost is then the evaluator's own (bench/core:
  // BM_EvaluateBare* against BM_Evaluate* and BM_Step*).
  [[nodiscard]] Sample<T> at(T t) const noexcept {
    if constexpr (kSplitEvaluation) {
      return at_inline_from<0>(t);
    } else {
      return visit([t](const auto& p) { return p.at(t); });
    }
  }
  [[nodiscard]] T duration() const noexcept {
    return visit([](const auto& p) { return p.duration(); });
  }
  [[nodiscard]] T distance() const noexcept {
    return visit([](const auto& p) { return p.distance(); });
  }

 private:
  template <typename S>
  static constexpr bool inline_evaluation() noexcept {
    if constexpr (requires { S::kInlineEvaluation; }) {
      return S::kInlineEvaluation;
    } else {
      return false;
    }
  }
  template <typename S>
  [[gnu::noinline]] static Sample<T> at_out_of_line(const S& p, T t) noexcept {
    return p.at(t);
  }
  template <std::size_t I>
  [[nodiscard]] Sample<T> at_inline_from(T t) const noexcept {
    if constexpr (I == std::variant_size_v<Variant>) {
      return visit([t](const auto& p) {
        if constexpr (inline_evaluation<std::remove_cvref_t<decltype(p)>>()) {
          __builtin_unreachable();  // tested above
        }
        return at_out_of_line(p, t);
      });
    } else {
      if constexpr (inline_evaluation<std::variant_alternative_t<I, Variant>>()) {
        if (v_.index() == I) return std::get_if<I>(&v_)->at(t);
      }
      return at_inline_from<I + 1>(t);
    }
  }
  template <std::size_t I, typename F>
  decltype(auto) visit_from(F& f) const noexcept {
    if constexpr (I + 1 == std::variant_size_v<Variant>) {
      return f(*std::get_if<I>(&v_));
    } else {
      if (v_.index() == I) return f(*std::get_if<I>(&v_));
      return visit_from<I + 1>(f);
    }
  }
  // Stores, converted to T, a shape `p` that Profile<U> holds: the registry's first kind whose
  // Shape<U> is S names the shape, and its Shape<T> is stored. Looked up in the registry rather
  // than deduced through a template template parameter: PiecewiseJerk<T, N> has a second
  // (defaulted) parameter, and matching it to `template <typename> class` needs P0522, which
  // clang 14 does not do by default (the sanitizer preset's compiler).
  template <typename U, typename S, std::size_t I = 0>
  void assign(const S& p) noexcept {
    static_assert(I < kProfileCount, "not a registered profile's shape");
    using Descriptor = profile_t<static_cast<ProfileKind>(I)>;
    if constexpr (std::is_same_v<typename Descriptor::template Shape<U>, S>) {
      v_.template emplace<typename Descriptor::template Shape<T>>(p);
    } else {
      assign<U, S, I + 1>(p);
    }
  }

  ProfileKind kind_{};
  Variant v_{};
};

}  // namespace settle::core
