// SPDX-License-Identifier: Apache-2.0
#pragma once
// The three papers' experiments, rerun on Settle's own profiles and plants: the numbers behind
// `settle reproduce 000|001|004`. Each returns plain data (tables, time histories, grids); the CLI
// prints it and figures.hpp turns it into CSV and PNG.
#include <array>
#include <string>
#include <vector>

#include "settle/core/planner.hpp"
#include "settle/plant/beam.hpp"
#include "settle/commission/energy_optimiser.hpp"
#include "settle/plant/sensitivity.hpp"
#include "settle/plant/simulate.hpp"
#include "settle/plant/status.hpp"

namespace settle::papers {

// ---- Seed 000: ramp-cycloid S-curve against the 3-4-5 polynomial on the Table 1 beam ----------

inline constexpr std::array<double, 5> kTimeRatios000{0.8, 1.25, 1.75, 2.25, 4.25};
inline constexpr double kVmax000 = 1.0;  // the paper's actuator velocity limit (m/s)
// The paper gives no distance. Its remark that below Tn/2 the velocity nears the 1 m/s limit
// fixes D: the 4-segment S-curve peaks at 2D/T, which is 1 m/s at T = Tn/2 for D = Vmax Tn/4 =
// 0.071 m. We use 0.07 m, and 0.15 m as the second distance (the S-curve then has to cruise at
// the limit for the short times, and the 3-4-5 polynomial breaks the limit).
inline constexpr std::array<double, 2> kDistances000{0.07, 0.15};

struct Row000 {
  double time_ratio{0.0};  // T / Tn
  double time{0.0};
  core::ProfileKind profile{core::ProfileKind::scurve};
  core::Status plan_status{core::Status::ok};
  double cruise{0.0};           // S-curve: T3 (0 for the 4-segment profile)
  double peak_velocity{0.0};    // true peak |v| of the command (m/s)
  double peak_acceleration{0.0};
  bool over_vmax{false};
  double prv_mode1{0.0};        // % of |Lambda_1| D: the paper's measure (first mode)
  double prv_tip{0.0};          // % of the 3-mode tip's unshaped-step residual
  double residual_tip{0.0};     // m
  double peak_deflection{0.0};  // m, during the move
  plant::InsensitivityWidth width{};   // mode-1 frequency ratio, PRV <= 5 %
  std::vector<plant::HistorySample> history;
};

struct Run000 {
  double distance{0.0};
  std::vector<Row000> rows;  // for each time ratio: S-curve then 3-4-5
};

// PRV against the ratio of true to designed frequency on the beam's first mode, for every core
// profile (D = 0.07 m in T = 2 Tn, designed for mode 1 where the profile takes a mode) and every
// shaper (on a step, the textbook setting).
struct Sensitivity000 {
  std::string name;        // profile or "shaper:<kind>"
  double duration{0.0};    // of the move (s)
  double prv_nominal{0.0};
  plant::InsensitivityWidth width{};  // at 5 %
  std::vector<plant::SensitivityPoint> curve;
};

struct Result000 {
  std::vector<plant::BeamMode> modes;
  double period{0.0};  // Tn of mode 1
  std::vector<Run000> runs;
  std::vector<Sensitivity000> sensitivity;
};

struct Options000 {
  std::vector<double> distances{kDistances000.begin(), kDistances000.end()};
  bool history{true};
  bool widths{true};
  bool sensitivity{true};
  double dt{1e-4};
};
[[nodiscard]] plant::SimStatus reproduce_000(const Options000& o, Result000& out);

// ---- Seeds 001/002: ramp + cycloid + versine on the m = 1, k = 800, c = 9 system ------------------

inline constexpr std::array<double, 2> kTaus001{0.167, 0.74};
inline constexpr std::array<double, 3> kArbitraryY001{0.5, 0.25, 0.25};
// The robustness comparison (Figs. 4-7) is at the move time kTaus001[0] for every method. The
// shapers (ZV, ZVD, EI) shape the plain ramp of that family, Y = (L, 0, 0): L in tau at constant
// velocity, the base the proposed command adds its cycloid and versine to. The hybrid shapes the
// proposed command itself.
inline constexpr std::array<double, 3> kRampY001{1.0, 0.0, 0.0};
// Every robustness residual is referred to this one time (the move time): a command that ends at
// t_end leaves a free vibration of the TRUE plant, whose amplitude decays exactly as
// exp(-zeta w_n t), so its amplitude at t_ref is A(t_end) exp(zeta w_n (t_end - t_ref)). Two
// commands compared this way are compared as if both masses were observed at one instant after
// both commands have ended; the choice of t_ref scales every residual by the same factor.
inline constexpr double kResidualAt001 = kTaus001[0];

struct Case001 {
  double tau{0.0};
  std::array<double, 3> y_computed{};      // Y / L from the zero-vibration conditions
  double residual_arbitrary{0.0};          // residual amplitude / L at tau (the command's end)
  double residual_computed{0.0};
  std::vector<plant::HistorySample> history_arbitrary, history_computed;
};

// Residual amplitude / L, referred to kResidualAt001, over eps(w) = w*/w - 1 (rows) and
// eps(zeta) = zeta*/zeta - 1 (columns), starred = what the command was designed with.
struct Grid001 {
  std::string method;
  std::vector<double> eps;        // the same axis for both
  std::vector<double> residual;   // row-major [i_omega][i_zeta]
  double nominal{0.0};
  double worst{0.0};
  double duration{0.0};           // when the nominal command ends (s)
};

struct Width001 {
  std::string method;
  double zeta{0.0};  // the plant's true damping ratio
  plant::InsensitivityWidth width{};
};

struct Result001 {
  double omega{0.0}, zeta{0.0};
  std::vector<Case001> cases;
  double residual_at{kResidualAt001};  // the grids' reference time (s)
  // proposed, zv, zvd, ei, sahinkaya (3-4-5 output), sahinkaya-cubic, hybrid at tau = 0.167 s
  std::vector<Grid001> grids;
  // Textbook insensitivity widths: ZV, ZVD, EI shaping a step on an undamped mode.
  std::vector<Width001> widths;
};

struct Options001 {
  bool history{true};
  bool grids{true};
  std::size_t grid_points{21};
  double dt{2e-4};
};
[[nodiscard]] plant::SimStatus reproduce_001(const Options001& o, Result001& out);

// The residual amplitude / final position that `cmd` leaves on the seed-001 plant (its true
// w_n, zeta), referred to time t_ref: A(end) exp(zeta w_n (end - t_ref)). bad_range for a
// non-finite t_ref or a command that ends where it started; non_finite_result if it overflows.
[[nodiscard]] plant::SimStatus referred_residual_001(const plant::Command& cmd, double dt, double t_ref, double& out);

// Shaper insensitivity widths of shaped steps on one mode (for tests and the 001 table).
[[nodiscard]] plant::SimStatus shaper_width(core::ShaperKind kind, double zeta, double threshold_percent,
                                     plant::InsensitivityWidth& out);

// ---- Seed 004: pseudo-polynomial commands on the Table III belt platform --------------------------

inline constexpr std::array<double, 3> kPaperGammas004{3.024, 4.565, 5.874};

struct Exponents004 {
  std::size_t count{0};
  std::vector<double> gammas;
  double h_index{0.0};
  double slope{0.0};             // |w d(G, wF)/dw|: sensitivity to a frequency error
  plant::InsensitivityWidth width{};    // residual <= 10 % of the 3-4-5 command's, in frequency ratio
};

struct Result004 {
  commission::EnergyTarget target{};
  double h_scale{0.0};  // h of E = h H
  commission::EnergyIntegrals initial{}, paper{}, optimised{};
  commission::OptimiserResult optimiser{};
  double optimiser_ms{0.0};
  double boundary_error{0.0};   // max |phi, phi', phi''| at 0 and |phi - Phi|, |phi'|, |phi''| at T
  double h_simulated_initial{0.0}, h_simulated_optimised{0.0};  // E(T)/h from the time-stepped plant
  double prv_initial{0.0}, prv_optimised{0.0};
  std::vector<plant::HistorySample> history_initial, history_optimised;
  std::vector<Exponents004> exponents;  // 3 .. 6 exponents
};

struct Options004 {
  bool history{true};
  bool exponents{true};
  double dt{1e-4};
};
[[nodiscard]] plant::SimStatus reproduce_004(const Options004& o, Result004& out);

}  // namespace settle::papers
