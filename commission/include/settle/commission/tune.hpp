// SPDX-License-Identifier: Apache-2.0
#pragma once
// The fastest move that stays at rest over what is known about the machine: given modes with
// uncertainty bands (identified confidence intervals, or +-PCT on omega) and a move (distance, and
// limits or a move time), plan every profile family Settle has (every registry profile, alone and
// shaped by ZV, ZVD or EI composed over the modes, designed at the nominal modes or retuned within
// the band) and keep the shortest whose relative residual stays <= residual_max for every mode over
// its whole band. docs/tuning.md defines the residual and says how the worst case is established.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "settle/commission/uncertain_mode.hpp"
#include "settle/core/enum_text.hpp"
#include "settle/core/planner.hpp"
#include "settle/plant/status.hpp"

namespace settle::commission {

// The move: distance, and either a move time of the unshaped profile or limits.
struct TuneMove {
  double distance{0.0};
  std::optional<double> time;
  core::OptionalLimits limits;
};

// Bounds of one tune() call, checked before any work: the modes, and the grid each band is
// searched on (kMaxTuneOmegaPoints omega points; fewer are used when the band is narrow).
inline constexpr std::size_t kMaxTuneModes = 4;
inline constexpr std::size_t kMinTuneOmegaPoints = 17;
inline constexpr std::size_t kMaxTuneOmegaPoints = 4097;
// The work of one tune() call, bounded two ways: no profile's quadrature may have more than
// kMaxTuneNodes nodes (checked for every candidate before any is built: memory), and the residual
// evaluations times the nodes they sum, counted as the search goes, may not exceed
// TuneOptions::max_work (CPU: about 2 s of one core at kMaxTuneWork). Either gives too_much_work.
inline constexpr double kMaxTuneNodes = 1e6;
inline constexpr double kMaxTuneWork = 1e9;
inline constexpr std::size_t kMaxTuneZetaPoints = 9;
// A candidate longer than this (s; or not finite) is refused as too_long.
inline constexpr double kMaxTuneDuration = 3600.0;
// Where a retuned design may sit in each mode's omega band: lo + k/(n-1) (hi - lo), k = 0..n-1.
inline constexpr std::size_t kTunePlacements = 9;

struct TuneOptions {
  double residual_max{0.05};  // fraction of the unshaped residual (a step of the distance), (0, 1)
  std::size_t zeta_points{5};  // grid points across each zeta band (1 if the band is a point)
  double max_work{kMaxTuneWork};  // evaluations x quadrature nodes; more: too_much_work
};

// Every status in order (ok first, 0): its enumerator, which is also its code (to_string), and
// the sentence describe() gives. The enum and both tables are made from this list (enum_text.hpp).
#define SETTLE_TUNE_STATUSES(X) \
  X(ok, "ok") \
  /* the list of modes is empty */ \
  X(no_modes, "no modes given") \
  /* more than kMaxTuneModes */ \
  X(too_many_modes, "more modes than the tuner searches (4)") \
  /* omega not positive and finite, zeta outside [0, 1), a non-finite gain */ \
  X(bad_mode, \
    "a mode's omega is not positive and finite, its zeta is outside [0, 1), or its gain is not " \
    "finite") \
  /* omega_lo <= omega <= omega_hi, 0 < omega_lo, 0 <= zeta_lo <= zeta <= zeta_hi < 1 violated */ \
  X(bad_band, \
    "a mode's band does not contain it (0 < omega_lo <= omega <= omega_hi, 0 <= zeta_lo <= zeta" \
    " <= zeta_hi < 1)") \
  /* distance zero or not finite, neither time nor limits, or a non-positive one */ \
  X(bad_move, "the move needs a finite non-zero distance and a positive time or positive limits") \
  /* residual_max outside (0, 1) */ \
  X(bad_residual_max, "residual_max must lie in (0, 1)") \
  /* zeta_points outside 1..kMaxTuneZetaPoints, or max_work not positive */ \
  X(bad_grid, "zeta_points must lie in 1..9 and max_work be positive") \
  /* a quadrature over kMaxTuneNodes, or the search over max_work (omega_hi x duration too large) */ \
  X(too_much_work, \
    "the bands and the moves need too fine a search (omega_hi x move duration too large): " \
    "narrow the band, shorten the move or drop the highest mode") \
  /* every candidate either cannot be planned or exceeds residual_max somewhere */ \
  X(no_feasible_plan, \
    "no profile family keeps the residual within residual_max over the whole band (widen the " \
    "limits or the time, narrow the band, or raise residual_max)")
enum class TuneStatus : unsigned char { SETTLE_TUNE_STATUSES(SETTLE_ENUM_ENUMERATOR) };
[[nodiscard]] const char* to_string(TuneStatus s) noexcept;
[[nodiscard]] const char* describe(TuneStatus s) noexcept;

// The residual a move leaves on the mode (omega, zeta) once it is over, as a fraction of what an
// unshaped position step of the same distance leaves on that mode (PRV / 100): independent of the
// mode's gain. For a shaped move it is the unshaped profile's residual times the shaper's
// V(omega, zeta) (superposition; tests check it against a simulation of the shaped move).
[[nodiscard]] plant::SimStatus relative_residual(const core::Move<double>& move, double omega, double zeta, double& out);

struct BandWorst {
  double residual{0.0};
  double omega{0.0};
  double zeta{0.0};
  std::size_t evaluations{0};  // residuals computed
};

// The largest relative_residual of `move` over the mode's band: a grid of omega_points x
// zeta_points (ends included), then golden-section refinement in omega and in zeta around the
// grid's three largest local maxima (docs/tuning.md).
[[nodiscard]] plant::SimStatus worst_in_band(const core::Move<double>& move, const UncertainMode& band,
                                      std::size_t omega_points, std::size_t zeta_points, BandWorst& out);

// relative_residual at n evenly spaced omegas from omega_lo to omega_hi (0 < lo < hi, 2 <= n <=
// kMaxTuneOmegaPoints, else bad_range / too_many_samples): the curve `settle tune --png` draws.
[[nodiscard]] plant::SimStatus residual_curve(const core::Move<double>& move, double omega_lo, double omega_hi, double zeta,
                                       std::size_t n, std::vector<double>& out);

// The omega grid size worst_in_band is given for a move of `duration` on a band: at least a point
// every pi/4 of phase (omega * duration) across the band, within kMin/kMaxTuneOmegaPoints.
[[nodiscard]] std::size_t omega_points_for(const UncertainMode& band, double duration) noexcept;

struct TuneCandidate {
  std::string name;  // "<profile>", "<profile>+<shaper>", with "@retuned" when retuned
  core::ProfileKind profile{};
  core::ShaperKind shaper{core::ShaperKind::none};  // composed over every mode (none: unshaped)
  bool retuned{false};
  double placement{-1.0};  // retuned: where in each omega band the design sits (0 lo .. 1 hi)
  std::vector<double> design_omega;  // per mode: what the shaper (and mode-designed profile) is for
  std::vector<double> design_zeta;
  core::MoveRequest request{};  // plans the unshaped profile again (shaper none; after a time search, its time)
  bool time_searched{false};  // the profile's own planner refused the limits: shortest T searched
  bool planned{false};
  std::string refusal;  // core's status when not planned
  core::Move<double> move{};
  double duration{0.0};
  bool evaluated{false};  // false: slower than the chosen plan, so never checked
  bool meets{false};
  std::vector<BandWorst> mode_worst;  // per mode checked (in TuneResult::modes order)
  BandWorst worst{};  // when !meets: the search stopped at the first row over the bound (a lower bound)
  std::size_t worst_mode{0};
};

struct TuneResult {
  std::vector<UncertainMode> modes;      // sorted by omega
  // Each family (profile, shaper, nominal or retuned) once: planned ones by duration, refused last.
  std::vector<TuneCandidate> candidates;
  std::size_t chosen{0};                  // index into candidates (valid when status ok)
  double residual_max{0.0};
};

// Plans every candidate, then checks them shortest first. ok: candidates[chosen] is the shortest
// that meets residual_max; every planned candidate before it was evaluated and breaks the bound. The result is filled even on no_feasible_plan,
// so that the caller can show what was tried; on any other status `out` is untouched.
[[nodiscard]] TuneStatus tune(const std::vector<UncertainMode>& modes, const TuneMove& move, const TuneOptions& opt,
                              TuneResult& out);

// The input shaper of a tuned candidate: `kind` designed on each design mode in turn (the EI family
// with the tolerance tune gives it for residual_max) and composed; ShaperKind::none gives the unit
// impulse. The one place that design is made: tune's candidates, and a tuned plan read back from its
// file (settle --plan-from), which is accepted only if its impulses are exactly these.
[[nodiscard]] core::Status tuned_shaper(core::ShaperKind kind, const std::vector<double>& omega,
                                        const std::vector<double>& zeta, double residual_max, core::Shaper<double>& out);

}  // namespace settle::commission
