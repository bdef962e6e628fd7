// SPDX-License-Identifier: Apache-2.0
#include "settle/core/fixed/poly.hpp"

#include "settle/core/fixed/qmath.hpp"

namespace settle::core::fixed {

namespace {

// Delta^i of j^k at j = 0, i.e. i! S(k, i) (Stirling numbers of the second kind).
constexpr std::int64_t kDiff[kMaxDegree + 1][kMaxDegree + 1] = {
    {1, 0, 0, 0, 0, 0},   {0, 1, 0, 0, 0, 0},     {0, 1, 2, 0, 0, 0},
    {0, 1, 6, 6, 0, 0},   {0, 1, 14, 36, 24, 0},  {0, 1, 30, 150, 240, 120}};

// n (n-1) ... (n-r+1): the factor a derivative of order r brings to the coefficient of j^n.
constexpr std::int64_t falling(int n, int r) noexcept {
  std::int64_t f = 1;
  for (int k = 0; k < r; ++k) f *= n - k;
  return f;
}

// F_i - 32 for every order: prefix sums of the shifts.
std::array<int, kMaxDegree + 1> scales(const Shifts& sh) noexcept {
  std::array<int, kMaxDegree + 1> f{};
  for (int i = 1; i <= kMaxDegree; ++i) f[static_cast<unsigned>(i)] = f[static_cast<unsigned>(i - 1)] + sh[static_cast<unsigned>(i)];
  return f;
}

// kDiff[m][i] falling(m + r, r): the weight of b_{m+r} in element i of chain r, for r = 0, 1, 2
// (at most 240). A table, so that anchoring a chain (a cam table's stepper does it at every knot)
// makes one product per term, not three, and a small one (mul_small: on a Cortex-M0 three 32-bit
// products instead of a library call each); zero weights are skipped.
using Weights = std::array<std::array<std::array<std::uint32_t, kMaxDegree + 1>, kMaxDegree + 1>, 3>;
constexpr Weights kWeight = [] {
  Weights w{};
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned i = 0; i <= kMaxDegree; ++i) {
      for (unsigned m = i; m + r <= kMaxDegree; ++m) {
        w[r][i][m] = static_cast<std::uint32_t>(kDiff[m][i] * falling(static_cast<int>(m + r), static_cast<int>(r)));
      }
    }
  }
  return w;
}();
static_assert([] {
  for (const auto& chain : kWeight) {
    for (const auto& row : chain) {
      for (const std::uint32_t x : row) {
        if (x >= 0x10000U) return false;
      }
    }
  }
  return true;
}(), "mul_small takes factors below 2^16");

// Chain of derivative order r: element i is Delta^i of the r-th derivative, at scale F_{i+r}.
void init_chain(std::int64_t* x, int r, const Coeffs& b, int degree, const std::array<int, kMaxDegree + 1>& f) noexcept {
  const auto& w = kWeight[static_cast<unsigned>(r)];
  for (int i = 0; i + r <= degree; ++i) {
    std::int64_t acc = 0;
    for (int m = i; m + r <= degree; ++m) {
      const std::uint32_t weight = w[static_cast<unsigned>(i)][static_cast<unsigned>(m)];
      if (weight == 0) continue;
      const auto k = static_cast<unsigned>(m + r);
      acc += mul_small(shift(b[k], f[k] - f[static_cast<unsigned>(i + r)]), weight);
    }
    x[i] = acc;
  }
}

}  // namespace

void chains_init(const Coeffs& b, int degree, const Shifts& sh, Chains& out) noexcept {
  const auto f = scales(sh);
  init_chain(out.p.data(), 0, b, degree, f);
  init_chain(out.v.data(), 1, b, degree, f);
  init_chain(out.a.data(), 2, b, degree, f);
}

}  // namespace settle::core::fixed
