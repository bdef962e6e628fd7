// SPDX-License-Identifier: Apache-2.0
#include "figure_option.hpp"

#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "move_options.hpp"
#include "settle/papers/figures.hpp"

namespace settle::app {

int parse_png_option(const ParsedArgs& args, std::optional<FigurePath>& out) {
  out.reset();
  const auto png = args.text("--png");
  if (!png) return -1;
  const std::filesystem::path p{*png};
  if (p.extension() != ".png" || p.stem().empty()) {
    return report_bad_request({"bad_png", "--png", "--png: the figure's file name must end in .png"}, args.json());
  }
  out = FigurePath{p.parent_path().empty() ? std::string{"."} : p.parent_path().string(), p.stem().string(), *png};
  return -1;
}

int refuse_png_with_axes(const ParsedArgs& args) {
  return report_bad_request({"conflicting_options", "--png", "--png: draws one axis; not with --axes"}, args.json());
}

int write_move_png(const ParsedArgs& args, const core::Move<double>& move, double dt, const char* command,
                   const FigurePath& png) {
  const plant::PositionUnit unit = position_unit(args);
  char title[160];
  std::snprintf(title, sizeof title, "settle %s: %s, distance %.6g %s in %.6g s", command,
                core::to_string(move.profile().kind()), move.distance(), plant::to_string(unit), move.duration());
  papers::FigureFiles files;
  const plant::SimStatus st = papers::write_move_figure(move, png.dir, png.stem, {dt, title, unit}, files);
  if (st != plant::SimStatus::ok) {
    return report_failure(command, "write_failed", "--png: cannot write " + png.png + ": " + plant::describe(st),
                          args.json());
  }
  if (!files.gnuplot) {
    std::fprintf(stderr, "settle %s: gnuplot not found; wrote %s.gp and %s.csv only\n", command, png.stem.c_str(),
                 png.stem.c_str());
  }
  return kExitOk;
}

}  // namespace settle::app
