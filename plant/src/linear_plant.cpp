// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/linear_plant.hpp"

#include <algorithm>
#include <cmath>

#include <unsupported/Eigen/MatrixFunctions>

namespace settle::plant {

namespace {

constexpr std::size_t kCacheSize = 8;
constexpr int kMinChain = 3;  // the chain always carries y, y', y'' because B may use all three

}  // namespace

SimStatus LinearPlant::make(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c,
                            const Eigen::MatrixXd& d, LinearPlant& out) {
  const Eigen::Index n = a.rows();
  if (n == 0 || a.cols() != n || b.rows() != n || b.cols() != 3 || c.cols() != n || d.rows() != c.rows() ||
      d.cols() != 3) {
    return SimStatus::dimension_mismatch;
  }
  if (static_cast<std::size_t>(n) > kMaxStates) return SimStatus::too_many_modes;
  if (!a.allFinite() || !b.allFinite() || !c.allFinite() || !d.allFinite()) return SimStatus::non_finite_parameter;
  LinearPlant p;
  p.a_ = a;
  p.b_ = b;
  p.c_ = c;
  p.d_ = d;
  p.jump_y_ = b.col(1) + a * b.col(2);
  p.x_ = Eigen::VectorXd::Zero(n);
  out = std::move(p);
  out.reset(0.0);
  return SimStatus::ok;
}

Eigen::VectorXd LinearPlant::rest_state(double y) const {
  if (b_.col(0).isZero(0.0)) return Eigen::VectorXd::Zero(a_.rows());
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(a_);
  if (!lu.isInvertible()) return Eigen::VectorXd::Zero(a_.rows());
  return -lu.solve(b_.col(0)) * y;
}

void LinearPlant::reset(double base_position, double time) {
  x_ = rest_state(base_position);
  base_ = BaseState{base_position, 0.0, 0.0};
  t_ = time;
}

void LinearPlant::set_state(const Eigen::VectorXd& x, const BaseState& base, double time) {
  if (x.size() == x_.size()) x_ = x;
  base_ = base;
  t_ = time;
}

double LinearPlant::output(Eigen::Index row) const {
  return c_.row(row).dot(x_) + d_(row, 0) * base_.p + d_(row, 1) * base_.v + d_(row, 2) * base_.a;
}

const LinearPlant::Transition& LinearPlant::transition(double dt, int degree) {
  const int chain = std::max(degree + 1, kMinChain);
  if (last_ < cache_.size() && cache_[last_].dt == dt && cache_[last_].chain == chain) return cache_[last_];
  for (std::size_t i = 0; i < cache_.size(); ++i) {
    if (cache_[i].dt == dt && cache_[i].chain == chain) {
      last_ = i;
      return cache_[i];
    }
  }
  // Augmented state z = [x; y; y'; ...; y^(chain-1)]: the base derivatives form a chain of
  // integrators ending in y^(chain-1)' = 0, which is exact for a polynomial of degree < chain.
  const Eigen::Index n = a_.rows();
  const Eigen::Index m = n + chain;
  Eigen::MatrixXd big = Eigen::MatrixXd::Zero(m, m);
  big.topLeftCorner(n, n) = a_;
  big.block(0, n, n, 3) = b_;
  for (Eigen::Index i = 0; i + 1 < chain; ++i) big(n + i, n + i + 1) = 1.0;
  const Eigen::MatrixXd e = (big * dt).exp();
  Transition tr;
  tr.dt = dt;
  tr.chain = chain;
  tr.phi = e.topLeftCorner(n, n);
  tr.gamma = e.block(0, n, n, chain);
  // Columns act on y^(k)(0) = k! c[k]; fold the factorials in once.
  double f = 1.0;
  for (Eigen::Index k = 0; k < chain; ++k) {
    if (k > 0) f *= static_cast<double>(k);
    tr.gamma.col(k) *= f;
  }
  tr.packed.resize(n, n + chain);
  tr.packed << tr.phi, tr.gamma;
  if (cache_.size() < kCacheSize) {
    cache_.push_back(std::move(tr));
    last_ = cache_.size() - 1;
    return cache_.back();
  }
  last_ = evict_;
  Transition& slot = cache_[evict_];
  evict_ = (evict_ + 1) % kCacheSize;
  slot = std::move(tr);
  return slot;
}

SimStatus LinearPlant::advance(double dt, const BasePolynomial& base) {
  if (!(dt > 0.0) || !std::isfinite(dt)) return SimStatus::non_positive_step;
  if (base.degree < 0 || base.degree > kMaxBaseDegree) return SimStatus::degree_too_high;
  for (int k = 0; k <= base.degree; ++k) {
    if (!std::isfinite(base.c[static_cast<std::size_t>(k)])) return SimStatus::non_finite_input;
  }
  jump_base({base.c[0], base.degree >= 1 ? base.c[1] : 0.0, base.degree >= 2 ? 2.0 * base.c[2] : 0.0});
  const Transition& tr = transition(dt, base.degree);
  // x(dt) = [Phi | Gamma] [x; c], written as plain loops over contiguous rows: for the few states
  // of a plant this beats Eigen's dynamic-size products, and it is the whole per-step cost.
  const Eigen::Index n = a_.rows();
  const Eigen::Index m = n + base.degree + 1;
  const Eigen::Index stride = tr.packed.cols();
  // make() bounds the states by kMaxStates, so the step needs no heap (a simulated drive steps
  // in its receive path).
  constexpr auto kStack = static_cast<Eigen::Index>(kMaxStates);
  double z[kStack + kMaxBaseDegree + 1];
  double out[kStack];
  for (Eigen::Index j = 0; j < n; ++j) z[j] = x_[j];
  for (int k = 0; k <= base.degree; ++k) z[n + k] = base.c[static_cast<std::size_t>(k)];
  const double* row = tr.packed.data();
  for (Eigen::Index i = 0; i < n; ++i, row += stride) {
    double acc = 0.0;
    for (Eigen::Index j = 0; j < m; ++j) acc += row[j] * z[j];
    out[i] = acc;
  }
  for (Eigen::Index i = 0; i < n; ++i) x_[i] = out[i];
  base_ = base.state(dt);
  t_ += dt;
  return SimStatus::ok;
}

void LinearPlant::jump_base(const BaseState& to) {
  // y = dy H(t) + dv t H(t) puts (B1 dy + B2 dv) delta + B2 dy delta' into x'; the delta' term
  // leaves x(0+) - x(0-) = A B2 dy once its own delta has passed.
  const double dy = to.p - base_.p;
  const double dv = to.v - base_.v;
  const Eigen::Index n = x_.size();
  const double* jy = jump_y_.data();
  const double* b2 = b_.col(2).data();  // column-major: contiguous
  for (Eigen::Index i = 0; i < n; ++i) x_[i] += jy[i] * dy + b2[i] * dv;
  base_ = to;
}

double LinearPlant::free_amplitude(Eigen::Index row) const {
  if (!modal_ready_) {
    const Eigen::EigenSolver<Eigen::MatrixXd> es(a_);
    v_ = es.eigenvectors();
    w_ = v_.inverse();
    modal_ready_ = true;
  }
  const Eigen::VectorXd e = x_ - rest_state(base_.p);
  const Eigen::RowVectorXcd cv = c_.row(row).cast<std::complex<double>>() * v_;
  const Eigen::VectorXcd we = w_ * e.cast<std::complex<double>>();
  double amp = 0.0;
  for (Eigen::Index k = 0; k < e.size(); ++k) amp += std::abs(cv(k) * we(k));
  return amp;
}

}  // namespace settle::plant
