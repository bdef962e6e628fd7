// SPDX-License-Identifier: Apache-2.0
#include "settle/plant/modal_plant.hpp"

#include <cmath>

namespace settle::plant {

const char* to_string(PlantKind k) noexcept {
  switch (k) {
    case PlantKind::sdof: return "sdof";
    case PlantKind::beam: return "beam";
    case PlantKind::belt: return "belt";
    case PlantKind::modes: return "modes";
  }
  return "unknown";
}

double belt_lambda(const BeltParams& p) noexcept { return p.ratio * p.pulley_r / p.pulley_R; }

SimStatus ModalPlant::make_modes(const std::vector<Mode>& modes, double rigid_gain, PlantKind kind, ModalPlant& out) {
  if (modes.empty()) return SimStatus::bad_mode_count;
  if (modes.size() > kMaxModes) return SimStatus::too_many_modes;  // before the matrices are sized
  if (!std::isfinite(rigid_gain)) return SimStatus::non_finite_parameter;
  for (const Mode& m : modes) {
    for (double v : {m.omega, m.zeta, m.gain, m.output, m.mass, m.coupling}) {
      if (!std::isfinite(v)) return SimStatus::non_finite_parameter;
    }
    if (!(m.omega > 0.0)) return SimStatus::non_positive_omega;
    if (m.zeta < 0.0) return SimStatus::negative_damping;
    if (!(m.zeta < 1.0)) return SimStatus::not_underdamped;
    if (!(m.mass > 0.0)) return SimStatus::non_positive_mass;
  }
  const auto n = static_cast<Eigen::Index>(2 * modes.size());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n, 3);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(4, n);
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(4, 3);
  d(kRowPosition, 0) = rigid_gain;
  d(kRowVelocity, 1) = rigid_gain;
  d(kRowAcceleration, 2) = rigid_gain;
  for (std::size_t j = 0; j < modes.size(); ++j) {
    const Mode& m = modes[j];
    const auto i = static_cast<Eigen::Index>(2 * j);
    const double w2 = m.omega * m.omega;
    const double cw = 2.0 * m.zeta * m.omega;
    a(i, i + 1) = 1.0;
    a(i + 1, i) = -w2;
    a(i + 1, i + 1) = -cw;
    b(i + 1, 2) = m.gain;
    c(kRowDeflection, i) = m.output;
    c(kRowPosition, i) = m.output;
    c(kRowVelocity, i + 1) = m.output;
    // q'' from the equation of motion, so the acceleration output needs no differencing.
    c(kRowAcceleration, i) = -m.output * w2;
    c(kRowAcceleration, i + 1) = -m.output * cw;
    d(kRowAcceleration, 2) += m.output * m.gain;
  }
  ModalPlant p;
  const SimStatus st = LinearPlant::make(a, b, c, d, p.lin_);
  if (st != SimStatus::ok) return st;
  p.kind_ = kind;
  p.modes_ = modes;
  p.rigid_ = rigid_gain;
  for (std::size_t j = 1; j < modes.size(); ++j) {
    if (modes[j].omega < modes[p.fundamental_].omega) p.fundamental_ = j;
  }
  out = std::move(p);
  return SimStatus::ok;
}

SimStatus ModalPlant::make_sdof(const SdofParams& p, ModalPlant& out) {
  for (double v : {p.mass, p.stiffness, p.damping}) {
    if (!std::isfinite(v)) return SimStatus::non_finite_parameter;
  }
  if (!(p.mass > 0.0)) return SimStatus::non_positive_mass;
  if (!(p.stiffness > 0.0)) return SimStatus::non_positive_stiffness;
  if (p.damping < 0.0) return SimStatus::negative_damping;
  Mode m;
  m.omega = std::sqrt(p.stiffness / p.mass);
  m.zeta = p.damping / (2.0 * std::sqrt(p.stiffness * p.mass));
  m.gain = -1.0;
  m.output = 1.0;
  m.mass = p.mass;
  m.coupling = 1.0;  // kinetic energy of the mass: 1/2 m x'^2 = 1/2 m (q' + y')^2
  return make_modes({m}, 1.0, PlantKind::sdof, out);
}

SimStatus ModalPlant::make_belt(const BeltParams& p, ModalPlant& out) {
  for (double v : {p.inertia, p.belt_stiffness, p.belt_damping, p.pulley_r, p.pulley_R, p.ratio}) {
    if (!std::isfinite(v)) return SimStatus::non_finite_parameter;
  }
  if (!(p.inertia > 0.0)) return SimStatus::non_positive_mass;
  if (!(p.belt_stiffness > 0.0)) return SimStatus::non_positive_stiffness;
  if (p.belt_damping < 0.0) return SimStatus::negative_damping;
  if (!(p.pulley_r > 0.0) || !(p.pulley_R > 0.0)) return SimStatus::non_positive_radius;
  if (!(p.ratio > 0.0)) return SimStatus::non_positive_ratio;
  const double kt = 2.0 * p.belt_stiffness * p.pulley_R * p.pulley_R;
  const double ct = 2.0 * p.belt_damping * p.pulley_R * p.pulley_R;
  const double lambda = belt_lambda(p);
  Mode m;
  m.omega = std::sqrt(kt / p.inertia);
  m.zeta = ct / (2.0 * p.inertia * m.omega);
  m.gain = -lambda;
  m.output = 1.0;
  m.mass = p.inertia;
  m.coupling = lambda;  // 1/2 J theta'^2 = 1/2 J (alpha' + lambda phi_m')^2
  return make_modes({m}, lambda, PlantKind::belt, out);
}

SimStatus ModalPlant::make_beam(const BeamOptions& o, ModalPlant& out) {
  if (!std::isfinite(o.modal_damping)) return SimStatus::non_finite_parameter;
  if (o.modal_damping < 0.0) return SimStatus::negative_damping;
  if (!(o.modal_damping < 1.0)) return SimStatus::not_underdamped;
  std::vector<BeamMode> bm;
  const SimStatus st = beam_modes(o.params, o.modes, bm);
  if (st != SimStatus::ok) return st;
  std::vector<Mode> modes;
  for (const BeamMode& b : bm) {
    Mode m;
    m.omega = b.omega;
    m.zeta = o.modal_damping;
    m.gain = b.lambda;
    m.output = b.phi_tip;
    m.mass = 1.0;  // mass-normalised shapes; the energy is that of the elastic motion
    m.coupling = 0.0;
    m.beta = b.beta;
    modes.push_back(m);
  }
  return make_modes(modes, 1.0, PlantKind::beam, out);
}

SimStatus make_plant(const PlantSpec& spec, ModalPlant& out) {
  switch (spec.kind) {
    case PlantKind::sdof: return ModalPlant::make_sdof(spec.sdof, out);
    case PlantKind::beam: return ModalPlant::make_beam(spec.beam, out);
    case PlantKind::belt: return ModalPlant::make_belt(spec.belt, out);
    case PlantKind::modes: return ModalPlant::make_modes(spec.modes, 1.0, PlantKind::modes, out);
  }
  return SimStatus::bad_mode_count;
}

double ModalPlant::deflection() const { return lin_.output(kRowDeflection); }
double ModalPlant::position() const { return lin_.output(kRowPosition); }
double ModalPlant::velocity() const { return lin_.output(kRowVelocity); }
double ModalPlant::acceleration() const { return lin_.output(kRowAcceleration); }
double ModalPlant::mode_q(std::size_t j) const { return lin_.state()[static_cast<Eigen::Index>(2 * j)]; }
double ModalPlant::mode_dq(std::size_t j) const { return lin_.state()[static_cast<Eigen::Index>(2 * j + 1)]; }

Energy ModalPlant::energy() const {
  Energy e;
  const double yv = lin_.base().v;
  for (std::size_t j = 0; j < modes_.size(); ++j) {
    const Mode& m = modes_[j];
    const double v = mode_dq(j) + m.coupling * yv;
    const double q = mode_q(j);
    e.kinetic += 0.5 * m.mass * v * v;
    e.potential += 0.5 * m.mass * m.omega * m.omega * q * q;
  }
  return e;
}

double ModalPlant::mode_residual(std::size_t j) const {
  const Mode& m = modes_[j];
  const double wd = m.omega * std::sqrt(1.0 - m.zeta * m.zeta);
  const double q = mode_q(j);
  const double s = (mode_dq(j) + m.zeta * m.omega * q) / wd;
  return std::sqrt(q * q + s * s);
}

double ModalPlant::residual_amplitude() const {
  double acc = 0.0;
  for (std::size_t j = 0; j < modes_.size(); ++j) acc += std::fabs(modes_[j].output) * mode_residual(j);
  return acc;
}

double ModalPlant::mode_step_residual(std::size_t j, double distance) const {
  const Mode& m = modes_[j];
  return std::fabs(m.gain * distance) / std::sqrt(1.0 - m.zeta * m.zeta);
}

double ModalPlant::step_residual(double distance) const {
  double acc = 0.0;
  for (std::size_t j = 0; j < modes_.size(); ++j) acc += std::fabs(modes_[j].output) * mode_step_residual(j, distance);
  return acc;
}

}  // namespace settle::plant
