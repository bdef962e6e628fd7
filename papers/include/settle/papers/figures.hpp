// SPDX-License-Identifier: Apache-2.0
#pragma once
// CSV of every curve of the reproduced experiments and gnuplot PNGs laid out like the papers'
// figures (seed 000 Fig. 3, seed 001 Figs. 2-7, seed 004 Fig. 3). PNGs need gnuplot on the PATH;
// without it the CSV files and the .gp scripts are still written. gnuplot runs without a shell
// (spawn.hpp), in the output directory, with the script on its standard input and the PNG on its
// standard output (a file this process opens). No name a user chose ever reaches gnuplot's parser
// (it runs data names starting with '<' and output names starting with '|' through /bin/sh): data
// named by the user goes into the script as a datablock. Any directory or file name works.
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "settle/core/move.hpp"
#include "settle/papers/reproduce.hpp"
#include "settle/plant/csv_columns.hpp"
#include "settle/plant/status.hpp"
#include "settle/commission/tune.hpp"

namespace settle::papers {

struct FigureFiles {
  std::vector<std::string> csv;
  std::vector<std::string> png;
  bool gnuplot{false};  // false: gnuplot was not found, scripts written but not run
};

[[nodiscard]] plant::SimStatus write_figures_000(const Result000& r, const std::string& dir, FigureFiles& out);
[[nodiscard]] plant::SimStatus write_figures_001(const Result001& r, const std::string& dir, FigureFiles& out);
[[nodiscard]] plant::SimStatus write_figures_004(const Result004& r, const std::string& dir, FigureFiles& out);

// The demo's figure of one streamed move, from its `settle stream --feedback-log` CSV (`csv`, a
// file in `dir`: period, t, commanded, drive position, load position, load position replayed
// offline): commanded and measured motion in counts, which coincide when the bus is faithful.
// Writes <name>.gp and, with gnuplot, <name>.png in `dir`.
[[nodiscard]] plant::SimStatus write_stream_figure(const std::string& dir, const std::string& name, const std::string& csv,
                                            const std::string& title, FigureFiles& out);

// `settle tune --png`: residual (fraction of the unshaped residual) against frequency error (%) of
// each mode, at its nominal damping, for the chosen plan and the (at most six) slowest of the faster
// plans it beat, with the bound and the band's edges. Writes <name>.csv, <name>.gp and, with
// gnuplot, <name>.png in `dir`.
[[nodiscard]] plant::SimStatus write_tune_figure(const commission::TuneResult& r, const std::string& dir, const std::string& name,
                                          FigureFiles& out);
// settle identify's figure, like Klipper's resonance graph: above, the load deflection measured
// and fitted against time (`time_csv`: time, measured, fitted); below, their spectra over the free
// response against frequency (`spectrum_csv`: frequency, measured, fitted; log axes), each identified
// mode (`mode_hz`) marked there; deflections in `unit`. Both files in `dir`; writes <name>.gp and, with gnuplot,
// <name>.png there.
[[nodiscard]] plant::SimStatus write_identify_figure(const std::string& dir, const std::string& name,
                                              const std::string& time_csv, const std::string& spectrum_csv,
                                              const std::vector<double>& mode_hz, plant::PositionUnit unit,
                                              FigureFiles& out);

// `settle simulate --png`: from its history CSV (`csv` in `dir`, write_history_csv's columns), three
// panels: the commanded and the machine's output position against time; the output's deviation from
// the final position over the whole run with the settling band; and the tail after the command
// ends (t >= end), zoomed to what is left there, with the residual amplitude and the band drawn.
// Writes <name>.gp and, with gnuplot, <name>.png in `dir`.
struct SimulateFigure {
  double end{0.0};       // when the command came to rest (s)
  double target{0.0};    // the command's final position
  double residual{0.0};  // residual amplitude at `end` (output units)
  double band{0.0};      // settling band (output units)
  std::string title;     // what was simulated, in words
  plant::PositionUnit unit{plant::PositionUnit::m};  // output unit
};
[[nodiscard]] plant::SimStatus write_simulate_figure(const std::string& dir, const std::string& name, const std::string& csv,
                                              const SimulateFigure& f, FigureFiles& out);

// `settle plan --png` and `settle sample --png`: the move itself, sampled every `dt` from 0 to its
// end: four panels, position (the target dashed), velocity, acceleration and jerk against time,
// each with the move's peak drawn dashed at plus and minus its value. Writes <name>.csv (sample's
// columns, move_columns), <name>.gp and, with gnuplot, <name>.png in `dir`.
// io_error also when a sample is not finite (nothing is drawn then).
struct MoveFigure {
  double dt{0.0};     // sample period (s), > 0
  std::string title;  // what was planned, in words
  plant::PositionUnit unit{plant::PositionUnit::m};  // position unit (labels only)
};
[[nodiscard]] plant::SimStatus write_move_figure(const core::Move<double>& move, const std::string& dir,
                                          const std::string& name, const MoveFigure& f, FigureFiles& out);

// The columns of a sampled move: t_s, position_<u>, velocity_<u>_per_s, acceleration_<u>_per_s2,
// jerk_<u>_per_s3 (plant/csv_columns.hpp); with `axis` (1..N, settle sample --axes) the four
// motion columns only, each quantity suffixed _<axis> before its unit (position_2_m, ...).
[[nodiscard]] std::vector<std::string> move_columns(plant::PositionUnit u, int axis = 0);
// The header line of `columns`, comma-separated, with its newline.
[[nodiscard]] std::string csv_header(const std::vector<std::string>& columns);

// The move every `dt` from 0 to its end (the last sample at its end) as `settle sample` prints it
// and the move figure reads it: the header (move_columns), then one row a sample. false when a
// sample is not finite (nothing of it written) or a write fails.
[[nodiscard]] bool write_move_rows(std::FILE* f, const core::Move<double>& move, double dt, plant::PositionUnit u);
// One row of that table: t as %.9g, then each value as %.12g, comma-separated (multi-axis sample
// prints its rows with it too).
void write_sample_row(std::FILE* f, std::span<const double> row);

// `text` as a gnuplot single-quoted string: ' doubled (gnuplot's escape; backslashes are literal
// there), line breaks as spaces (a gnuplot command is one line).
[[nodiscard]] std::string gnuplot_string(std::string_view text);

// The columns of a time history on a plant of `kind` whose positions are in `u`: t_s, the command's
// position, velocity, acceleration, the deflection, the output's position, velocity, acceleration,
// and the kinetic and potential energy (their unit: plant::energy_suffix).
[[nodiscard]] std::vector<std::string> history_columns(plant::PlantKind kind, plant::PositionUnit u);
// Writes time histories as CSV (history_columns, then one row a sample; the `--csv` of settle
// simulate uses it too).
[[nodiscard]] plant::SimStatus write_history_csv(const std::vector<plant::HistorySample>& h, const std::string& path,
                                                 plant::PlantKind kind, plant::PositionUnit u);

}  // namespace settle::papers
