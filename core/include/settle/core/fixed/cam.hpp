// SPDX-License-Identifier: Apache-2.0
#pragma once
// Electronic cam: any planned Move as a table of (p, v, a) samples at evenly spaced ticks in the
// controller's memory, interpolated per tick by a linear, cubic (p, v) or quintic (p, v, a) Hermite
// polynomial. Seed 004's point: an optimised command is just such a table. Integer tick path.
#include <cstddef>
#include <cstdint>
#include <span>

#include "settle/core/fixed/format.hpp"
#include "settle/core/fixed/poly.hpp"
#include "settle/core/move.hpp"
#include "settle/core/status.hpp"

namespace settle::core::fixed {

enum class CamOrder : std::uint8_t { linear = 1, cubic = 3, quintic = 5 };

// One sample; the fraction bits are per table (CamFormats) so that short and long moves both use
// the whole 32 bits.
struct CamKnot {
  std::int32_t p{0};  // counts * 2^p_frac from the start of the move
  std::int32_t v{0};  // counts/tick * 2^v_frac
  std::int32_t a{0};  // counts/tick^2 * 2^a_frac
};

struct CamFormats {
  std::uint8_t log2_spacing{0};  // knots every 2^log2_spacing ticks
  std::uint8_t p_frac{0};
  std::uint8_t v_frac{0};
  std::uint8_t a_frac{0};
};

// What the builder measured against the double evaluator (|fixed - double|), on every tick of
// moves up to 2^18 ticks and on four ticks per interval of longer ones.
struct CamCheck {
  double p{0.0};  // counts
  double v{0.0};  // output LSB
  double a{0.0};  // output LSB
};

class CamTable {
 public:
  CamTable() = default;  // an empty table: at rest on 0

  [[nodiscard]] Sample at_tick(std::int32_t n) const noexcept;
  [[nodiscard]] std::int32_t end_tick() const noexcept { return end_tick_; }
  [[nodiscard]] std::int32_t target() const noexcept { return target_; }
  [[nodiscard]] std::size_t knots() const noexcept { return count_; }
  [[nodiscard]] CamOrder order() const noexcept { return order_; }
  [[nodiscard]] CamFormats formats() const noexcept { return fmt_; }
  [[nodiscard]] const CamCheck& check() const noexcept { return check_; }
  [[nodiscard]] bool steppable() const noexcept { return steppable_; }

  // The interpolating polynomial of interval k in its phase (Q32.32 counts), for the stepper.
  [[nodiscard]] Coeffs interval(std::size_t k) const noexcept;

 private:
  friend Status build_cam_table(const Move<double>&, const Scale&, CamOrder, std::span<CamKnot>, CamTable&,
                                double) noexcept;
  friend class CamStepper;
  [[nodiscard]] Sample finish(const Wide& w) const noexcept { return to_sample(w, out_vf_, out_af_); }
  [[nodiscard]] int degree() const noexcept { return static_cast<int>(order_); }
  const CamKnot* knots_{nullptr};
  std::size_t count_{0};
  CamOrder order_{CamOrder::linear};
  CamFormats fmt_{};
  std::uint8_t out_vf_{16}, out_af_{16};
  bool steppable_{false};
  std::int32_t target_{0};
  std::int32_t end_tick_{0};
  CamCheck check_{};
};

// Samples `move` into `storage` with the finest spacing (a power of two ticks) that fits, then
// checks the table against the double evaluator: table_too_small if the position error exceeds
// `tolerance_counts`. The table refers to `storage`, which must outlive it; on failure `out` is
// unchanged (the storage's contents are then unspecified).
[[nodiscard]] Status build_cam_table(const Move<double>& move, const Scale& scale, CamOrder order,
                                     std::span<CamKnot> storage, CamTable& out,
                                     double tolerance_counts = 1.0) noexcept;

// Stepping evaluation of a cam table: at each knot the interval's polynomial is turned into
// forward differences (exactly, the knot spacing being a power of two), then a tick is additions.
class CamStepper {
 public:
  CamStepper() = default;
  explicit CamStepper(const CamTable& t, std::int32_t first_tick = 0) noexcept : table_{&t}, n_{first_tick} {}
  void restart(std::int32_t n) noexcept {
    n_ = n;
    anchored_ = false;
  }
  [[nodiscard]] Sample next() noexcept;
  [[nodiscard]] std::int32_t tick() const noexcept { return n_; }

 private:
  const CamTable* table_{nullptr};
  Chains fd_{};
  std::int32_t n_{0};
  bool anchored_{false};
};

}  // namespace settle::core::fixed
