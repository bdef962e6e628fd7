// SPDX-License-Identifier: Apache-2.0
#include "settle/commission/identify.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <unsupported/Eigen/MatrixFunctions>
#include <utility>

namespace settle::commission {

namespace {
constexpr const char* kIdentifyStatusCodes[] = {SETTLE_IDENTIFY_STATUSES(SETTLE_ENUM_CODE)};
constexpr const char* kIdentifyStatusTexts[] = {SETTLE_IDENTIFY_STATUSES(SETTLE_ENUM_TEXT)};
}  // namespace

const char* to_string(IdentifyStatus s) noexcept { return core::enum_text(kIdentifyStatusCodes, s, "?"); }

const char* describe(IdentifyStatus s) noexcept { return core::enum_text(kIdentifyStatusTexts, s, "?"); }

namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kPi = 3.14159265358979323846;

struct Candidate {
  double omega;
  double zeta;
};

// One period of a mode's exact stepping (mode_response): the state's transition and the base
// velocity's input, from the matrix exponential.
struct ModeStep {
  double p00, p01, p10, p11, g0, g1;
};

ModeStep mode_step(double omega, double zeta, double period_s) {
  // State (q, r = q' - v) with v the base velocity, constant over each period: r is continuous
  // where v jumps, and within a period d/dt (q, r) = A (q, r) + B v exactly.
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  m(0, 1) = 1.0;
  m(1, 0) = -omega * omega;
  m(1, 1) = -2.0 * zeta * omega;
  m(0, 2) = 1.0;
  m(1, 2) = -2.0 * zeta * omega;
  const Eigen::Matrix3d e = (m * period_s).exp();
  return {e(0, 0), e(0, 1), e(1, 0), e(1, 1), e(0, 2), e(1, 2)};
}

// Several modes' responses to one motor record in one pass, column i of `q` for steps[i]: each
// recurrence alone is bound by its own latency, side by side they share it. The same arithmetic,
// in the same order, as mode_response for each.
template <std::size_t N>
void mode_responses(const std::array<ModeStep, N>& steps, double period_s, std::span<const double> x, MatrixXd& q) {
  std::array<double, N> s0{};
  std::array<double, N> s1{};
  const auto n = static_cast<std::size_t>(q.rows());
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < N; ++i) q(static_cast<Index>(k), static_cast<Index>(i)) = s0[i];
    if (k + 1 == n) break;
    const double v = (x[k + 1] - x[k]) / period_s;
    for (std::size_t i = 0; i < N; ++i) {
      const ModeStep& p = steps[i];
      const double a = p.p00 * s0[i] + p.p01 * s1[i] + p.g0 * v;
      s1[i] = p.p10 * s0[i] + p.p11 * s1[i] + p.g1 * v;
      s0[i] = a;
    }
  }
}

// The two-sided normal quantile of `confidence` (0.5..0.999), by bisection on erfc.
double normal_quantile(double confidence) {
  double lo = 0.0;
  double hi = 10.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > 1.0 - confidence ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Matrix pencil (Hua & Sarkar) on the free response z: a Hankel matrix of lagged windows, its
// singular values for the order (those standing out of the noise floor, at most max_order), and
// the eigenvalues of the shift between the windows' signal subspace for the poles. Complex pairs
// with damping below 0.95 become candidates; real poles (the rest position) are left out.
std::vector<Candidate> pencil(const VectorXd& z, double h, std::size_t max_order, std::size_t& order,
                              double& noise_rms) {
  const Index n = z.size();
  const Index cols = std::min<Index>(std::max<Index>(n / 3, 8), 100);
  const Index windows = n - cols + 1;
  // Every stride-th window: the shift invariance is along the columns, so rows can be thinned to
  // bound the cost; the nonlinear fit uses every sample afterwards.
  const Index stride = std::max<Index>(1, (windows + 999) / 1000);
  const Index rows = (windows + stride - 1) / stride;
  MatrixXd hk(rows, cols);
  for (Index i = 0; i < rows; ++i) hk.row(i) = z.segment(i * stride, cols).transpose();
  const Eigen::BDCSVD<MatrixXd> svd(hk, Eigen::ComputeThinV);
  const VectorXd& s = svd.singularValues();
  const Index cap = std::min<Index>(static_cast<Index>(max_order), cols - 2);
  // The noise floor: white noise of standard deviation sigma gives singular values of about
  // sigma (sqrt(rows) + sqrt(cols)); those past the largest order possible are noise.
  const Index tail_from = cap + 1;
  std::vector<double> tail(s.data() + tail_from, s.data() + s.size());
  std::nth_element(tail.begin(), tail.begin() + static_cast<std::ptrdiff_t>(tail.size() / 2), tail.end());
  const double median = tail[tail.size() / 2];
  noise_rms = median / (std::sqrt(static_cast<double>(rows)) + std::sqrt(static_cast<double>(cols)));
  const double floor = 1.5 * s(cap);
  Index k = 0;
  while (k < cap && s(k) > floor) ++k;
  order = static_cast<std::size_t>(k);
  std::vector<Candidate> out;
  if (k == 0) return out;
  const MatrixXd v1 = svd.matrixV().topLeftCorner(cols - 1, k);
  const MatrixXd v2 = svd.matrixV().block(1, 0, cols - 1, k);
  const MatrixXd shift = v1.completeOrthogonalDecomposition().solve(v2);
  const Eigen::EigenSolver<MatrixXd> eig(shift, false);
  for (Index i = 0; i < k; ++i) {
    const std::complex<double> lambda = eig.eigenvalues()(i);
    if (lambda.imag() <= 1e-9 || std::abs(lambda) < 1e-12) continue;  // real poles, and one of each pair
    const std::complex<double> p = std::log(lambda) / h;
    const double wn = std::abs(p);
    const double zeta = -p.real() / wn;
    // An undamped mode's pole can land just outside the unit circle in the noise.
    if (zeta > -0.02 && zeta < 0.95) out.push_back({wn, std::max(zeta, 0.0)});
  }
  return out;
}

// The load as the model explains it: rigid x motor + offset + sum_j g_j q_j, with the gains and
// the two rigid parameters from linear least squares for given (omega, zeta) of each mode.
struct Model {
  const VectorXd& x;  // motor, output units
  const VectorXd& y;  // load, output units
  double h;
  double load_count;  // one load count, output units
  // The lowest frequency the record resolves: one cycle over the free response (the scan of step 5
  // starts there). A fit that drives a mode below it has found drift, not a mode.
  double omega_min;

  // Regressors [x, 1, q_1 .. q_m] for the modes' parameters theta = (w_1, z_1, ...).
  [[nodiscard]] MatrixXd regressors(const VectorXd& theta) const {
    const Index m = theta.size() / 2;
    MatrixXd phi(x.size(), 2 + m);
    phi.col(0) = x;
    phi.col(1).setOnes();
    for (Index j = 0; j < m; ++j) mode_column(theta, j, phi);
    return phi;
  }
  // Mode j's column of the regressors, for theta's (w_j, z_j): a parameter of one mode changes
  // only its column, so the Jacobians recompute that one (the same numbers as regressors()).
  void mode_column(const VectorXd& theta, Index j, MatrixXd& phi) const {
    mode_response(theta(2 * j), theta(2 * j + 1), h, std::span<const double>{x.data(), static_cast<std::size_t>(x.size())},
                  std::span<double>{phi.col(2 + j).data(), static_cast<std::size_t>(x.size())});
  }
  // Least-squares linear parameters (columns scaled for conditioning) and the residual y - phi b.
  static VectorXd solve(const MatrixXd& phi, const VectorXd& y, VectorXd& residual) {
    VectorXd scale = phi.colwise().norm().transpose();
    for (Index i = 0; i < scale.size(); ++i) scale(i) = scale(i) > 0.0 ? scale(i) : 1.0;
    const MatrixXd scaled = phi * scale.cwiseInverse().asDiagonal();
    const VectorXd b = scaled.householderQr().solve(y).cwiseQuotient(scale);
    residual = y - phi * b;
    return b;
  }
  // The residual's sum of squares for theta, with its regressors `phi` and linear parameters.
  [[nodiscard]] double cost(const VectorXd& theta, VectorXd& residual, VectorXd& beta, MatrixXd& phi) const {
    phi = regressors(theta);
    beta = solve(phi, y, residual);
    return residual.squaredNorm();
  }
};

// Keeps the parameters physical: 0 < omega below Nyquist, 0 <= zeta <= 0.99 (an undamped mode,
// a beam's, is exactly 0).
void clamp(VectorXd& theta, double h) {
  for (Index j = 0; j < theta.size(); j += 2) {
    theta(j) = std::clamp(theta(j), 1e-3, 0.999 * kPi / h);
    theta(j + 1) = std::clamp(theta(j + 1), 0.0, 0.99);
  }
}

// Levenberg-Marquardt on the modes' (omega, zeta), the linear parameters projected out (variable
// projection), the Jacobian by forward differences.
double fit(const Model& model, VectorXd& theta, std::size_t& iterations) {
  VectorXd r;
  VectorXd beta;
  MatrixXd phi;  // theta's regressors
  double cost = model.cost(theta, r, beta, phi);
  double mu = 1e-3;
  const Index p = theta.size();
  MatrixXd jac(r.size(), p);
  VectorXd kept(r.size());
  for (int it = 0; it < 60; ++it) {
    ++iterations;
    for (Index k = 0; k < p; ++k) {
      VectorXd t = theta;
      const double step = (k % 2 == 0 ? 1e-6 * theta(k) : 1e-6 * std::max(theta(k), 1e-2));
      t(k) += step;
      // t's regressors are theta's but for mode k/2's column: swap it in, solve, put it back.
      kept = phi.col(2 + k / 2);
      model.mode_column(t, k / 2, phi);
      VectorXd rk;
      (void)Model::solve(phi, model.y, rk);
      phi.col(2 + k / 2) = kept;
      jac.col(k) = (rk - r) / step;
    }
    const MatrixXd jtj = jac.transpose() * jac;
    const VectorXd g = jac.transpose() * r;
    bool improved = false;
    for (int tries = 0; tries < 12 && !improved; ++tries) {
      MatrixXd a = jtj;
      a.diagonal() += mu * jtj.diagonal().cwiseMax(1e-300);
      VectorXd t = theta - a.ldlt().solve(g);
      clamp(t, model.h);
      VectorXd rt;
      VectorXd bt;
      MatrixXd pt;
      const double c = model.cost(t, rt, bt, pt);
      if (std::isfinite(c) && c < cost) {
        const double gain = (cost - c) / cost;
        theta = t;
        r = rt;
        phi = std::move(pt);
        cost = c;
        mu = std::max(mu / 5.0, 1e-12);
        improved = true;
        if (gain < 1e-12) return cost;
      } else {
        mu *= 8.0;
      }
    }
    if (!improved) break;
  }
  return cost;
}

struct Uncertainty {
  VectorXd peak;  // per mode: the largest |g_j q_j| over the record, output units
  VectorXd theta_sd;
  VectorXd beta;
  VectorXd beta_sd;
  double rss{0.0};
};

// The covariance of every parameter from the full Jacobian at the optimum, s^2 (J'J)^-1 with s^2
// the residual variance: the first-order (Gauss-Newton) confidence region.
Uncertainty uncertainty(const Model& model, const VectorXd& theta) {
  Uncertainty u{};
  VectorXd r;
  const MatrixXd phi = model.regressors(theta);
  u.beta = Model::solve(phi, model.y, r);
  u.rss = r.squaredNorm();
  const Index p = theta.size();
  u.peak.resize(p / 2);
  for (Index j = 0; j < p / 2; ++j) u.peak(j) = std::fabs(u.beta(2 + j)) * phi.col(2 + j).cwiseAbs().maxCoeff();
  const Index q = phi.cols();
  const Index n = r.size();
  MatrixXd jac(n, p + q);
  MatrixXd pk = phi;
  for (Index k = 0; k < p; ++k) {
    VectorXd t = theta;
    const double step = (k % 2 == 0 ? 1e-6 * theta(k) : 1e-6 * std::max(theta(k), 1e-2));
    t(k) += step;
    // Only mode k/2's column moves with its parameters.
    model.mode_column(t, k / 2, pk);
    jac.col(k) = (pk.col(2 + k / 2) - phi.col(2 + k / 2)) * u.beta(2 + k / 2) / step;
    pk.col(2 + k / 2) = phi.col(2 + k / 2);
  }
  jac.rightCols(q) = phi;
  VectorXd scale = jac.colwise().norm().transpose();
  for (Index i = 0; i < scale.size(); ++i) scale(i) = scale(i) > 0.0 ? scale(i) : 1.0;
  const MatrixXd js = jac * scale.cwiseInverse().asDiagonal();
  const MatrixXd inv = (js.transpose() * js).ldlt().solve(MatrixXd::Identity(p + q, p + q));
  const double s2 = u.rss / static_cast<double>(std::max<Index>(n - p - q, 1));
  const VectorXd var = inv.diagonal().cwiseQuotient(scale.cwiseAbs2()) * s2;
  const VectorXd sd = var.cwiseMax(0.0).cwiseSqrt();
  u.theta_sd = sd.head(p);
  u.beta_sd = sd.tail(q);
  return u;
}

// A fitted mode damped more than this may be two overlapping modes: it is tried split in two.
constexpr double kSplitZeta = 0.2;
// A fit whose rms residual is more than this many times the noise the pencil measured has not
// explained the record (one that does leaves 1.33-1.38 times it: the pencil's estimate is low).
constexpr double kPoorFit = 2.0;
// How many rounds of replacing modes (step 6) the estimate tries at most.
constexpr int kMaxReplacements = 8;

VectorXd without_mode(const VectorXd& theta, Index j) {
  VectorXd t(theta.size() - 2);
  t << theta.head(2 * j), theta.tail(theta.size() - 2 * j - 2);
  return t;
}

// Fits theta, then drops the least significant mode until every one left stands out of the noise
// (gain at least min_significance standard errors, frequency determined), there are at most
// max_modes, and each moves the load by at least min_relative_deflection of the largest mode's
// peak (|g_j q_j| over the record: a mode's share of the deflection, not its gain g_j, which
// scales as omega_j^2 for the same deflection). `u` is the final fit's.
void prune(const Model& model, const IdentifyOptions& opt, double noise_rms, VectorXd& theta, Uncertainty& u,
           std::size_t& iterations) {
  while (theta.size() > 0) {
    (void)fit(model, theta, iterations);
    u = uncertainty(model, theta);
    const Index m = theta.size() / 2;
    Index weakest = 0;
    double weakest_t = std::numeric_limits<double>::infinity();
    double largest = 0.0;
    for (Index j = 0; j < m; ++j) {
      const double g = std::fabs(u.beta(2 + j));
      const double t = u.beta_sd(2 + j) > 0.0 ? g / u.beta_sd(2 + j) : std::numeric_limits<double>::infinity();
      bool undetermined = !(u.theta_sd(2 * j) < 0.5 * theta(2 * j)) || !std::isfinite(u.theta_sd(2 * j + 1)) ||
                          theta(2 * j) < model.omega_min;
      // A mode that never moves the load by more than a few counts (and three times the noise, or
      // the fit's rms if that is lower) is not measured: it is what the model cannot otherwise
      // explain (quantisation, a drive whose motion between samples is not linear). Not the fit's
      // rms alone: while a real mode is still missing (two slow modes the pencil saw as one) the
      // rms is that mode's, far above the noise, and would prune every mode that is there.
      const double rms = std::sqrt(u.rss / static_cast<double>(model.y.size()));
      const double floor = 3.0 * std::min(rms, noise_rms);
      undetermined = undetermined || u.peak(j) < std::max(3.0 * model.load_count, floor);
      // Two modes at one frequency are one mode split in two (their gains cancel): drop one.
      for (Index k = 0; k < j; ++k) undetermined = undetermined || std::fabs(theta(2 * k) / theta(2 * j) - 1.0) < 0.02;
      const double score = undetermined ? 0.0 : t;
      if (score < weakest_t) {
        weakest_t = score;
        weakest = j;
      }
      largest = std::max(largest, u.peak(j));
    }
    if (weakest_t < opt.min_significance || m > static_cast<Index>(opt.max_modes)) {
      theta = without_mode(theta, weakest);
      continue;
    }
    Index smallest = 0;
    for (Index j = 1; j < m; ++j) {
      if (u.peak(j) < u.peak(smallest)) smallest = j;
    }
    if (u.peak(smallest) < opt.min_relative_deflection * largest) {
      theta = without_mode(theta, smallest);
      continue;
    }
    return;
  }
  u = uncertainty(model, theta);
}

// The (omega, zeta) on a grid (omega from omega_lo to 0.9 Nyquist in 8 % steps; zeta 0.02, 0.08,
// 0.25) whose mode response, added to theta's regressors, most reduces the residual: the
// projection of the residual on the new column once the existing ones are projected out.
// Frequencies within 1.2 times `avoid` (if positive) are skipped.
Eigen::Vector2d best_addition(const Model& model, const VectorXd& theta, double omega_lo, double avoid = 0.0) {
  const MatrixXd phi = model.regressors(theta);
  const Eigen::HouseholderQR<MatrixXd> qr(phi);
  const MatrixXd q = qr.householderQ() * MatrixXd::Identity(phi.rows(), phi.cols());
  const VectorXd r = model.y - q * (q.transpose() * model.y);
  constexpr std::array<double, 3> zetas{0.02, 0.08, 0.25};
  MatrixXd responses(model.x.size(), static_cast<Index>(zetas.size()));
  VectorXd u(model.x.size());
  Eigen::Vector2d best{omega_lo, 0.05};
  double best_score = -1.0;
  const std::span<const double> xs{model.x.data(), static_cast<std::size_t>(model.x.size())};
  for (double w = omega_lo; w < 0.9 * kPi / model.h; w *= 1.08) {
    if (avoid > 0.0 && w > avoid / 1.2 && w < avoid * 1.2) continue;
    // The three damping ratios' responses at this frequency in one pass.
    std::array<ModeStep, zetas.size()> steps{};
    for (std::size_t i = 0; i < zetas.size(); ++i) steps[i] = mode_step(w, zetas[i], model.h);
    mode_responses(steps, model.h, xs, responses);
    for (std::size_t i = 0; i < zetas.size(); ++i) {
      const double zeta = zetas[i];
      u = responses.col(static_cast<Index>(i));
      u -= q * (q.transpose() * u);
      const double uu = u.squaredNorm();
      if (!(uu > 0.0)) continue;
      const double ur = u.dot(r);
      const double score = ur * ur / uu;
      if (score > best_score) {
        best_score = score;
        best = {w, zeta};
      }
    }
  }
  return best;
}

}  // namespace

void mode_response(double omega, double zeta, double period_s, std::span<const double> x, std::span<double> q) {
  const ModeStep st = mode_step(omega, zeta, period_s);
  const double p00 = st.p00, p01 = st.p01, p10 = st.p10, p11 = st.p11, g0 = st.g0, g1 = st.g1;
  double s0 = 0.0;
  double s1 = 0.0;
  const std::size_t n = std::min(x.size(), q.size());
  for (std::size_t k = 0; k < n; ++k) {
    q[k] = s0;
    if (k + 1 == n) break;
    const double v = (x[k + 1] - x[k]) / period_s;
    const double a = p00 * s0 + p01 * s1 + g0 * v;
    s1 = p10 * s0 + p11 * s1 + g1 * v;
    s0 = a;
  }
}

namespace {

// The estimator's steps (docs/identification.md, "The estimate") as named stages. One fit is the
// modes' (omega, zeta) in theta with the uncertainty of its last refit.
struct Fit {
  VectorXd theta;
  Uncertainty u;
};

// Step 1: the input checked, and the motion's window in the record (res.motion_start/end).
IdentifyStatus check_record(const IdentifyInput& in, const IdentifyOptions& opt, IdentifyResult& res) {
  const std::size_t n = in.motor.size();
  const bool scales_ok = std::isfinite(in.period_s) && in.period_s > 0.0 && std::isfinite(in.counts_per_unit) &&
                         in.counts_per_unit > 0.0 && std::isfinite(in.load_counts_per_unit) &&
                         in.load_counts_per_unit > 0.0;
  if (n != in.load.size() || !scales_ok || opt.max_modes < 1 || opt.max_modes > kMaxIdentifyModes ||
      !(opt.confidence >= 0.5 && opt.confidence <= 0.999) ||
      !(opt.min_relative_deflection >= 0.0 && opt.min_relative_deflection < 1.0) || !(opt.min_significance > 0.0)) {
    return IdentifyStatus::bad_input;
  }
  if (n > kMaxIdentifySamples) return IdentifyStatus::too_many_samples;
  std::size_t first = 0;
  while (first < n && in.motor[first] == in.motor[0]) ++first;
  if (first >= n) return IdentifyStatus::no_motion;
  std::size_t end = n;
  while (end > 0 && in.motor[end - 1] == in.motor[n - 1]) --end;
  res.motion_start = first;
  res.motion_end = end;
  if (n - end < kMinFreeSamples) return IdentifyStatus::free_response_too_short;
  return IdentifyStatus::ok;
}

// Fits, prunes and grows: every fit of steps 3-6 goes through one Estimator, which holds the
// record's model, the options, the pencil's noise estimate and the iteration count.
class Estimator {
 public:
  Estimator(const Model& model, const IdentifyOptions& opt, IdentifyResult& res) : model_(model), opt_(opt), res_(res) {}

  // Steps 3 and 4 from theta's start.
  [[nodiscard]] Fit pruned(VectorXd theta) const {
    Fit f{std::move(theta), {}};
    prune(model_, opt_, res_.noise_rms, f.theta, f.u, res_.iterations);
    return f;
  }
  // Step 5: while there is room, the scan's best addition, kept if it survives the pruning.
  void grow(Fit& f) const {
    while (f.theta.size() / 2 < static_cast<Index>(opt_.max_modes)) {
      VectorXd trial(f.theta.size() + 2);
      trial << f.theta, best_addition(model_, f.theta, model_.omega_min);
      Fit t = pruned(std::move(trial));
      if (t.theta.size() <= f.theta.size()) break;
      f = std::move(t);
    }
  }
  // A fit that has not explained the record (kPoorFit times the pencil's noise).
  [[nodiscard]] bool poor(const Fit& f) const {
    return std::sqrt(f.u.rss / static_cast<double>(model_.y.size())) > kPoorFit * res_.noise_rms;
  }
  // Step 5's scan twice: the best mode for the residual of `rest`, then the best one at least
  // 1.2 times away from it.
  [[nodiscard]] VectorXd scan_pair(const VectorXd& rest) const {
    const Eigen::Vector2d pick = best_addition(model_, rest, model_.omega_min);
    VectorXd one(rest.size() + 2);
    one << rest, pick;
    VectorXd pair(rest.size() + 4);
    pair << one, best_addition(model_, one, model_.omega_min, pick(0));
    return pair;
  }
  [[nodiscard]] const Model& model() const noexcept { return model_; }
  [[nodiscard]] const IdentifyOptions& options() const noexcept { return opt_; }

 private:
  const Model& model_;
  const IdentifyOptions& opt_;
  IdentifyResult& res_;
};

// Step 2: the pencil's candidates on the free response (mean removed: the rest position is a pole
// at 1), sorted by frequency and clamped, as theta.
VectorXd pencil_start(const VectorXd& y, std::size_t end, double h, std::size_t max_modes, IdentifyResult& res) {
  const auto ni = y.size();
  VectorXd z = y.tail(ni - static_cast<Index>(end));
  z.array() -= z.mean();
  std::vector<Candidate> cands = pencil(z, h, 2 * max_modes + 1, res.pencil_order, res.noise_rms);
  std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) { return a.omega < b.omega; });
  VectorXd theta(2 * static_cast<Index>(cands.size()));
  for (std::size_t j = 0; j < cands.size(); ++j) {
    theta(2 * static_cast<Index>(j)) = cands[j].omega;
    theta(2 * static_cast<Index>(j) + 1) = cands[j].zeta;
  }
  clamp(theta, h);
  return theta;
}

// Steps 2-5: the fit from the pencil's start, grown; when it leaves more than kPoorFit times the
// noise, the same from the scan alone, and the start whose fit explains more of the record stays.
Fit first_fit(const Estimator& est, VectorXd pencil_theta) {
  Fit f = est.pruned(std::move(pencil_theta));
  est.grow(f);
  if (f.theta.size() == 0 || est.poor(f)) {
    Fit scanned{VectorXd(0), {}};
    scanned.u.rss = std::numeric_limits<double>::infinity();
    est.grow(scanned);
    if (scanned.theta.size() > 0 && (f.theta.size() == 0 || scanned.u.rss < f.u.rss)) f = std::move(scanned);
  }
  return f;
}

// One round of step 6: every broad mode (or every mode, when the fit is poor) replaced by two, in
// each way the step lists; the best replacement of all, or `f` itself when none helps.
Fit best_replacement(const Estimator& est, const Fit& f) {
  const double h = est.model().h;
  const bool poor = est.poor(f);
  const bool room = f.theta.size() / 2 < static_cast<Index>(est.options().max_modes);
  Fit best = f;
  const auto consider = [&](VectorXd trial) {
    clamp(trial, h);
    Fit t = est.pruned(std::move(trial));
    const bool more = t.theta.size() > f.theta.size() && t.u.rss < best.u.rss;
    const bool as_many = t.theta.size() == f.theta.size() && t.u.rss < 0.8 * best.u.rss;
    if (more || as_many) best = std::move(t);
  };
  const Index m = f.theta.size() / 2;
  const auto tried = [&](Index j) { return poor || f.theta(2 * j + 1) >= kSplitZeta; };
  for (Index j = 0; j < m; ++j) {
    if (!tried(j)) continue;
    const double w = f.theta(2 * j);
    const double zj = f.theta(2 * j + 1);
    const VectorXd rest = without_mode(f.theta, j);
    if (!room) {
      // No room for one more: the mode and each other one are replaced by the scan's two (a
      // pair once: an earlier mode that is tried itself has been paired with this one).
      for (Index k = 0; k < m; ++k) {
        if (k == j || (k < j && tried(k))) continue;
        consider(est.scan_pair(without_mode(rest, k < j ? k : k - 1)));
      }
      continue;
    }
    if (zj >= kSplitZeta) {  // broad: also the symmetric splits
      for (const double width : {0.4, 0.8}) {
        const double spread = std::min(width * zj, 0.9);
        VectorXd trial(f.theta.size() + 2);
        trial << rest, w * (1.0 - spread), 0.5 * zj, w * (1.0 + spread), 0.5 * zj;
        consider(trial);
      }
    }
    consider(est.scan_pair(rest));
  }
  return best;
}

// Step 7 and the result: the modes with their intervals, sorted by frequency, and the fit's record.
void report(const Model& model, const Fit& f, double confidence, IdentifyResult& res) {
  const double zq = normal_quantile(confidence);
  const Index m = f.theta.size() / 2;
  for (Index j = 0; j < m; ++j) {
    UncertainMode md{};
    md.omega = f.theta(2 * j);
    md.zeta = f.theta(2 * j + 1);
    md.gain = f.u.beta(2 + j);
    md.omega_sd = f.u.theta_sd(2 * j);
    md.zeta_sd = f.u.theta_sd(2 * j + 1);
    md.gain_sd = f.u.beta_sd(2 + j);
    md.omega_lo = std::max(md.omega - zq * md.omega_sd, 0.0);
    md.omega_hi = md.omega + zq * md.omega_sd;
    md.zeta_lo = std::max(md.zeta - zq * md.zeta_sd, 0.0);
    md.zeta_hi = md.zeta + zq * md.zeta_sd;
    res.modes.push_back(md);
  }
  std::sort(res.modes.begin(), res.modes.end(),
            [](const UncertainMode& a, const UncertainMode& b) { return a.omega < b.omega; });
  const MatrixXd phi = model.regressors(f.theta);
  const VectorXd fitted = phi * f.u.beta;
  res.fitted_load.assign(fitted.data(), fitted.data() + fitted.size());
  res.rms_residual = std::sqrt(f.u.rss / static_cast<double>(model.y.size()));
  res.rigid_gain = f.u.beta(0);
  res.offset = f.u.beta(1);
  res.peak_deflection = (phi.rightCols(m) * f.u.beta.tail(m)).cwiseAbs().maxCoeff();
  res.order = 2 * static_cast<std::size_t>(m);
}

}  // namespace

IdentifyResult identify_modes(const IdentifyInput& in, const IdentifyOptions& opt) {
  IdentifyResult res{};
  res.status = check_record(in, opt, res);
  if (res.status != IdentifyStatus::ok) return res;
  const double h = in.period_s;
  const auto ni = static_cast<Index>(in.motor.size());
  VectorXd x(ni);
  VectorXd y(ni);
  for (Index k = 0; k < ni; ++k) {
    x(k) = in.motor[static_cast<std::size_t>(k)] / in.counts_per_unit;
    y(k) = in.load[static_cast<std::size_t>(k)] / in.load_counts_per_unit;
  }
  VectorXd start = pencil_start(y, res.motion_end, h, opt.max_modes, res);
  const double t_free = static_cast<double>(in.motor.size() - res.motion_end) * h;
  const Model model{x, y, h, 1.0 / in.load_counts_per_unit, 2.0 * kPi / t_free};
  const Estimator est(model, opt, res);
  Fit f = first_fit(est, std::move(start));
  // Step 6: merged modes replaced, at most kMaxReplacements rounds, while a round lowers the residual.
  for (int round = 0; round < kMaxReplacements && f.theta.size() > 0; ++round) {
    Fit next = best_replacement(est, f);
    if (!(next.u.rss < f.u.rss)) break;
    f = std::move(next);
  }
  if (f.theta.size() == 0) {
    res.status = IdentifyStatus::response_too_small;
    return res;
  }
  report(model, f, opt.confidence, res);
  res.status = IdentifyStatus::ok;
  return res;
}

}  // namespace settle::commission
