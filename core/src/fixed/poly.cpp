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

// Chain of derivative order r: element i is Delta^i of the r-th derivative, at scale F_{i+r}.
void init_chain(std::int64_t* x, int r, const Coeffs& b, int degree, const std::array<int, kMaxDegree + 1>& f) noexcept {
  for (int i = 0; i + r <= degree; ++i) {
    std::int64_t acc = 0;
    for (int m = i; m + r <= degree; ++m) {
      const auto k = static_cast<unsigned>(m + r);
      acc += kDiff[m][i] * falling(m + r, r) * shift(b[k], f[k] - f[static_cast<unsigned>(i + r)]);
    }
    x[i] = acc;
  }
}

void step_chain(std::int64_t* x, int r, int degree, const Shifts& sh) noexcept {
  for (int i = 0; i + r < degree; ++i) x[i] += shift(x[i + 1], sh[static_cast<unsigned>(i + r + 1)]);
}

}  // namespace

void taylor_shift(Coeffs& c, int degree, std::uint32_t s31, int passes) noexcept {
  for (int k = 0; k < passes; ++k) {
    for (int i = degree - 1; i >= k; --i) {
      c[static_cast<unsigned>(i)] += mul_shr(c[static_cast<unsigned>(i + 1)], s31, 31U);
    }
  }
}

void taylor_refine(Coeffs& t, int degree, std::uint32_t lo, int count) noexcept {
  for (int k = 0; k < count && k < degree; ++k) {
    t[static_cast<unsigned>(k)] += (k + 1) * mul_shr(t[static_cast<unsigned>(k + 1)], lo, 63U);
  }
}

void chains_init(const Coeffs& b, int degree, const Shifts& sh, Chains& out) noexcept {
  const auto f = scales(sh);
  init_chain(out.p.data(), 0, b, degree, f);
  init_chain(out.v.data(), 1, b, degree, f);
  init_chain(out.a.data(), 2, b, degree, f);
}

void chains_step(Chains& ch, int degree, const Shifts& sh) noexcept {
  step_chain(ch.p.data(), 0, degree, sh);
  step_chain(ch.v.data(), 1, degree, sh);
  step_chain(ch.a.data(), 2, degree, sh);
}

Wide chains_value(const Chains& ch, int degree, const Shifts& sh) noexcept {
  Wide w{ch.p[0], 0, 0};
  if (degree >= 1) w.v = shift(ch.v[0], sh[1]);
  if (degree >= 2) w.a = shift(ch.a[0], sh[1] + sh[2]);
  return w;
}

}  // namespace settle::core::fixed
