// SPDX-License-Identifier: Apache-2.0
// --png FILE (plan, sample, simulate, tune, identify): where a command draws its figure. The name must end in
// .png; the figure's data and script go beside it (<stem>.csv, <stem>.gp, ...). The name never
// reaches gnuplot's parser (papers/figures.hpp), so any name a file system takes works.
#pragma once

#include <optional>
#include <string>

#include "options.hpp"
#include "settle/core/move.hpp"

namespace settle::app {

struct FigurePath {
  std::string dir;   // the directory the figure goes to ("." for a bare name)
  std::string stem;  // its name without .png
  std::string png;   // the name as given
};

// Exit status (2: bad_png, naming --png) or -1 with `out` set when --png was given (empty when not).
[[nodiscard]] int parse_png_option(const ParsedArgs& args, std::optional<FigurePath>& out);

// plan and sample --png with --axes: exit 2, conflicting_options naming --png (one axis is drawn).
[[nodiscard]] int refuse_png_with_axes(const ParsedArgs& args);

// plan and sample --png: the move every `dt` (papers::write_move_figure), titled for `command`.
// Exit status: 0 drawn (or, without gnuplot, its script and data written, said on stderr), 1
// write_failed naming --png.
[[nodiscard]] int write_move_png(const ParsedArgs& args, const core::Move<double>& move, double dt, const char* command,
                                 const FigurePath& png);

}  // namespace settle::app
