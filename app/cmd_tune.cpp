// SPDX-License-Identifier: Apache-2.0
// settle tune: the composition root of commission::tune (settle/commission/tune.hpp). The modes come from
// `settle identify --json` (--modes-from) or from --mode; the band from their intervals or from
// --uncertainty PCT. The chosen plan is printed as `settle plan --json` prints it, plus the band,
// its worst residual, the request that plans it again (for --plan-from) and the alternatives.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "figure_option.hpp"
#include "io/json.hpp"
#include "io/modes_json.hpp"
#include "move_options.hpp"
#include "options.hpp"
#include "io/plan_json.hpp"
#include "settle/core/profiles/registry.hpp"
#include "settle/papers/figures.hpp"
#include "settle/commission/tune.hpp"

namespace settle::app {

namespace {

struct Band {
  bool ci{true};
  double pct{0.0};     // PCT when !ci
  double zeta_pm{0.0};  // --zeta-pm (its default is the option table's)
  std::string text;  // as reported: "ci" or "+-10%"
};

// "ci", or PCT / +-PCT / ±PCT with PCT in (0, 90].
bool parse_band(const ParsedArgs& a, Band& b, RequestError& err) {
  std::string v = a.text_or_default("--uncertainty");
  b.zeta_pm = a.real_or_default("--zeta-pm");
  if (v == "ci") {
    b.ci = true;
    b.text = "ci";
    return true;
  }
  for (const std::string prefix : {"+-", "\u00b1"}) {
    if (v.rfind(prefix, 0) == 0) v = v.substr(prefix.size());
  }
  double pct = 0.0;
  if (!parse_real(v, pct) || !std::isfinite(pct) || !(pct > 0.0 && pct <= 90.0)) {
    err = {"bad_uncertainty", "--uncertainty",
           "--uncertainty: expected 'ci' or a percentage PCT in (0, 90] (also +-PCT), not '" +
               a.text("--uncertainty", "") + "'"};
    return false;
  }
  b.ci = false;
  b.pct = pct;
  b.text = "+-" + format_number(pct) + "%";
  return true;
}

commission::UncertainMode banded(double omega, double zeta, double gain, const Band& b) {
  commission::UncertainMode m{.omega = omega, .zeta = zeta, .gain = gain, .omega_lo = omega * (1.0 - b.pct / 100.0),
                       .omega_hi = omega * (1.0 + b.pct / 100.0), .zeta_lo = std::max(0.0, zeta - b.zeta_pm),
                       .zeta_hi = std::min(0.99, zeta + b.zeta_pm)};
  m.zeta_hi = std::max(m.zeta_hi, zeta);
  return m;
}

Json band_json(const commission::TuneResult& r, const commission::TuneCandidate& c, const Band& b) {
  Json band;
  band["uncertainty"] = b.text;
  Json modes = Json::array();
  for (std::size_t j = 0; j < r.modes.size(); ++j) {
    const commission::UncertainMode& m = r.modes[j];
    Json e;
    e["omega"] = m.omega;
    e["zeta"] = m.zeta;
    e["gain"] = m.gain;
    e["omega_band"] = Json::array({m.omega_lo, m.omega_hi});
    e["zeta_band"] = Json::array({m.zeta_lo, m.zeta_hi});
    if (j < c.mode_worst.size()) {
      e["worst_residual"] = c.mode_worst[j].residual;
      e["worst_at"] = Json{{"omega", c.mode_worst[j].omega}, {"zeta", c.mode_worst[j].zeta}};
    }
    modes.push_back(e);
  }
  band["modes"] = modes;
  return band;
}

Json family_json(const commission::TuneCandidate& c) {
  Json f;
  f["name"] = c.name;
  f["profile"] = core::to_string(c.profile);
  f["shaper"] = core::to_string(c.shaper);
  f["retuned"] = c.retuned;
  f["placement"] = c.retuned ? Json(c.placement) : Json(nullptr);
  Json design = Json::array();
  for (std::size_t j = 0; j < c.design_omega.size(); ++j) {
    design.push_back(Json{{"omega", c.design_omega[j]}, {"zeta", c.design_zeta[j]}});
  }
  f["design_modes"] = design;
  f["time_searched"] = c.time_searched;
  return f;
}

Json alternatives_json(const commission::TuneResult& r) {
  Json a = Json::array();
  for (std::size_t i = 0; i < r.candidates.size(); ++i) {
    const commission::TuneCandidate& c = r.candidates[i];
    Json e;
    e["name"] = c.name;
    e["chosen"] = i == r.chosen;
    if (!c.planned) {
      e["planned"] = false;
      e["refusal"] = c.refusal;
    } else {
      e["planned"] = true;
      e["duration"] = c.duration;
      e["evaluated"] = c.evaluated;
      e["meets"] = c.meets;
      // A failing candidate's search stops where it first breaks the bound: at least this.
      e["worst_residual"] = c.evaluated ? Json(c.worst.residual) : Json(nullptr);
    }
    a.push_back(e);
  }
  return a;
}

// The alternatives: those whose residual was checked (each faster plan the chosen one beat, and
// itself); with `verbose` also those not checked or not planned, else one line counting them.
void print_text(const commission::TuneResult& r, const Band& b, bool verbose) {
  const commission::TuneCandidate& c = r.candidates[r.chosen];
  std::printf("chosen       %s\n", c.name.c_str());
  std::printf("duration     %.9g s (profile %.9g s + shaper %.9g s)\n", c.move.duration(),
              c.move.profile().duration(), c.move.shaper().duration());
  std::printf("worst        %.4g of the unshaped residual (bound %.4g), band %s\n", c.worst.residual, r.residual_max,
              b.text.c_str());
  for (std::size_t j = 0; j < r.modes.size() && j < c.mode_worst.size(); ++j) {
    const commission::UncertainMode& m = r.modes[j];
    std::printf("  mode %zu     omega %.6g [%.6g, %.6g] rad/s, zeta %.4g [%.4g, %.4g]: worst %.4g at omega %.6g, "
                "zeta %.4g\n",
                j + 1, m.omega, m.omega_lo, m.omega_hi, m.zeta, m.zeta_lo, m.zeta_hi, c.mode_worst[j].residual,
                c.mode_worst[j].omega, c.mode_worst[j].zeta);
  }
  std::printf("alternatives\n");
  std::size_t unchecked = 0, unplanned = 0;
  for (const commission::TuneCandidate& a : r.candidates) {
    if (!a.planned) {
      ++unplanned;
      if (verbose) std::printf("  %-28s not planned (%s)\n", a.name.c_str(), a.refusal.c_str());
    } else if (!a.evaluated) {
      ++unchecked;
      if (verbose) std::printf("  %-28s %.6g s, not checked (slower than the chosen plan)\n", a.name.c_str(), a.duration);
    } else {
      std::printf("  %-28s %.6g s, %s %.4g\n", a.name.c_str(), a.duration, a.meets ? "worst" : "fails: at least",
                  a.worst.residual);
    }
  }
  if (!verbose && unchecked + unplanned > 0) {
    std::printf("  (%zu more not checked: slower than the chosen plan; %zu not planned; --verbose lists them)\n",
                unchecked, unplanned);
  }
}

}  // namespace

int cmd_tune(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("tune", argc, argv, args); rc >= 0) return rc;
  const bool json = args.json();
  RequestError err;
  Band band;
  if (!parse_band(args, band, err)) return report_bad_request(err, json);

  // The modes and their band.
  std::vector<commission::UncertainMode> modes;
  const auto file = args.text("--modes-from");
  const std::string mode_option = file ? "--modes-from" : "--mode";
  if (file && args.has("--mode")) {
    return report_bad_request({"conflicting_options", "--mode", "--mode: give --modes-from or --mode, not both"}, json);
  }
  if (file) {
    if (!read_modes_file(*file, "--modes-from", band.ci, commission::kMaxTuneModes, modes, err)) {
      return report_bad_request(err, json);
    }
    if (!band.ci) {
      for (commission::UncertainMode& m : modes) m = banded(m.omega, m.zeta, m.gain, band);
    }
  } else if (args.has("--mode")) {
    if (band.ci) {
      return report_bad_request({"missing_interval", "--uncertainty",
                                 "--uncertainty: 'ci' needs the identified intervals of --modes-from; with --mode "
                                 "give a percentage, e.g. --uncertainty 10"},
                                json);
    }
    for (const std::vector<double>& m : args.lists("--mode")) {
      modes.push_back(banded(m[0], m[1], m.size() > 2 ? m[2] : 1.0, band));
    }
  } else {
    return report_bad_request({"missing_option", "--mode",
                               "--mode: required (or --modes-from FILE): the modes to tune for"},
                              json);
  }

  // The move.
  const auto distance = args.real("--distance");
  if (!distance) return report_bad_request({"missing_option", "--distance", "--distance: required"}, json);
  commission::TuneMove mv{.distance = *distance, .time = args.real("--time"), .limits = limits_of(args)};
  if (mv.time && mv.limits.any()) {
    return report_bad_request({"conflicting_options", "--time",
                               "--time: give --time or limits (--vmax, --amax, --jmax), not both"},
                              json);
  }
  if (!mv.time && !mv.limits.any()) {
    return report_bad_request({"missing_option", "--time",
                               "--time: required, or limits (--vmax, --amax, --jmax)"},
                              json);
  }
  if (mv.distance == 0.0) {
    return report_bad_request({"out_of_range", "--distance", "--distance: must not be 0 (nothing to tune)"}, json);
  }
  std::optional<FigurePath> png;
  if (const int rc = parse_png_option(args, png); rc >= 0) return rc;

  commission::TuneOptions opt;
  opt.residual_max = args.real_or_default("--residual-max");
  commission::TuneResult result;
  const commission::TuneStatus st = commission::tune(modes, mv, opt, result);
  switch (st) {
    case commission::TuneStatus::ok: break;
    case commission::TuneStatus::no_feasible_plan: {
      // The nearest miss, to say how far off the bound is.
      const commission::TuneCandidate* best = nullptr;
      for (const commission::TuneCandidate& c : result.candidates) {
        if (c.planned && c.evaluated && (best == nullptr || c.worst.residual < best->worst.residual)) best = &c;
      }
      std::string msg = "--residual-max: " + std::string{describe(st)};
      if (best != nullptr) {
        msg += "; nearest: " + best->name + " (" + format_number(best->duration) + " s) leaves at least " +
               format_number(best->worst.residual);
      }
      return report_bad_request({"no_feasible_plan", "--residual-max", msg}, json);
    }
    case commission::TuneStatus::bad_move:
      return report_bad_request({"bad_move", "--distance", "--distance: " + std::string{describe(st)}}, json);
    default:
      return report_bad_request({to_string(st), mode_option, mode_option + ": " + describe(st)}, json);
  }
  const commission::TuneCandidate& chosen = result.candidates[result.chosen];

  Json j = plan_json(chosen.move);
  j["candidate"] = family_json(chosen);  // "family" is the plan's own key (which family of a profile won)
  j["request"] = request_json(chosen.request);
  j["robust_band"] = band_json(result, chosen, band);
  j["worst_residual"] = chosen.worst.residual;
  j["residual_max"] = result.residual_max;
  j["alternatives"] = alternatives_json(result);
  if (!all_finite(j)) {
    return report_bad_request({"non_finite_result", "--distance", "--distance: the tuned plan has a non-finite number"},
                              json);
  }
  if (png) {
    papers::FigureFiles files;
    const plant::SimStatus fs = papers::write_tune_figure(result, png->dir, png->stem, files);
    if (fs != plant::SimStatus::ok) {
      return report_failure("tune", "write_failed", "cannot write " + png->png + ": " + describe(fs), json);
    }
    if (!files.gnuplot) std::fprintf(stderr, "settle tune: gnuplot not found; wrote the .gp and .csv only\n");
  }
  if (json) {
    print_json(j);
  } else {
    print_text(result, band, args.flag("--verbose"));
  }
  return kExitOk;
}

}  // namespace settle::app
