// SPDX-License-Identifier: Apache-2.0
// settle identify: the composition root of sim's run_identify (settle/commission/identify_run.hpp). The
// options become an excitation (a planned jerk-limited move, a train of it back and forth before
// it, and a hold: settle/commission/identify_excitation.hpp) streamed to the drive on
// --bus, the drive's feedback becomes the modes, and the report goes out as text or --json, with
// the --png figure (measured against fitted, in time and frequency).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "drive_advice.hpp"
#include "eds_option.hpp"
#include "figure_option.hpp"
#include "io/json.hpp"
#include "io/modes_json.hpp"
#include "move_options.hpp"
#include "options.hpp"
#include "progress.hpp"
#include "plant_options.hpp"
#include "settle/core/planner.hpp"
#include "settle/hal/eds_reader.hpp"
#include "settle/papers/figures.hpp"
#include "settle/plant/move_vocabulary.hpp"
#include "settle/commission/identify_excitation.hpp"
#include "settle/commission/identify_run.hpp"
#include "settle/testbed/clocked_bus.hpp"
#include "clocked_bus_open.hpp"

namespace settle::app {

namespace {

// The excitation's limits, each in its table range; planned into the move, or refused naming
// the option to change. The move respects every limit by construction (the planner's jerk-limited
// profile); what can still be out of reach is its length and its size in counts.
int parse_spec(const ParsedArgs& args, commission::IdentifyRunSpec& spec) {
  const bool json = args.json();
  RequestError err;
  testbed::StreamSpec& s = spec.stream;
  if (!parse_plant(args, s.plant, err)) return report_bad_request(err, json);
  if (!parse_drive(args, s.plant, s.drive, err)) return report_bad_request(err, json);
  const std::string bus = args.text_or_default("--bus");
  if (args.has("--noise") && bus != "loopback") {
    return report_bad_request({"option_not_for_bus", "--noise",
                               "--noise: adds noise in the in-process drive (--bus loopback); on " + bus +
                                   " the drive is another process"},
                              json);
  }
  s.drive.load_noise_counts = args.real_or_default("--noise");
  s.drive.noise_seed = static_cast<std::uint64_t>(args.integer("--seed"));
  spec.options.max_modes = static_cast<std::size_t>(args.integer("--max-modes"));

  commission::IdentifyExcitation ex{};
  ex.distance = args.real_or_default("--distance");
  ex.limits = {.vmax = args.real_or_default("--vmax"), .amax = args.real_or_default("--amax"),
               .jmax = args.real_or_default("--jmax")};
  ex.round_trips = static_cast<std::size_t>(args.integer("--train"));
  // A limit so small that the move cannot fit the excitation's 600 s is that limit's fault (the
  // planner, fed a denormal, fails in ways that would name another option).
  double bound = 0.0;
  const char* binding = binding_limit(ex.distance, core::as_optional(ex.limits), "--vmax", &bound);
  if (!(bound <= 600.0)) {
    return report_bad_request({"too_long", binding,
                               std::string{binding} + ": the excitation's move lasts at least " + format_number(bound) +
                                   " s within this limit; at most 600 s"},
                              json);
  }
  if (const core::Status st = commission::plan_identify_excitation(ex, s.axes.front().move); st != core::Status::ok) {
    return report_bad_request({core::to_string(st), "--distance",
                               std::string{"--distance: the excitation cannot be planned within the limits: "} +
                                   core::describe(st)},
                              json);
  }
  s.settle_time_s = args.real_or_default("--hold");
  // Refused for its length first: an excitation of hours is not what was meant, and its peaks,
  // summed over copies hours apart, carry rounding of a few 1e-9 that the check below would
  // misreport as a limit exceeded (--distance 1000 --vmax 1: 46 202 s with 15 round trips).
  if (s.axes.front().move.duration() > 600.0) {
    // The move alone too long: its limits are to blame; otherwise the train of its copies.
    const double once = s.axes.front().move.profile().duration();
    if (once > 600.0 || ex.round_trips == 0) {
      return report_bad_request({"too_long", binding,
                                 std::string{binding} + ": the excitation's move lasts " + format_number(once) +
                                     " s; at most 600 s (raise --vmax, --amax or --jmax, or shorten --distance)"},
                                json);
    }
    return report_bad_request(
        {"too_long", "--train",
         "--train: the move and " + std::to_string(ex.round_trips) + " round trips of it last " +
             format_number(s.axes.front().move.duration()) + " s (the move alone " + format_number(once) +
             " s); at most 600 s (fewer round trips, or raise --vmax, --amax or --jmax, or shorten --distance)"},
        json);
  }
  // The excitation as planned must respect what was asked (the planner guarantees it; checked so
  // that a planner change cannot silently excite harder than the user allowed).
  const core::Status within = core::check_limits(ex.limits, s.axes.front().move.peaks());
  if (within != core::Status::ok) {
    const char* exceeded = plant::option_of(within, core::MoveRequest{});  // --vmax, --amax or --jmax
    return report_bad_request({"excitation_exceeds_limits", exceeded,
                               std::string{exceeded} + ": the planned excitation would exceed this limit"},
                              json);
  }
  // What the estimator will fit: the excitation and the hold, one sample per period (the start-up
  // is not recorded). Refused here, before the bus is opened, rather than after minutes of streaming.
  // It also keeps the stream (start-up + record) inside kMaxStreamPeriods at the shortest period.
  static_assert(static_cast<double>(commission::kMaxIdentifySamples) + 5.0 * 1e6 / 100.0 <= kMaxStreamPeriods);
  const double recorded = (s.axes.front().move.duration() + s.settle_time_s) * 1e6 / s.drive.scale.period_us;
  if (recorded > static_cast<double>(commission::kMaxIdentifySamples)) {
    return report_bad_request(
        {"too_many_samples", "--hold",
         "--hold: the record would hold " + format_number(std::ceil(recorded)) + " samples (excitation " +
             format_number(s.axes.front().move.duration()) + " s + hold " + format_number(s.settle_time_s) +
             " s, one per --period-us); the estimator fits at most " +
             std::to_string(commission::kMaxIdentifySamples) + " (a shorter --hold or a longer --period-us)"},
        json);
  }
  if (const char* who = counts_reach_exceeded(s.axes.front().move.distance(), s.drive.scale.counts_per_unit,
                                               s.drive.load_counts_per_unit)) {
    return report_bad_request({"out_of_range", "--distance",
                               std::string{"--distance: the excitation exceeds 32-bit counts with "} + who},
                              json);
  }
  s.axes.front().node = static_cast<hal::canopen::NodeId>(args.integer("--node"));
  s.heartbeat_ms = static_cast<std::uint16_t>(args.integer("--heartbeat-ms"));
  s.sdo_timeout_us = static_cast<std::uint32_t>(args.integer("--sdo-timeout-ms") * 1000);
  s.feedback_timeout_periods = static_cast<std::uint16_t>(args.integer("--feedback-timeout-periods"));
  EdsOption eds;
  const std::uint8_t nodes[] = {s.axes.front().node};
  if (const int rc = load_eds_option(args, "identify", nodes, eds); rc >= 0) return rc;
  s.eds = eds.description;
  if (const int rc = parse_load_feedback(args, s.eds.get(), s.load_feedback); rc >= 0) return rc;
  if (s.eds && testbed::streaming_feedback(*s.eds, s.load_feedback).load_position_index == 0) {
    return report_bad_request({"no_load_feedback", "--load-feedback",
                               "--load-feedback: the drive's EDS marks no load position (0x2000 is the load "
                               "position on Settle's own drive only): name the drive's load or vibration "
                               "measurement with --load-feedback INDEX:SUB"},
                              json);
  }
  return -1;
}

std::string error_doc(const std::string& code, const std::string& why) {
  return Json{{"status", "error"}, {"error", code}, {"message", why}}.dump(-1, ' ', false,
                                                                          nlohmann::json::error_handler_t::replace);
}

int failed(const std::string& code, const std::string& why, bool json, const std::string& doc) {
  if (json) {
    std::printf("%s\n", doc.c_str());
  } else {
    std::fprintf(stderr, "settle identify: %s [%s]\n", why.c_str(), code.c_str());
  }
  return kExitFailure;
}

template <typename Writer>
bool write_file(const std::string& path, Writer&& write) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  const bool written = write(f);
  return std::fclose(f) == 0 && written;
}

// The --png figure: the two CSVs beside it (<stem>_time.csv, <stem>_spectrum.csv) and gnuplot, the
// identified modes marked on the spectrum.
std::string write_png(const commission::IdentifyRunSpec& spec, const commission::IdentifyRunReport& r, const FigurePath& png,
                      plant::PositionUnit u) {
  const std::filesystem::path dir{png.dir};
  const std::string time_csv = png.stem + "_time.csv";
  const std::string spectrum_csv = png.stem + "_spectrum.csv";
  if (!write_file((dir / time_csv).string(), [&](std::FILE* f) { return commission::write_identify_time_csv(spec, r, u, f); }) ||
      !write_file((dir / spectrum_csv).string(),
                  [&](std::FILE* f) { return commission::write_identify_spectrum_csv(spec, r, u, f); })) {
    return "cannot write the figure's data beside " + png.png;
  }
  std::vector<double> mode_hz;
  for (const commission::UncertainMode& m : r.result.modes) mode_hz.push_back(m.omega / (2.0 * M_PI));
  papers::FigureFiles files{};
  const plant::SimStatus st =
      papers::write_identify_figure(png.dir, png.stem, time_csv, spectrum_csv, mode_hz, u, files);
  if (st != plant::SimStatus::ok) return "cannot write " + png.png + ": " + describe(st);
  if (!files.gnuplot) return "gnuplot was not found: wrote " + (dir / (png.stem + ".gp")).string() + " and the CSVs only";
  return {};
}

// The JSON document, one line: {"status":"ok","modes":[...] (io/modes_json.hpp: what `settle tune
// --modes-from` reads) sorted by omega,"excitation":{...},"fit":{order, rms_residual, ...}}; on
// failure {"status":"error","error":code,"message":...}.
std::string identify_document(const commission::IdentifyRunSpec& spec, const commission::IdentifyRunReport& r,
                              plant::PositionUnit u) {
  Json j;
  if (!r.ok()) {
    j["status"] = "error";
    j["error"] = r.failure_code;
    j["message"] = r.failure;
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  }
  const commission::IdentifyResult& f = r.result;
  j["status"] = "ok";
  j["unit"] = plant::to_string(u);  // of the excitation's distance and the deflections: a label
  j["modes"] = modes_json(f.modes);
  const core::Move<double>& mv = spec.stream.axes.front().move;
  j["excitation"] = {{"profile", core::to_string(mv.profile().kind())},
                     {"distance", mv.distance()},
                     {"round_trips", commission::train_round_trips(mv)},
                     {"duration", mv.duration()},
                     {"peak_velocity", mv.peaks().v},
                     {"peak_acceleration", mv.peaks().a},
                     {"peak_jerk", mv.peaks().j},
                     {"hold", spec.stream.settle_time_s},
                     {"period", r.period_s},
                     {"samples", r.motor.size()},
                     {"peak_deflection", f.peak_deflection},
                     {"bus", r.stream.bus}};
  j["fit"] = {{"order", f.order},
              {"rms_residual", f.rms_residual},
              {"noise_rms", f.noise_rms},
              {"pencil_order", f.pencil_order},
              {"rigid_gain", f.rigid_gain},
              {"iterations", f.iterations},
              {"confidence", spec.options.confidence},
              {"max_modes", spec.options.max_modes}};
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

int cmd_identify(int argc, char** argv) {
  ParsedArgs args;
  if (const int rc = parse_or_exit("identify", argc, argv, args); rc >= 0) return rc;
  std::optional<FigurePath> png;
  if (const int rc = parse_png_option(args, png); rc >= 0) return rc;
  commission::IdentifyRunSpec spec{};
  if (const int rc = parse_spec(args, spec); rc >= 0) return rc;

  hal::SocketCanBus socketcan;
  std::string bus_error;
  const std::unique_ptr<testbed::ClockedBus> bus = open_clocked_bus(args, socketcan, bus_error);
  if (!bus) return failed("bus_unavailable", bus_error, args.json(), error_doc("bus_unavailable", bus_error));

  const Progress progress;
  progress.say("settle identify: start-up (at most 5 s), then %.1f s of excitation and hold on %s ...",
               spec.stream.axes.front().move.duration() + spec.stream.settle_time_s, args.text_or_default("--bus").c_str());
  commission::IdentifyRunReport report = commission::run_identify(spec, *bus);
  progress.done();
  if (!report.ok()) {
    if (const std::string advice = drive_advice(report.stream); !advice.empty()) report.failure += ": " + advice;
  }
  if (!report.ok()) return failed(report.failure_code, report.failure, args.json(), identify_document(spec, report, position_unit(args)));
  if (png) {
    if (const std::string why = write_png(spec, report, *png, position_unit(args)); !why.empty()) {
      return failed("figure_failed", why, args.json(), error_doc("figure_failed", why));
    }
  }
  if (args.json()) {
    std::printf("%s\n", identify_document(spec, report, position_unit(args)).c_str());
  } else {
    commission::write_identify_text(spec, report, stdout);
  }
  return kExitOk;
}

}  // namespace settle::app
