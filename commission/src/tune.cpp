// SPDX-License-Identifier: Apache-2.0
#include "settle/commission/tune.hpp"

#include <algorithm>
#include <complex>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <tuple>

#include "settle/core/golden_section.hpp"
#include "settle/core/mode.hpp"
#include "settle/core/profiles/registry.hpp"
#include "settle/plant/command.hpp"
#include "settle/plant/move_vocabulary.hpp"

namespace settle::commission {

namespace {
constexpr const char* kTuneStatusCodes[] = {SETTLE_TUNE_STATUSES(SETTLE_ENUM_CODE)};
constexpr const char* kTuneStatusTexts[] = {SETTLE_TUNE_STATUSES(SETTLE_ENUM_TEXT)};
}  // namespace

const char* to_string(TuneStatus s) noexcept { return core::enum_text(kTuneStatusCodes, s, "unknown"); }

const char* describe(TuneStatus s) noexcept { return core::enum_text(kTuneStatusTexts, s, "unknown"); }

namespace {

// The residual of the unshaped profile on (omega, zeta), relative to a step of its distance:
// e^{-zeta w T} |I| / (w |D|), I = int_0^T a(s) e^{(zeta w - i wd) s} ds plus the Dirac terms of a
// velocity step at either end (the Duhamel integral of the mode's response to the base
// acceleration). Equal to prv_on_mode / 100 on the same profile (tests check it against that
// simulation and against RK4); used here because it costs about 1/50 of a simulation: the nodes
// and the profile's accelerations are computed once per profile, then each (omega, zeta) is a sum.
class ProfileResidual {
 public:
  ProfileResidual(const core::Profile<double>& p, bool velocity_step, double omega_max) {
    static const std::vector<std::pair<double, double>> gl = gauss_legendre(8);
    std::vector<double> b;
    plant::profile_breakpoints(p, b);
    std::sort(b.begin(), b.end());
    b.erase(std::unique(b.begin(), b.end()), b.end());
    duration_ = p.duration();
    distance_ = std::fabs(p.distance());
    for (std::size_t i = 0; i + 1 < b.size(); ++i) {
      const double len = b[i + 1] - b[i];
      if (!(len > 0.0)) continue;
      // At most 1.5 rad of the mode's phase per 8-point panel: the rule is then exact to rounding
      // for the oscillating factor, and the profile's pieces are smooth within their breakpoints.
      const double panels_real = std::ceil(omega_max * len / 1.5);
      const std::size_t panels = std::clamp<std::size_t>(static_cast<std::size_t>(std::min(panels_real, 1e6)), 2, 1000000);
      const double h = len / static_cast<double>(panels);
      for (std::size_t k = 0; k < panels; ++k) {
        const double lo = b[i] + static_cast<double>(k) * h;
        for (const auto& [x, w] : gl) {
          const double s = lo + 0.5 * h * (x + 1.0);
          s_.push_back(s);
          wa_.push_back(0.5 * h * w * plant::profile_sample(p, s, false).a);
        }
      }
    }
    if (velocity_step) {
      v0_ = plant::profile_sample(p, 0.0, false).v;
      v1_ = plant::profile_sample(p, duration_, true).v;
    }
    // A node whose term has decayed below this (|weight| x e^{zeta w (s - T)}) adds nothing a double
    // sum of these terms can hold (1e-24 of the largest weight, far under its rounding), so it is
    // skipped: on a long, damped move most nodes decay into subnormal numbers, whose arithmetic costs
    // ~100 times a normal one (a 3000 s move took 40 s of CPU for a 3 s budget of work).
    double largest = 0.0;
    log_wa_.reserve(wa_.size());
    for (double w : wa_) {
      largest = std::max(largest, std::fabs(w));
      log_wa_.push_back(std::log(std::fabs(w)));  // -inf for a zero weight: always skipped
    }
    log_negligible_ = largest > 0.0 ? std::log(largest) + std::log(1e-24) : 0.0;
  }

  // relative() at omega0 + k domega, k = 0..n-1, one zeta: with lambda = omega mu linear in omega,
  // every node's exponential advances by a fixed factor per point (one complex multiply, not an
  // exp); |factor| <= 1 since s <= T, so the recurrence cannot grow.
  [[nodiscard]] plant::SimStatus row(double zeta, double omega0, double domega, std::size_t n, double* out) const {
    if (core::mode_status(omega0, zeta) != core::Status::ok || !(domega >= 0.0) ||
        !std::isfinite(omega0 + domega * static_cast<double>(n))) {
      return plant::SimStatus::bad_range;
    }
    const std::complex<double> mu{zeta, -std::sqrt(1.0 - zeta * zeta)};
    std::vector<std::complex<double>> acc(n, {0.0, 0.0});
    for (std::size_t q = 0; q < s_.size(); ++q) {
      const double u = s_[q] - duration_;
      // |term| = |w| e^{zeta omega u}, u <= 0: it only shrinks along the row (omega grows), so the
      // row stops where it falls under the negligible level.
      const double log_start = log_wa_[q] + zeta * omega0 * u;
      if (!(log_start > log_negligible_)) continue;
      const double log_decay = zeta * domega * u;  // per point, <= 0
      const std::size_t live =
          log_decay < 0.0 ? static_cast<std::size_t>(
                                std::min(static_cast<double>(n), std::ceil((log_negligible_ - log_start) / log_decay)))
                          : n;
      std::complex<double> z = wa_[q] * std::exp(omega0 * mu * u);
      const std::complex<double> step = std::exp(domega * mu * u);
      for (std::size_t k = 0; k < live; ++k) {
        acc[k] += z;
        z *= step;
      }
    }
    for (std::size_t k = 0; k < n; ++k) {
      const double omega = omega0 + domega * static_cast<double>(k);
      const std::complex<double> a = acc[k] + v0_ * std::exp(omega * mu * (-duration_)) - v1_;
      out[k] = distance_ > 0.0 ? std::abs(a) / (omega * distance_) : 0.0;
      if (!std::isfinite(out[k])) return plant::SimStatus::non_finite_result;
    }
    return plant::SimStatus::ok;
  }
  [[nodiscard]] std::size_t nodes() const noexcept { return s_.size(); }
  // Nodes a profile of these pieces would get for omega_max (the work bound's estimate).
  [[nodiscard]] static double node_estimate(const core::Profile<double>& p, double omega_max) {
    std::vector<double> b;
    plant::profile_breakpoints(p, b);
    std::sort(b.begin(), b.end());
    double n = 0.0;
    for (std::size_t i = 0; i + 1 < b.size(); ++i) {
      const double len = b[i + 1] - b[i];
      if (len > 0.0) n += 8.0 * std::max(2.0, std::ceil(omega_max * len / 1.5));
    }
    return n;
  }

  [[nodiscard]] plant::SimStatus relative(double omega, double zeta, double& out) const {
    if (core::mode_status(omega, zeta) != core::Status::ok) return plant::SimStatus::bad_range;
    if (!(distance_ > 0.0)) {
      out = 0.0;
      return plant::SimStatus::ok;
    }
    const double wd = omega * std::sqrt(1.0 - zeta * zeta);
    // e^{-zeta w T} folded into every term so that heavy damping cannot overflow.
    const std::complex<double> k{zeta * omega, -wd};
    std::complex<double> acc{0.0, 0.0};
    for (std::size_t q = 0; q < s_.size(); ++q) {
      const double u = s_[q] - duration_;
      if (!(log_wa_[q] + zeta * omega * u > log_negligible_)) continue;  // see row()
      acc += wa_[q] * std::exp(k * u);
    }
    acc += v0_ * std::exp(k * (-duration_));
    acc -= v1_;
    out = std::abs(acc) / (omega * distance_);
    return std::isfinite(out) ? plant::SimStatus::ok : plant::SimStatus::non_finite_result;
  }

 private:
  static std::vector<std::pair<double, double>> gauss_legendre(int n) {
    std::vector<std::pair<double, double>> r;
    for (int i = 1; i <= n; ++i) {
      double z = std::cos(std::numbers::pi * (i - 0.25) / (n + 0.5));
      double dp = 1.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::fabs(dz) < 1e-16) break;
      }
      r.emplace_back(z, 2.0 / ((1.0 - z * z) * dp * dp));
    }
    return r;
  }

  std::vector<double> s_, wa_, log_wa_;  // nodes, weighted accelerations, log |weight| (once)
  double duration_{0.0}, distance_{0.0}, v0_{0.0}, v1_{0.0};
  double log_negligible_{0.0};  // log of the term size below which a node is skipped
};

// The maximum of f on [a, b] by golden-section search, raising best_f (and best_x) to the best
// value seen; f(x, r) gives r and a status, and the first failure ends the search.
template <typename F>
plant::SimStatus golden_max(F&& f, double a, double b, int iterations, double& best_x, double& best_f) {
  plant::SimStatus st = plant::SimStatus::ok;
  const auto value = [&](double x) {
    double r = 0.0;
    if (st != plant::SimStatus::ok) return r;
    st = f(x, r);
    if (r > best_f && st == plant::SimStatus::ok) {
      best_f = r;
      best_x = x;
    }
    return r;
  };
  (void)core::golden_section_max(value, a, b, iterations,
                                 [&](double, double) { return st != plant::SimStatus::ok; });
  return st;
}

double lerp(double lo, double hi, std::size_t i, std::size_t n) {
  if (n < 2) return lo;
  return i + 1 == n ? hi : lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(n - 1);
}

// worst_in_band on a profile's quadrature (shared by every shaper and design that uses it).
// stop_above: once a grid row exceeds it the search ends there (the move fails either way, and
// what was found is a lower bound of its worst).
// work: evaluations x nodes so far, refused (too_many_samples) once it would pass max_work.
plant::SimStatus worst_impl(const core::Shaper<double>& shaper, const ProfileResidual& pr, const UncertainMode& b,
                     std::size_t n_omega, std::size_t n_zeta, double stop_above, double& work, double max_work,
                     BandWorst& out) {
  const double nodes = static_cast<double>(pr.nodes()) + 1.0;
  auto spend = [&](double points) {
    work += points * nodes;
    return work <= max_work;
  };
  if (!(b.omega_hi > b.omega_lo)) n_omega = 1;
  if (!(b.zeta_hi > b.zeta_lo)) n_zeta = 1;
  BandWorst w;
  w.residual = -1.0;
  auto keep = [&](double omega, double zeta, double r) {
    ++w.evaluations;
    if (r > w.residual) {
      w.residual = r;
      w.omega = omega;
      w.zeta = zeta;
    }
  };
  auto eval = [&](double omega, double zeta, double& r) {
    if (!spend(1.0)) return plant::SimStatus::too_many_samples;
    double pf = 0.0;
    const plant::SimStatus st = pr.relative(omega, zeta, pf);
    if (st != plant::SimStatus::ok) return st;
    r = pf * core::shaper_residual(shaper, omega, zeta);
    if (!std::isfinite(r)) return plant::SimStatus::non_finite_result;
    keep(omega, zeta, r);
    return plant::SimStatus::ok;
  };
  const double domega = n_omega > 1 ? (b.omega_hi - b.omega_lo) / static_cast<double>(n_omega - 1) : 0.0;
  auto omega_at = [&](std::size_t i) { return i + 1 == n_omega && n_omega > 1 ? b.omega_hi : b.omega_lo + domega * static_cast<double>(i); };
  std::vector<double> grid(n_omega * n_zeta);
  for (std::size_t k = 0; k < n_zeta; ++k) {
    const double zeta = lerp(b.zeta_lo, b.zeta_hi, k, n_zeta);
    double* row = grid.data() + k * n_omega;
    if (!spend(static_cast<double>(n_omega))) return plant::SimStatus::too_many_samples;
    const plant::SimStatus st = pr.row(zeta, b.omega_lo, domega, n_omega, row);
    if (st != plant::SimStatus::ok) return st;
    for (std::size_t i = 0; i < n_omega; ++i) {
      row[i] *= core::shaper_residual(shaper, omega_at(i), zeta);
      if (!std::isfinite(row[i])) return plant::SimStatus::non_finite_result;
      keep(omega_at(i), zeta, row[i]);
    }
    if (w.residual > stop_above) {
      out = w;
      return plant::SimStatus::ok;
    }
  }
  if (n_omega * n_zeta == 1) {
    out = w;
    return plant::SimStatus::ok;
  }
  // Local maxima along omega in every zeta row (ends count); the three largest are refined, each in
  // omega between its grid neighbours, then in zeta between the neighbouring rows.
  struct Peak {
    double r;
    std::size_t i, k;
  };
  std::vector<Peak> peaks;
  for (std::size_t k = 0; k < n_zeta; ++k) {
    for (std::size_t i = 0; i < n_omega; ++i) {
      const double r = grid[k * n_omega + i];
      const bool left = i == 0 || r >= grid[k * n_omega + i - 1];
      const bool right = i + 1 == n_omega || r >= grid[k * n_omega + i + 1];
      if (left && right) peaks.push_back({r, i, k});
    }
  }
  std::sort(peaks.begin(), peaks.end(), [](const Peak& x, const Peak& y) { return x.r > y.r; });
  if (peaks.size() > 3) peaks.resize(3);
  for (const Peak& p : peaks) {
    double om = omega_at(p.i);
    double ze = lerp(b.zeta_lo, b.zeta_hi, p.k, n_zeta);
    double best = p.r;
    if (n_omega > 1) {
      const double a = omega_at(p.i == 0 ? 0 : p.i - 1);
      const double c = omega_at(std::min(p.i + 1, n_omega - 1));
      const plant::SimStatus st = golden_max([&](double x, double& r) { return eval(x, ze, r); }, a, c, 24, om, best);
      if (st != plant::SimStatus::ok) return st;
    }
    if (n_zeta > 1) {
      const double a = lerp(b.zeta_lo, b.zeta_hi, p.k == 0 ? 0 : p.k - 1, n_zeta);
      const double c = lerp(b.zeta_lo, b.zeta_hi, std::min(p.k + 1, n_zeta - 1), n_zeta);
      const plant::SimStatus st = golden_max([&](double x, double& r) { return eval(om, x, r); }, a, c, 16, ze, best);
      if (st != plant::SimStatus::ok) return st;
    }
  }
  out = w;
  return plant::SimStatus::ok;
}

bool valid_band(const UncertainMode& m) {
  return m.omega_lo > 0.0 && m.omega_lo <= m.omega && m.omega <= m.omega_hi && std::isfinite(m.omega_hi) &&
         m.zeta_lo >= 0.0 && m.zeta_lo <= m.zeta && m.zeta <= m.zeta_hi && m.zeta_hi < 1.0;
}

constexpr double kBuildCost = 64.0;

// The unshaped profile of `req` within the move's limits: the profile's own planner, or, when it
// refuses the combination of limits it was given (ramp-versine takes only vmax, say), the shortest
// move time whose peaks are within them, found by doubling then bisection (peaks fall as the time
// grows for every registered family; a family for which they do not is refused, never exceeded).
core::Status plan_profile(core::MoveRequest& req_io, const TuneMove& mv, core::Move<double>& out, bool& searched) {
  core::MoveRequest req = req_io;
  searched = false;
  core::Status st = core::plan(req, out);
  if (st == core::Status::ok || mv.time) return st;
  const core::Status own = st;
  const core::LimitTimes bound = core::shortest_times(mv.distance, mv.limits);
  // No rest-to-rest move is faster than these bounds (a NaN bound does not raise it).
  double t_lo = std::max({0.0, bound.by_vmax, bound.by_amax, bound.by_jmax});
  req.limits = {};
  core::Move<double> found{};
  auto ok_at = [&](double t, core::Move<double>& m) {
    req.time = t;
    return core::plan(req, m) == core::Status::ok && core::check_limits(req_io.limits, m.peaks()) == core::Status::ok;
  };
  double t_hi = std::max(t_lo, 1e-6);
  int doublings = 0;
  while (!ok_at(t_hi, found)) {
    if (++doublings > 40 || t_hi > 3600.0) return own;
    t_lo = t_hi;
    t_hi *= 2.0;
  }
  for (int i = 0; i < 60 && t_hi - t_lo > 1e-12 * t_hi; ++i) {
    const double mid = 0.5 * (t_lo + t_hi);
    core::Move<double> m{};
    if (ok_at(mid, m)) {
      t_hi = mid;
      found = m;
    } else {
      t_lo = mid;
    }
  }
  out = found;
  req.time = t_hi;  // the request that plans `found` again
  req_io = req;
  searched = true;
  return core::Status::ok;
}

}  // namespace

core::Status tuned_shaper(core::ShaperKind kind, const std::vector<double>& omega, const std::vector<double>& zeta,
                          double residual_max, core::Shaper<double>& out) {
  if (omega.size() != zeta.size()) return core::Status::bad_shape_parameter;
  // EI designed for the tolerance asked (its widest band), within the (0, 0.5) EI allows.
  const double vtol = std::min(residual_max, 0.49);
  core::Shaper<double> acc{};
  if (kind != core::ShaperKind::none) {
    for (std::size_t j = 0; j < omega.size(); ++j) {
      core::Shaper<double> s{}, c{};
      core::Status st = core::design_shaper(kind, omega[j], zeta[j], vtol, s);
      if (st != core::Status::ok) return st;
      st = core::compose(acc, s, c);
      if (st != core::Status::ok) return st;
      acc = c;
    }
  }
  out = acc;
  return core::Status::ok;
}

plant::SimStatus relative_residual(const core::Move<double>& move, double omega, double zeta, double& out) {
  // Before the quadrature is laid out: its nodes grow with omega (an infinite one would ask for a
  // million panels per piece).
  if (core::mode_status(omega, zeta) != core::Status::ok) return plant::SimStatus::bad_range;
  double pf = 0.0;
  const plant::SimStatus st = ProfileResidual{move.profile(), move.peaks().velocity_step, omega}.relative(omega, zeta, pf);
  if (st != plant::SimStatus::ok) return st;
  out = pf * core::shaper_residual(move.shaper(), omega, zeta);
  return plant::SimStatus::ok;
}

plant::SimStatus residual_curve(const core::Move<double>& move, double omega_lo, double omega_hi, double zeta, std::size_t n,
                         std::vector<double>& out) {
  if (!(omega_lo > 0.0) || !(omega_hi > omega_lo) || !std::isfinite(omega_hi) || !(zeta >= 0.0 && zeta < 1.0) ||
      n < 2) {
    return plant::SimStatus::bad_range;
  }
  if (n > kMaxTuneOmegaPoints) return plant::SimStatus::too_many_samples;
  const ProfileResidual pr{move.profile(), move.peaks().velocity_step, omega_hi};
  const double dw = (omega_hi - omega_lo) / static_cast<double>(n - 1);
  std::vector<double> r(n);
  const plant::SimStatus st = pr.row(zeta, omega_lo, dw, n, r.data());
  if (st != plant::SimStatus::ok) return st;
  for (std::size_t i = 0; i < n; ++i) {
    r[i] *= core::shaper_residual(move.shaper(), omega_lo + dw * static_cast<double>(i), zeta);
  }
  out = std::move(r);
  return plant::SimStatus::ok;
}

std::size_t omega_points_for(const UncertainMode& band, double duration) noexcept {
  const double phase = (band.omega_hi - band.omega_lo) * std::max(duration, 0.0);
  const double n = std::ceil(phase / (std::numbers::pi / 4.0)) + 1.0;
  if (!(n >= static_cast<double>(kMinTuneOmegaPoints))) return kMinTuneOmegaPoints;
  if (n >= static_cast<double>(kMaxTuneOmegaPoints)) return kMaxTuneOmegaPoints;
  return static_cast<std::size_t>(n);
}

plant::SimStatus worst_in_band(const core::Move<double>& move, const UncertainMode& band, std::size_t omega_points,
                        std::size_t zeta_points, BandWorst& out) {
  if (!valid_band(band)) return plant::SimStatus::bad_range;
  if (omega_points < 1 || zeta_points < 1 || omega_points > kMaxTuneOmegaPoints || zeta_points > kMaxTuneZetaPoints) {
    return plant::SimStatus::too_many_samples;
  }
  if (ProfileResidual::node_estimate(move.profile(), band.omega_hi) > kMaxTuneNodes) return plant::SimStatus::too_many_samples;
  const ProfileResidual pr{move.profile(), move.peaks().velocity_step, band.omega_hi};
  double work = 0.0;
  return worst_impl(move.shaper(), pr, band, omega_points, zeta_points, std::numeric_limits<double>::infinity(), work,
                    std::numeric_limits<double>::infinity(), out);
}

namespace {

// The request's own faults, before anything is planned.
TuneStatus tune_input_status(const std::vector<UncertainMode>& modes_in, const TuneMove& mv, const TuneOptions& opt) {
  if (modes_in.empty()) return TuneStatus::no_modes;
  if (modes_in.size() > kMaxTuneModes) return TuneStatus::too_many_modes;
  for (const UncertainMode& m : modes_in) {
    if (core::mode_status(m.omega, m.zeta) != core::Status::ok || !std::isfinite(m.gain)) {
      return TuneStatus::bad_mode;
    }
    if (!valid_band(m)) return TuneStatus::bad_band;
  }
  const auto positive = [](const std::optional<double>& x) { return !x || (*x > 0.0 && std::isfinite(*x)); };
  if (!(mv.distance != 0.0) || !std::isfinite(mv.distance) || !positive(mv.time) ||
      !positive(mv.limits.vmax) || !positive(mv.limits.amax) || !positive(mv.limits.jmax) ||
      (!mv.time && !mv.limits.any())) {
    return TuneStatus::bad_move;
  }
  if (!(opt.residual_max > 0.0 && opt.residual_max < 1.0)) return TuneStatus::bad_residual_max;
  if (opt.zeta_points < 1 || opt.zeta_points > kMaxTuneZetaPoints || !(opt.max_work > 0.0)) {
    return TuneStatus::bad_grid;
  }
  return TuneStatus::ok;
}

// The candidates found so far: those that could be planned, and the refusals shown.
struct TuneFamilies {
  std::vector<TuneCandidate> planned;  // every (family, design) that could be planned
  std::vector<TuneCandidate> refused;
};

// One design of one family: profile `kind` shaped by `sk` at the nominal modes (v == 0) or
// retuned at placement v-1 within the band; planned within the move's limits, or refused (shown
// once per family), or skipped (a retuned design that changes nothing, or cannot be planned).
void plan_design(core::ProfileKind kind, core::ShaperKind sk, std::size_t v, const std::vector<UncertainMode>& modes,
                 const TuneMove& mv, const TuneOptions& opt, TuneFamilies& out) {
  TuneCandidate c;
  c.profile = kind;
  c.shaper = sk;
  c.retuned = v > 0;
  c.placement = v > 0 ? static_cast<double>(v - 1) / static_cast<double>(kTunePlacements - 1) : -1.0;
  for (const UncertainMode& m : modes) {
    c.design_omega.push_back(c.retuned ? m.omega_lo + c.placement * (m.omega_hi - m.omega_lo) : m.omega);
    c.design_zeta.push_back(m.zeta);
  }
  core::MoveRequest r{};
  r.profile = kind;
  r.distance = mv.distance;
  r.time = mv.time;
  r.limits = mv.limits;
  // A profile that designs for a mode takes the fundamental; `fastest` takes every mode (up
  // to its kMaxModes), as `settle plan --profile fastest` does, by the same rules.
  const bool every_mode = kind == core::ProfileKind::fastest && c.design_omega.size() <= core::kMaxModes;
  const std::size_t designed = every_mode ? c.design_omega.size() : 1;
  const char* option = nullptr;
  std::string why;
  (void)plant::set_design_modes({c.design_omega.begin(), c.design_omega.begin() + static_cast<std::ptrdiff_t>(designed)},
                                {c.design_zeta.begin(), c.design_zeta.begin() + static_cast<std::ptrdiff_t>(designed)}, r,
                                option, why);
  // A design that changes nothing (no shaper, a profile that ignores the mode) is one family.
  if (c.retuned && sk == core::ShaperKind::none && !core::needs_mode(r)) return;
  c.name = std::string{core::to_string(kind)} + (sk == core::ShaperKind::none ? "" : "+") +
           (sk == core::ShaperKind::none ? "" : core::to_string(sk)) + (c.retuned ? "@retuned" : "");
  const core::OptionalLimits limited = r.limits;  // the move's limits (a time-searched request drops them)
  core::Move<double> bare{};
  core::Status st = plan_profile(r, mv, bare, c.time_searched);
  c.request = r;
  if (st != core::Status::ok) {
    // The profile itself cannot be planned: shown once, under its own name (a retuned design
    // that cannot be planned is skipped).
    if (v == 0 && sk == core::ShaperKind::none) {
      c.refusal = core::to_string(st);
      out.refused.push_back(std::move(c));
    }
    return;
  }
  core::Shaper<double> shaper{};
  if (st == core::Status::ok) st = tuned_shaper(sk, c.design_omega, c.design_zeta, opt.residual_max, shaper);
  if (st == core::Status::ok) {
    const core::Peaks<double> pk = core::shaped_peaks(bare.profile(), shaper, bare.peaks());
    st = core::check_limits(limited, pk);
    c.move = core::Move<double>{bare.profile(), shaper, pk};
  }
  const bool too_long = st == core::Status::ok && !(c.move.duration() <= kMaxTuneDuration);
  if (st != core::Status::ok || too_long) {
    if (v <= 1) {  // one refusal per family is enough to show
      c.refusal = st != core::Status::ok ? core::to_string(st) : "too_long";
      out.refused.push_back(std::move(c));
    }
    return;
  }
  c.planned = true;
  c.duration = c.move.duration();
  out.planned.push_back(std::move(c));
}

// Enumerate: every family, each registry profile unshaped or shaped, at the nominal modes or
// retuned, planned.
TuneFamilies enumerate_families(const std::vector<UncertainMode>& modes, const TuneMove& mv, const TuneOptions& opt) {
  const std::vector<core::ShaperKind> shapers = {core::ShaperKind::none, core::ShaperKind::zv,  core::ShaperKind::zvd,
                                                 core::ShaperKind::ei,   core::ShaperKind::ei2, core::ShaperKind::ei3};
  TuneFamilies out;
  core::for_each_profile([&](auto kind) {
    for (core::ShaperKind sk : shapers) {
      for (std::size_t v = 0; v <= kTunePlacements; ++v) plan_design(kind.value, sk, v, modes, mv, opt, out);  // v == 0: nominal
    }
  });
  return out;
}

// Evaluate, shortest first: each candidate is checked in turn until one meets the bound; the
// slower ones are then not evaluated (they could not be chosen). A failing candidate's search stops
// at the first grid row that breaks the bound. `chosen`: the index in `planned` (sorted here) of the
// one that meets it, planned.size() when none does; too_much_work past opt.max_work.
TuneStatus evaluate_shortest_first(std::vector<TuneCandidate>& planned, const std::vector<UncertainMode>& modes,
                                   const TuneOptions& opt, std::size_t& chosen) {
  std::stable_sort(planned.begin(), planned.end(),
                   [](const TuneCandidate& a, const TuneCandidate& b) { return a.duration < b.duration; });
  double omega_max = 0.0;
  for (const UncertainMode& m : modes) omega_max = std::max(omega_max, m.omega_hi);
  const std::size_t n_zeta = opt.zeta_points;
  // Memory, before any quadrature is built: every candidate's nodes.
  for (const TuneCandidate& c : planned) {
    if (ProfileResidual::node_estimate(c.move.profile(), omega_max) > kMaxTuneNodes) return TuneStatus::too_much_work;
  }
  double work = 0.0;  // CPU: counted as the search goes

  // One quadrature per distinct profile (a profile that ignores the mode is the same for every
  // design), shared by the shapers and designs that use it.
  std::map<std::tuple<int, double, double>, std::shared_ptr<ProfileResidual>> profiles;
  chosen = planned.size();
  for (std::size_t ci = 0; ci < planned.size() && chosen == planned.size(); ++ci) {
    TuneCandidate& c = planned[ci];
    const bool by_mode = core::needs_mode(c.request);
    const auto key = std::make_tuple(static_cast<int>(c.profile), by_mode ? c.design_omega[0] : 0.0,
                                     by_mode ? c.design_zeta[0] : 0.0);
    auto& pr = profiles[key];
    if (!pr) {
      // Building a quadrature evaluates the profile at every node: charged as kBuildCost residual
      // points per node (measured: a profile evaluation costs about that many recurrence steps).
      work += kBuildCost * ProfileResidual::node_estimate(c.move.profile(), omega_max);
      if (work > opt.max_work) return TuneStatus::too_much_work;
      pr = std::make_shared<ProfileResidual>(c.move.profile(), c.move.peaks().velocity_step, omega_max);
    }
    c.evaluated = true;
    c.meets = true;
    c.worst.residual = -1.0;
    for (std::size_t j = 0; j < modes.size() && c.meets; ++j) {
      BandWorst w;
      const plant::SimStatus st = worst_impl(c.move.shaper(), *pr, modes[j], omega_points_for(modes[j], c.duration),
                                             n_zeta, opt.residual_max, work, opt.max_work, w);
      if (st == plant::SimStatus::too_many_samples) return TuneStatus::too_much_work;
      if (st != plant::SimStatus::ok) {
        c.meets = false;
        c.refusal = to_string(st);
        break;
      }
      c.worst.evaluations += w.evaluations;
      c.mode_worst.push_back(w);
      if (w.residual > c.worst.residual) {
        const std::size_t evals = c.worst.evaluations;
        c.worst = w;
        c.worst.evaluations = evals;
        c.worst_mode = j;
      }
      if (w.residual > opt.residual_max) c.meets = false;
    }
    if (c.meets) chosen = ci;
  }
  return TuneStatus::ok;
}

// Report: every family (profile, shaper, nominal or retuned) once, by its shortest design that
// was evaluated (the chosen one for the chosen family), else its shortest design; then the refusals.
TuneStatus report_families(std::vector<UncertainMode> modes, const TuneOptions& opt, TuneFamilies families,
                           std::size_t chosen, TuneResult& out) {
  std::vector<TuneCandidate>& planned = families.planned;
  std::vector<TuneCandidate> kept;
  auto family = [](const TuneCandidate& a, const TuneCandidate& b) {
    return a.profile == b.profile && a.shaper == b.shaper && a.retuned == b.retuned;
  };
  if (chosen < planned.size()) kept.push_back(planned[chosen]);
  for (TuneCandidate& c : planned) {
    if (std::none_of(kept.begin(), kept.end(), [&](const TuneCandidate& k) { return family(k, c); })) {
      kept.push_back(std::move(c));
    }
  }
  std::stable_sort(kept.begin(), kept.end(), [](const TuneCandidate& a, const TuneCandidate& b) {
    if (a.duration != b.duration) return a.duration < b.duration;
    return a.meets && !b.meets;
  });
  TuneResult res;
  res.modes = std::move(modes);
  res.residual_max = opt.residual_max;
  res.candidates = std::move(kept);
  std::size_t pick = res.candidates.size();
  if (chosen < planned.size()) {
    for (std::size_t i = 0; i < res.candidates.size(); ++i) {
      if (res.candidates[i].meets) {
        pick = i;
        break;
      }
    }
  }
  const bool found = pick < res.candidates.size();
  for (TuneCandidate& c : families.refused) res.candidates.push_back(std::move(c));
  res.chosen = found ? pick : res.candidates.size();
  out = std::move(res);
  return found ? TuneStatus::ok : TuneStatus::no_feasible_plan;
}

}  // namespace

TuneStatus tune(const std::vector<UncertainMode>& modes_in, const TuneMove& mv, const TuneOptions& opt,
                TuneResult& out) {
  if (const TuneStatus st = tune_input_status(modes_in, mv, opt); st != TuneStatus::ok) return st;
  std::vector<UncertainMode> modes = modes_in;
  std::stable_sort(modes.begin(), modes.end(), [](const auto& a, const auto& b) { return a.omega < b.omega; });
  TuneFamilies families = enumerate_families(modes, mv, opt);
  std::size_t chosen = 0;
  if (const TuneStatus st = evaluate_shortest_first(families.planned, modes, opt, chosen); st != TuneStatus::ok) {
    return st;
  }
  return report_families(std::move(modes), opt, std::move(families), chosen, out);
}

}  // namespace settle::commission
