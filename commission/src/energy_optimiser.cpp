// SPDX-License-Identifier: Apache-2.0
#include "settle/commission/energy_optimiser.hpp"

#include <algorithm>
#include <cmath>

#include <complex>

#include <boost/math/quadrature/gauss.hpp>
#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "settle/core/pseudo_poly.hpp"

namespace settle::commission {

namespace {

struct Design {
  std::size_t n{0};
  std::array<double, core::kMaxGammas> g{};
  std::array<double, core::kMaxGammas> p2c{};  // P(gamma, 2) C
};

plant::SimStatus design(const std::vector<double>& gammas, Design& d) {
  if (gammas.size() < 3 || gammas.size() > core::kMaxGammas) return plant::SimStatus::bad_gammas;
  core::PseudoPolyParams pp{};
  if (core::pseudo_poly_design(1.0, 1.0, gammas.data(), gammas.size(), pp) != core::Status::ok) {
    return plant::SimStatus::bad_gammas;
  }
  d.n = gammas.size();
  for (std::size_t i = 0; i < d.n; ++i) {
    d.g[i] = gammas[i];
    d.p2c[i] = gammas[i] * (gammas[i] - 1.0) * pp.coeffs[i];
  }
  return plant::SimStatus::ok;
}

// I_k = (1/k!) int_0^1 a(u) (r u)^k e^{r u} du with r = (-xi w + i w_d) T and u = 1 - tau/T, where
// phi'' = -(Phi/T^2) a(u), a(u) = sum P2 C u^(g-2). Then F = -(Phi/T) Im I_0 and
// G = -(Phi/T) w Re(e^{i delta} I_0); I_1 is w times the derivative of I_0 in w (xi fixed): how
// fast the residual grows with a frequency error.
// A fixed composite Gauss-Legendre rule rather than an adaptive one: H must be a smooth function of
// the exponents for the optimiser's finite-difference Jacobian, and an adaptive rule that
// subdivides differently for nearby exponents is not (it also never stops when I is near 0, which
// is exactly where the optimiser goes). u^(g-2) is singular at u = 0, so the panels are dyadic
// there (each panel then sees the singularity at 3 half-widths: 16 nodes give ~1e-15), and
// uniform elsewhere with about 2 rad of oscillation per panel.
constexpr int kMaxOrder = 1;
using Moments = std::array<std::complex<double>, kMaxOrder + 1>;

Moments moments(const EnergyTarget& t, const Design& d, int order) {
  const double beta = std::sqrt(1.0 - t.zeta * t.zeta);
  const std::complex<double> rate{-t.zeta * t.omega * t.duration, t.omega * beta * t.duration};
  Moments sum{};
  using GL = boost::math::quadrature::gauss<double, 16>;
  auto panel = [&](double lo, double hi) {
    const double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo);
    const auto& x = GL::abscissa();
    const auto& w = GL::weights();
    for (std::size_t i = 0; i < x.size(); ++i) {
      for (double sgn : {-1.0, 1.0}) {
        const double u = mid + sgn * half * x[i];
        double a = 0.0;
        for (std::size_t j = 0; j < d.n; ++j) a += d.p2c[j] * std::pow(u, d.g[j] - 2.0);
        const std::complex<double> ru = rate * u;
        std::complex<double> term = half * w[i] * a * std::exp(ru);
        for (int k = 0; k <= order; ++k) {
          sum[static_cast<std::size_t>(k)] += term;
          term *= ru / static_cast<double>(k + 1);
        }
      }
    }
  };
  constexpr double kSplit = 1.0 / 64.0;
  double hi = kSplit;
  for (int k = 0; k < 54; ++k) {  // [2^-60, 1/64] in dyadic panels; below 2^-60 contributes < 1e-18
    panel(0.5 * hi, hi);
    hi *= 0.5;
  }
  const int panels = std::max(8, static_cast<int>(std::ceil(std::abs(rate) * (1.0 - kSplit) / 2.0)));
  const double width = (1.0 - kSplit) / panels;
  for (int k = 0; k < panels; ++k) panel(kSplit + k * width, kSplit + (k + 1) * width);
  return sum;
}

// (G, w F) from a moment: the two terms of H = G^2 + w^2 F^2.
void residual_pair(const EnergyTarget& t, const std::complex<double>& m, double& g, double& wf) {
  const double beta = std::sqrt(1.0 - t.zeta * t.zeta);
  const double k = -t.distance / t.duration * t.omega;
  g = k * (std::exp(std::complex<double>{0.0, std::atan2(t.zeta, beta)}) * m).real();
  wf = k * m.imag();
}

// Exponents from unconstrained parameters: g0 = min + e^p0, g_i = g_{i-1} + gap + e^p_i. Keeps them
// above 2 and ordered with a gap without any explicit constraint in the solver.
std::vector<double> to_gammas(const Eigen::VectorXd& p, const OptimiserOptions& o) {
  std::vector<double> g(static_cast<std::size_t>(p.size()));
  double prev = o.min_gamma - o.min_gap;
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    // Increments are capped at 20: beyond that a term is negligible except at u = 1 and the
    // solver would only chase it off to infinity.
    prev += o.min_gap + std::exp(std::min(p[i], std::log(20.0)));
    g[static_cast<std::size_t>(i)] = prev;
  }
  return g;
}

bool to_params(const std::vector<double>& g, const OptimiserOptions& o, Eigen::VectorXd& p) {
  p.resize(static_cast<Eigen::Index>(g.size()));
  double prev = o.min_gamma - o.min_gap;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double e = g[i] - prev - o.min_gap;
    if (!(e > 0.0)) return false;
    p[static_cast<Eigen::Index>(i)] = std::log(e);
    prev = g[i];
  }
  return true;
}

struct Residuals {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  const EnergyTarget* target;
  const OptimiserOptions* opt;
  int n_in;
  double scale;  // 1 / sqrt(H0): residuals of order 1 at the start
  mutable int evaluations{0};

  [[nodiscard]] int inputs() const { return n_in; }
  // H = G^2 + (w F)^2 is two squares, and MINPACK needs at least as many residuals as unknowns:
  // the extra rows are zero, which leaves the problem (and its curve of zero-energy solutions)
  // unchanged; from a point off the curve the damped Gauss-Newton steps reach a nearby point on it.
  [[nodiscard]] int values() const { return std::max(2, n_in); }

  int operator()(const Eigen::VectorXd& p, Eigen::VectorXd& fvec) const {
    ++evaluations;
    fvec.setZero(values());
    Design d;
    if (design(to_gammas(p, *opt), d) != plant::SimStatus::ok) {
      fvec.setConstant(1e6);
      return 0;
    }
    double g = 0.0, wf = 0.0;
    residual_pair(*target, moments(*target, d, 0)[0], g, wf);
    fvec[0] = scale * g;
    fvec[1] = scale * wf;
    return 0;
  }
};

}  // namespace

EnergyTarget belt_energy_target(const plant::BeltParams& p, double distance, double duration) {
  EnergyTarget t;
  const double kt = 2.0 * p.belt_stiffness * p.pulley_R * p.pulley_R;
  const double ct = 2.0 * p.belt_damping * p.pulley_R * p.pulley_R;
  t.omega = std::sqrt(kt / p.inertia);
  t.zeta = ct / (2.0 * p.inertia * t.omega);
  t.lambda = plant::belt_lambda(p);
  t.inertia = p.inertia;
  t.distance = distance;
  t.duration = duration;
  return t;
}

double energy_scale(const EnergyTarget& t) noexcept {
  const double wd = t.omega * std::sqrt(1.0 - t.zeta * t.zeta);
  return 0.5 * t.inertia * (t.lambda / wd) * (t.lambda / wd);
}

plant::SimStatus energy_integrals(const EnergyTarget& t, const std::vector<double>& gammas, EnergyIntegrals& out) {
  for (double v : {t.omega, t.zeta, t.lambda, t.inertia, t.distance, t.duration}) {
    if (!std::isfinite(v)) return plant::SimStatus::non_finite_parameter;
  }
  if (!(t.omega > 0.0)) return plant::SimStatus::non_positive_omega;
  if (!(t.zeta >= 0.0 && t.zeta < 1.0)) return plant::SimStatus::not_underdamped;
  if (!(t.duration > 0.0)) return plant::SimStatus::non_positive_step;
  // The quadrature takes a panel per 2 rad of w T: bounded before its panel count is converted.
  if (!(t.omega * t.duration <= plant::kMaxEnergyPhase)) return plant::SimStatus::too_many_samples;
  Design d;
  const plant::SimStatus st = design(gammas, d);
  if (st != plant::SimStatus::ok) return st;
  EnergyIntegrals r;
  double wf = 0.0;
  residual_pair(t, moments(t, d, 0)[0], r.g, wf);
  r.f = wf / t.omega;
  r.h_index = r.g * r.g + t.omega * t.omega * r.f * r.f;
  r.energy = energy_scale(t) * r.h_index;
  out = r;
  return plant::SimStatus::ok;
}

plant::SimStatus optimise_exponents(const EnergyTarget& t, const std::vector<double>& start, const OptimiserOptions& opt,
                             OptimiserResult& out) {
  EnergyIntegrals e0;
  plant::SimStatus st = energy_integrals(t, start, e0);
  if (st != plant::SimStatus::ok) return st;
  std::vector<double> sorted = start;
  std::sort(sorted.begin(), sorted.end());
  Eigen::VectorXd p;
  if (!to_params(sorted, opt, p)) return plant::SimStatus::bad_gammas;

  // H is two squares in n unknowns: besides its zero set it has stationary points with H > 0
  // where LM stalls, and with more than three exponents a regular start such as (3, 4, 5, 6) can
  // fall into one. Retry from the same start stretched and shifted (a fixed list, so results are
  // reproducible) until H is zero to rounding; keep the best.
  const double scale = e0.h_index > 0.0 ? 1.0 / std::sqrt(e0.h_index) : 1.0;
  constexpr double kStretch[] = {1.0, 0.5, 1.5, 2.0};
  constexpr double kShift[] = {0.0, 1.0, 2.0};
  const std::size_t stretches = opt.retry ? 4 : 1, shifts = opt.retry ? 3 : 1;
  OptimiserResult r;
  r.h_final = HUGE_VAL;
  int evaluations = 0, iterations = 0;
  for (std::size_t i = 0; i < shifts; ++i) {
    for (std::size_t k = 0; k < stretches; ++k) {
      const double shift = kShift[i], stretch = kStretch[k];
      std::vector<double> g = sorted;
      for (double& x : g) x = sorted[0] + shift + stretch * (x - sorted[0]);
      if (!to_params(g, opt, p)) continue;
      Residuals fn{&t, &opt, static_cast<int>(g.size()), scale};
      Eigen::NumericalDiff<Residuals> nd(fn);
      Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Residuals>> lm(nd);
      lm.parameters.maxfev = opt.max_evaluations;
      lm.parameters.xtol = 1e-15;
      lm.parameters.ftol = 1e-30;
      lm.parameters.gtol = 0.0;
      const auto info = lm.minimize(p);
      evaluations += nd.evaluations;  // NumericalDiff is a copy of fn that counts every call
      iterations += static_cast<int>(lm.iter);
      if (info == Eigen::LevenbergMarquardtSpace::ImproperInputParameters) continue;
      EnergyIntegrals e1;
      const std::vector<double> found = to_gammas(p, opt);
      if (energy_integrals(t, found, e1) != plant::SimStatus::ok || !(e1.h_index < r.h_final)) continue;
      r.gammas = found;
      r.h_final = e1.h_index;
      r.energy = e1.energy;
      if (r.h_final <= 1e-12 * e0.h_index) break;
    }
    if (r.h_final <= 1e-12 * e0.h_index) break;
  }
  if (!(r.h_final < e0.h_index)) return plant::SimStatus::optimiser_failed;
  {
    Design d;
    if (design(r.gammas, d) != plant::SimStatus::ok) return plant::SimStatus::optimiser_failed;
    const Moments mo = moments(t, d, 1);
    double g0 = 0.0, f0 = 0.0, g1 = 0.0, f1 = 0.0;
    residual_pair(t, mo[0], g0, f0);
    residual_pair(t, mo[1], g1, f1);
    r.slope = std::hypot(g0 + g1, f0 + f1);
  }
  r.h_initial = e0.h_index;
  r.evaluations = evaluations;
  r.iterations = iterations;
  out = std::move(r);
  return plant::SimStatus::ok;
}

}  // namespace settle::commission
