// SPDX-License-Identifier: Apache-2.0
#include "settle/papers/figures.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "settle/testbed/spawn.hpp"

namespace settle::papers {

namespace {

namespace fs = std::filesystem;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

bool write_text(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  return std::fclose(f) == 0 && ok;
}

// gnuplot is found by posix_spawnp's PATH search: `gnuplot --version` runs, or it is absent.
bool have_gnuplot() {
  testbed::SpawnOptions o;
  o.output = testbed::SpawnOutput::discard;
  return testbed::run_program({"gnuplot", "--version"}, o).status == testbed::SpawnStatus::ok;
}

// Reads a file this process wrote (a figure's data) whole.
bool read_text(const std::string& path, std::string& out) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return false;
  out.clear();
  char buf[65536];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
  const bool ok = std::ferror(f) == 0;
  return std::fclose(f) == 0 && ok;
}

// `csv` as the gnuplot datablock $var: the data goes into the script itself. gnuplot runs a data
// file name that starts with '<' (and an output name that starts with '|') through /bin/sh, so no
// name a user chose may reach its parser: data comes inline, the PNG leaves on its standard output.
std::string datablock(const std::string& var, const std::string& csv) {
  return "$" + var + " << EOD\n" + csv + (csv.empty() || csv.back() != '\n' ? "\n" : "") + "EOD\n";
}

// The datablock $var holding the file `name` in `dir` (written by this process).
bool datablock_of(const std::string& dir, const std::string& name, const std::string& var, std::string& out) {
  std::string csv;
  if (!read_text((fs::path{dir} / name).string(), csv)) return false;
  out += datablock(var, csv);
  return true;
}

// Writes `script` next to the data (<name>.gp: rerun by hand with `gnuplot <name>.gp > <name>.png`)
// and runs gnuplot in that directory with the same script on its standard input and its standard
// output to <name>.png, a file this process opens. No shell, no `set output`, and no user-chosen
// name in any command or script: scripts name only the fixed data files of the paper figures or
// carry their data inline (datablock).
plant::SimStatus plot(const std::string& dir, const std::string& name, const std::string& script, FigureFiles& out,
               const char* terminal = "size 1400,1000") {
  const std::string gp = (fs::path{dir} / (name + ".gp")).string();
  const std::string png = (fs::path{dir} / (name + ".png")).string();
  const std::string text = std::string{"# gnuplot writes the PNG on its standard output: gnuplot this.gp > this.png\n"} +
                           "set terminal pngcairo " + terminal + " font 'Sans,10'\nset datafile separator ','\nset grid\n" +
                           script;
  if (!write_text(gp, text)) return plant::SimStatus::io_error;
  if (!out.gnuplot) return plant::SimStatus::ok;
  testbed::SpawnOptions o;
  o.workdir = dir;
  o.input = text;
  o.output = testbed::SpawnOutput::to_file;
  o.output_file = png;
  const testbed::SpawnResult r = testbed::run_program({"gnuplot"}, o);
  if (r.status == testbed::SpawnStatus::not_found) {
    out.gnuplot = false;  // gone since prepare(): the script stays for a rerun by hand
    std::error_code ec;
    fs::remove(png, ec);
    return plant::SimStatus::ok;
  }
  if (r.status != testbed::SpawnStatus::ok) {
    std::error_code ec;
    fs::remove(png, ec);  // no half-written figure left behind
    return plant::SimStatus::io_error;
  }
  out.png.push_back(png);
  return plant::SimStatus::ok;
}

plant::SimStatus prepare(const std::string& dir, FigureFiles& out) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return plant::SimStatus::io_error;
  out = FigureFiles{};
  out.gnuplot = have_gnuplot();
  return plant::SimStatus::ok;
}

}  // namespace

std::string gnuplot_string(std::string_view text) {
  std::string q = "'";
  for (const char c : text) {
    if (c == '\'') {
      q += "''";
    } else if (c == '\n' || c == '\r') {
      q += ' ';
    } else {
      q += c;
    }
  }
  q += '\'';
  return q;
}

std::string csv_header(const std::vector<std::string>& columns) {
  std::string line;
  for (const std::string& c : columns) line += (line.empty() ? "" : ",") + c;
  return line + "\n";
}

std::vector<std::string> history_columns(plant::PlantKind kind, plant::PositionUnit u) {
  using plant::column;
  using plant::motion_suffix;
  const std::string_view e = plant::energy_suffix(kind, u);
  return {column("t", "s"),
          column("command_position", motion_suffix(u, 0)),
          column("command_velocity", motion_suffix(u, 1)),
          column("command_acceleration", motion_suffix(u, 2)),
          column("deflection", motion_suffix(u, 0)),
          column("position", motion_suffix(u, 0)),
          column("velocity", motion_suffix(u, 1)),
          column("acceleration", motion_suffix(u, 2)),
          column("kinetic_energy", e),
          column("potential_energy", e)};
}

plant::SimStatus write_history_csv(const std::vector<plant::HistorySample>& h, const std::string& path,
                                   plant::PlantKind kind, plant::PositionUnit u) {
  const std::string header = csv_header(history_columns(kind, u));
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return plant::SimStatus::io_error;
  std::fputs(header.c_str(), f);
  for (const plant::HistorySample& s : h) {
    if (std::ferror(f) != 0) break;  // every row lost from here: stop writing them
    std::fprintf(f, "%.9g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", s.t, s.command.p, s.command.v,
                 s.command.a, s.deflection, s.position, s.velocity, s.acceleration, s.energy.kinetic,
                 s.energy.potential);
  }
  // Every write checked: a row the stream could not take (a full disk, a file that takes no data)
  // is an error, not only a close that fails.
  const bool written = std::fflush(f) == 0 && std::ferror(f) == 0;
  return std::fclose(f) == 0 && written ? plant::SimStatus::ok : plant::SimStatus::io_error;
}

plant::SimStatus write_stream_figure(const std::string& dir, const std::string& name, const std::string& csv,
                              const std::string& title, FigureFiles& out) {
  const plant::SimStatus st = prepare(dir, out);
  if (st != plant::SimStatus::ok) return st;
  std::string script;
  if (!datablock_of(dir, csv, "stream", script)) return plant::SimStatus::io_error;
  script +=
      "set title " + gnuplot_string(title) +
      "\nset xlabel 't from the move start (s)'\nset ylabel 'counts'\nset key bottom right\n"
      "plot $stream every ::1 using 2:3 with lines lw 2 title 'commanded setpoint (RPDO1)', \\\n"
      "     $stream every ::1 using 2:4 with lines title 'drive position (TPDO1)', \\\n"
      "     $stream every ::1 using 2:5 with lines lw 2 title 'load position (TPDO2)', \\\n"
      "     $stream every ::1 using 2:6 with lines dt 2 title 'load position, offline replay'\n";
  return plot(dir, name, script, out, "noenhanced size 900,500");  // ids and paths are plain text
}

plant::SimStatus write_tune_figure(const commission::TuneResult& r, const std::string& dir, const std::string& name, FigureFiles& out) {
  if (r.chosen >= r.candidates.size() || r.modes.empty()) return plant::SimStatus::bad_range;
  // The chosen plan and the closest of the faster ones it beat.
  std::vector<const commission::TuneCandidate*> shown{&r.candidates[r.chosen]};
  for (std::size_t i = r.chosen; i-- > 0 && shown.size() < 7;) {
    if (r.candidates[i].planned && r.candidates[i].evaluated) shown.push_back(&r.candidates[i]);
  }
  plant::SimStatus st = prepare(dir, out);
  if (st != plant::SimStatus::ok) return st;
  constexpr std::size_t kPoints = 401;
  // x: frequency error in % around each mode's nominal, over twice its band (at least +-10 %).
  double lo_pct = -10.0, hi_pct = 10.0;
  for (const commission::UncertainMode& m : r.modes) {
    lo_pct = std::min(lo_pct, 2.0 * 100.0 * (m.omega_lo / m.omega - 1.0));
    hi_pct = std::max(hi_pct, 2.0 * 100.0 * (m.omega_hi / m.omega - 1.0));
  }
  lo_pct = std::max(lo_pct, -95.0);
  // Columns: the frequency error (%), then each plan's residual on each mode as a fraction of the
  // unshaped residual (plant/csv_columns.hpp).
  std::string csv = plant::column("frequency_error", "pct");
  std::vector<std::vector<double>> cols;
  std::string plot_cmd = "plot ";
  std::size_t col = 2;
  for (const commission::TuneCandidate* c : shown) {
    for (std::size_t j = 0; j < r.modes.size(); ++j) {
      const commission::UncertainMode& m = r.modes[j];
      std::vector<double> y;
      st = commission::residual_curve(c->move, m.omega * (1.0 + lo_pct / 100.0), m.omega * (1.0 + hi_pct / 100.0), m.zeta, kPoints,
                          y);
      if (st != plant::SimStatus::ok) return st;
      cols.push_back(std::move(y));
      const std::string title = c->name + fmt(" (%.4g s)", c->duration) +
                                (r.modes.size() > 1 ? " mode " + std::to_string(j + 1) : std::string{});
      csv += "," + plant::column("residual_" + plant::identifier(c->name) + "_mode" + std::to_string(j + 1), "ratio");
      plot_cmd += std::string{col > 2 ? ", " : ""} + "$residual skip 1 using 1:" + std::to_string(col) +
                  " with lines" + (c == shown.front() ? " lw 3" : " lw 1 dt 2") + " title " + gnuplot_string(title);
      ++col;
    }
  }
  csv += "\n";
  for (std::size_t i = 0; i < kPoints; ++i) {
    csv += fmt("%.6g", lo_pct + (hi_pct - lo_pct) * static_cast<double>(i) / static_cast<double>(kPoints - 1));
    for (const std::vector<double>& y : cols) csv += fmt(",%.9g", y[i]);
    csv += "\n";
  }
  if (!write_text((fs::path{dir} / (name + ".csv")).string(), csv)) return plant::SimStatus::io_error;
  out.csv.push_back((fs::path{dir} / (name + ".csv")).string());
  std::string edges;
  for (const commission::UncertainMode& m : r.modes) {
    for (double e : {100.0 * (m.omega_lo / m.omega - 1.0), 100.0 * (m.omega_hi / m.omega - 1.0)}) {
      edges += "set arrow from " + fmt("%.6g", e) + ", graph 0 to " + fmt("%.6g", e) + ", graph 1 nohead dt 3\n";
    }
  }
  const std::string script =
      datablock("residual", csv) +
      "set title " + gnuplot_string("settle tune: residual over the band (bound " + fmt("%.4g", r.residual_max) + ")") +
      "\nset xlabel 'frequency error (% of the nominal omega)'\nset ylabel 'residual / unshaped residual'\n"
      "set key top left\n" + edges + plot_cmd + ", " + fmt("%.9g", r.residual_max) +
      " with lines lc rgb 'red' title 'residual max'\n";
  return plot(dir, name, script, out, "noenhanced size 1000,600");
}

plant::SimStatus write_identify_figure(const std::string& dir, const std::string& name, const std::string& time_csv,
                                const std::string& spectrum_csv, const std::vector<double>& mode_hz,
                                plant::PositionUnit unit, FigureFiles& out) {
  const plant::SimStatus st = prepare(dir, out);
  if (st != plant::SimStatus::ok) return st;
  std::string script;
  if (!datablock_of(dir, time_csv, "time", script) || !datablock_of(dir, spectrum_csv, "spectrum", script)) {
    return plant::SimStatus::io_error;
  }
  script +=
      "set multiplot layout 2,1\n"
      "set title 'load deflection: measured and identified model'\nset xlabel 't from the excitation (s)'\n"
      "set ylabel " + gnuplot_string(std::string{"deflection ("} + plant::to_string(unit) + ")") + "\nset key top right\n"
      "plot $time every ::1 using 1:2 with lines title 'measured (TPDO2 - rigid motion)', \\\n"
      "     $time every ::1 using 1:3 with lines lw 2 title 'identified model'\n"
      "set title 'spectrum of the free response (dashed: the identified modes)'\nset xlabel 'frequency (Hz)'\n"
      "set ylabel " + gnuplot_string(std::string{"amplitude ("} + plant::to_string(unit) + ")") + "\nset logscale xy\n";
  // Each identified mode a dashed vertical line labelled with its frequency.
  for (std::size_t k = 0; k < mode_hz.size(); ++k) {
    const std::string f = fmt("%.6g", mode_hz[k]);
    const std::string tag = std::to_string(k + 1);
    // Labels one below the other, so that modes close together stay readable.
    script += "set arrow " + tag + " from " + f + ", graph 0 to " + f + ", graph 1 nohead dashtype 2 lc rgb 'red'\n" +
              "set label " + tag + " " + gnuplot_string("mode " + tag + ": " + fmt("%.4g", mode_hz[k]) + " Hz") +
              " at " + f + ", graph " + fmt("%.2f", 0.95 - 0.07 * static_cast<double>(k)) + " offset 0.5,0 front\n";
  }
  script +=
      "plot $spectrum every ::1 using 1:2 with lines title 'measured', \\\n"
      "     $spectrum every ::1 using 1:3 with lines lw 2 title 'identified model'\nunset multiplot\n";
  return plot(dir, name, script, out, "noenhanced size 900,800");
}

plant::SimStatus write_simulate_figure(const std::string& dir, const std::string& name, const std::string& csv,
                                       const SimulateFigure& f, FigureFiles& out) {
  const plant::SimStatus st = prepare(dir, out);
  if (st != plant::SimStatus::ok) return st;
  std::string script;
  if (!datablock_of(dir, csv, "h", script)) return plant::SimStatus::io_error;
  const std::string u = plant::to_string(f.unit);
  const std::string end = fmt("%.17g", f.end);
  const std::string target = fmt("%.17g", f.target);
  const std::string residual = fmt("%.17g", f.residual);
  const std::string band = fmt("%.17g", f.band);
  // The deviation from the final position: column 6 (output position) minus the target; after the
  // command ends it is the deflection (column 5, the command at rest on the target), written to
  // its own precision rather than as the difference of two numbers near the target.
  const std::string dev = "($6 - " + target + ")";
  script += "set multiplot layout 3,1 title " + gnuplot_string(f.title) + "\nset key top right opaque box\nset autoscale xfix\n" +
            "set xlabel 't (s)'\nset ylabel " + gnuplot_string("position (" + u + ")") + "\n" +
            "set title 'commanded and output position'\nset arrow 1 from " + end + ", graph 0 to " + end +
            ", graph 1 nohead dashtype 2\n"
            "plot $h every ::1 using 1:2 with lines lw 2 title 'commanded', \\\n"
            "     $h every ::1 using 1:6 with lines title 'output (the machine)'\n" +
            "set ylabel " + gnuplot_string("output - final (" + u + ")") + "\n" +
            "set title 'deviation from the final position, with the settling band (dashed line: the command ends)'\n"
            "plot $h every ::1 using 1:" + dev + " with lines title 'output - final', \\\n"
            "     " + band + " with lines dashtype 3 lc rgb 'gray40' title 'settling band', \\\n"
            "     -" + band + " with lines dashtype 3 lc rgb 'gray40' notitle\n" +
            "unset arrow 1\nset format y '%.2e'\n"
            "set title 'after the command ends, zoomed: the residual vibration'\n"
            "set xrange [" + end + ":*]\nset offsets 0, 0, graph 0.15, graph 0.15\n"
            "plot $h every ::1 using ($1 >= " + end + " ? $1 : NaN):5 with lines title 'output - final', \\\n"
            "     " + residual + " with lines dashtype 2 lc rgb 'red' title " +
            gnuplot_string("residual amplitude " + fmt("%.3g", f.residual) + " " + u) + ", \\\n"
            "     -" + residual + " with lines dashtype 2 lc rgb 'red' notitle\n"
            "unset multiplot\n";
  return plot(dir, name, script, out, "noenhanced size 1000,1100");
}

namespace {

// The move's table (write_move_rows) in the file at `path`.
bool write_move_csv(const core::Move<double>& move, double dt, plant::PositionUnit u, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  const bool rows = write_move_rows(f, move, dt, u);
  const bool written = std::fflush(f) == 0 && std::ferror(f) == 0;
  return std::fclose(f) == 0 && written && rows;
}

}  // namespace

void write_sample_row(std::FILE* f, std::span<const double> row) {
  for (std::size_t c = 0; c < row.size(); ++c) std::fprintf(f, c == 0 ? "%.9g" : ",%.12g", row[c]);
  std::fputc('\n', f);
}

std::vector<std::string> move_columns(plant::PositionUnit u, int axis) {
  const std::string tag = axis > 0 ? "_" + std::to_string(axis) : std::string{};
  std::vector<std::string> c;
  if (axis <= 0) c.push_back(plant::column("t", "s"));
  const char* quantities[] = {"position", "velocity", "acceleration", "jerk"};
  for (int d = 0; d < 4; ++d) c.push_back(plant::column(quantities[d] + tag, plant::motion_suffix(u, d)));
  return c;
}

bool write_move_rows(std::FILE* f, const core::Move<double>& move, double dt, plant::PositionUnit u) {
  std::fputs(csv_header(move_columns(u)).c_str(), f);
  const double n = std::ceil(move.duration() / dt);
  for (double i = 0.0; i <= n && std::ferror(f) == 0; i += 1.0) {
    const double t = std::min(i * dt, move.duration());
    const auto s = move.at(t);
    const std::array<double, 5> row{t, s.p, s.v, s.a, s.j};
    if (!std::all_of(row.begin(), row.end(), [](double x) { return std::isfinite(x); })) return false;
    write_sample_row(f, row);
  }
  return std::ferror(f) == 0;
}

plant::SimStatus write_move_figure(const core::Move<double>& move, const std::string& dir, const std::string& name,
                                   const MoveFigure& f, FigureFiles& out) {
  plant::SimStatus st = prepare(dir, out);
  if (st != plant::SimStatus::ok) return st;
  const std::string csv = name + ".csv";
  if (!write_move_csv(move, f.dt, f.unit, (fs::path{dir} / csv).string())) return plant::SimStatus::io_error;
  out.csv.push_back((fs::path{dir} / csv).string());
  std::string script;
  if (!datablock_of(dir, csv, "m", script)) return plant::SimStatus::io_error;
  const std::string u = plant::to_string(f.unit);
  const core::Peaks<double>& pk = move.peaks();
  // One panel: column `col` against t, with +-peak dashed when the peak is finite (a trapezoid's
  // jerk is a train of impulses: no line).
  auto panel = [&](const char* what, const std::string& unit, int col, double peak, const std::string& note = "") {
    std::string p = "set title " + gnuplot_string(what + note) + "\nset ylabel " + gnuplot_string(std::string{what} + " (" + unit + ")") +
                    "\nplot $m every ::1 using 1:" + std::to_string(col) + " with lines lw 2 title " + gnuplot_string(what);
    if (std::isfinite(peak) && peak > 0.0) {
      const std::string v = fmt("%.17g", peak);
      p += ", \\\n     " + v + " with lines dashtype 2 lc rgb 'red' title " +
           gnuplot_string("peak " + fmt("%.4g", peak) + " " + unit) + ", \\\n     -" + v +
           " with lines dashtype 2 lc rgb 'red' notitle";
    }
    return p + "\n";
  };
  script += "set multiplot layout 4,1 title " + gnuplot_string(f.title) +
            "\nset key top right opaque box\nset autoscale xfix\nset offsets 0, 0, graph 0.08, graph 0.08\n"
            "set xlabel 't (s)'\n" +
            "set title 'position'\nset ylabel " + gnuplot_string("position (" + u + ")") +
            "\nplot $m every ::1 using 1:2 with lines lw 2 title 'position', \\\n     " +
            fmt("%.17g", move.distance()) + " with lines dashtype 2 lc rgb 'gray40' title " +
            gnuplot_string("target " + fmt("%.6g", move.distance()) + " " + u) + "\n" +
            panel("velocity", u + "/s", 3, pk.v) + panel("acceleration", u + "/s^2", 4, pk.a) +
            panel("jerk", u + "/s^3", 5, pk.j,
                  pk.acceleration_step || !std::isfinite(pk.j) ? " (the acceleration's steps are impulses: not drawn)"
                                                                : "") +
            "unset multiplot\n";
  return plot(dir, name, script, out, "noenhanced size 1000,1200");
}

plant::SimStatus write_figures_000(const Result000& r, const std::string& dir, FigureFiles& out) {
  plant::SimStatus st = prepare(dir, out);
  if (st != plant::SimStatus::ok) return st;
  std::string table = "distance,time_ratio,time,profile,plan_status,cruise,peak_velocity,peak_acceleration,over_vmax,"
                      "prv_mode1,prv_tip,residual_tip,peak_deflection,width_lo,width_hi\n";
  for (const Run000& run : r.runs) {
    const std::string dtag = fmt("%.3f", run.distance);
    // Fig. 3 of the paper: (a) S-curve input, (b) its tip, (c) 3-4-5 input, (d) its tip.
    std::string panels[4];
    for (const Row000& row : run.rows) {
      table += fmt("%.4g", run.distance) + "," + fmt("%.4g", row.time_ratio) + "," + fmt("%.9g", row.time) + "," +
               core::to_string(row.profile) + "," + core::to_string(row.plan_status) + "," + fmt("%.9g", row.cruise) +
               "," + fmt("%.9g", row.peak_velocity) + "," + fmt("%.9g", row.peak_acceleration) + "," +
               (row.over_vmax ? "1" : "0") + "," + fmt("%.6e", row.prv_mode1) + "," + fmt("%.6e", row.prv_tip) + "," +
               fmt("%.6e", row.residual_tip) + "," + fmt("%.6e", row.peak_deflection) + "," +
               fmt("%.6g", row.width.lo) + "," + fmt("%.6g", row.width.hi) + "\n";
      if (row.history.empty()) continue;
      const std::string name =
          "000_D" + dtag + "_" + core::to_string(row.profile) + "_T" + fmt("%.2f", row.time_ratio) + ".csv";
      st = write_history_csv(row.history, (fs::path{dir} / name).string(), plant::PlantKind::beam, plant::PositionUnit::m);
      if (st != plant::SimStatus::ok) return st;
      out.csv.push_back((fs::path{dir} / name).string());
      const int k = row.profile == core::ProfileKind::scurve ? 0 : 2;
      const std::string title = "title " + gnuplot_string(fmt("T = %.2f Tn", row.time_ratio));
      for (int p = 0; p < 2; ++p) {
        std::string& s = panels[k + p];
        s += (s.empty() ? "plot " : ", ") + gnuplot_string(name) + " skip 1 using 1:" + (p == 0 ? "2" : "5") +
             " with lines lw 2 " + title;
      }
    }
    if (panels[0].empty()) continue;
    std::string script = "set multiplot layout 2,2 title " +
                         gnuplot_string("Seed 000, Table 1 beam (3 modes), D = " + dtag +
                                        " m: ramp-cycloid S-curve (top) against 3-4-5 polynomial (bottom)") +
                         "\nset key right bottom\n";
    const char* titles[4] = {"(a) S-curve: input displacement s(t) (m)", "(b) S-curve: tip deflection y(L,t) (m)",
                             "(c) 3-4-5: input displacement s(t) (m)", "(d) 3-4-5: tip deflection y(L,t) (m)"};
    for (int p = 0; p < 4; ++p) {
      script += "set title " + gnuplot_string(titles[p]) + "\nset xlabel 't (s)'\n" +
                (p % 2 == 1 ? "set key right top\n" : "set key right bottom\n") + panels[p] + "\n";
    }
    script += "unset multiplot\n";
    st = plot(dir, "000_D" + dtag, script, out);
    if (st != plant::SimStatus::ok) return st;
  }
  const std::string tpath = (fs::path{dir} / "000_table.csv").string();
  if (!write_text(tpath, table)) return plant::SimStatus::io_error;
  out.csv.push_back(tpath);
  if (r.sensitivity.empty()) return plant::SimStatus::ok;
  // Sensitivity curves: one column per profile or shaper, PRV against the frequency ratio.
  std::string csv = "ratio";
  for (const Sensitivity000& s : r.sensitivity) csv += "," + s.name;
  csv += "\n";
  for (std::size_t i = 0; i < r.sensitivity[0].curve.size(); ++i) {
    csv += fmt("%.6g", r.sensitivity[0].curve[i].ratio);
    for (const Sensitivity000& s : r.sensitivity) csv += "," + fmt("%.9e", s.curve[i].prv_percent);
    csv += "\n";
  }
  const std::string spath = (fs::path{dir} / "000_sensitivity.csv").string();
  if (!write_text(spath, csv)) return plant::SimStatus::io_error;
  out.csv.push_back(spath);
  std::string script = "set title 'Seed 000 beam, mode 1: PRV against true/designed frequency (profiles: D = 0.07 m, "
                       "T = 2 Tn; shapers: on a step)'\nset xlabel 'omega true / omega designed'\nset ylabel "
                       "'PRV (%)'\nset logscale y\nset yrange [1e-4:200]\nset key outside right\n"
                       "f(x) = 5\nplot f(x) with lines dt 2 lc rgb 'black' title '5 %'";
  // gnuplot cycles eight colours: give each curve its own, and draw the shapers dashed.
  static const char* colours[] = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02",
                                  "#a6761d", "#000000", "#e41a1c", "#377eb8", "#4daf4a", "#984ea3"};
  for (std::size_t k = 0; k < r.sensitivity.size(); ++k) {
    const bool shaper = r.sensitivity[k].name.rfind("shaper:", 0) == 0;
    script += ", '000_sensitivity.csv' skip 1 using 1:" + std::to_string(k + 2) + " with lines lw 2 lc rgb '" +
              colours[k % 12] + "'" + (shaper ? " dt 4" : "") + " title " + gnuplot_string(r.sensitivity[k].name);
  }
  return plot(dir, "000_sensitivity", script + "\n", out);
}

plant::SimStatus write_figures_001(const Result001& r, const std::string& dir, FigureFiles& out) {
  plant::SimStatus st = prepare(dir, out);
  if (st != plant::SimStatus::ok) return st;
  // Figs. 2 and 3: command y(t) and mass x(t), arbitrary against computed Y, for each tau.
  std::string script = "set multiplot layout 2,2 title 'Seed 001: m = 1 kg, k = 800 N/m, c = 9 N s/m, L = 1'\n"
                       "set xlabel 't (s)'\nset ylabel 'displacement (m)'\nset key right bottom\n";
  for (const Case001& c : r.cases) {
    for (int which = 0; which < 2; ++which) {
      const auto& h = which == 0 ? c.history_arbitrary : c.history_computed;
      if (h.empty()) continue;
      const std::string name =
          std::string{"001_tau"} + fmt("%.3f", c.tau) + (which == 0 ? "_arbitrary" : "_computed") + ".csv";
      st = write_history_csv(h, (fs::path{dir} / name).string(), plant::PlantKind::sdof, plant::PositionUnit::m);
      if (st != plant::SimStatus::ok) return st;
      out.csv.push_back((fs::path{dir} / name).string());
      script += "set title " +
                gnuplot_string(std::string{which == 0 ? "(a) arbitrary Y = (0.5, 0.25, 0.25)" : "(b) computed Y"} +
                               fmt(", tau = %.3f s", c.tau)) +
                "\nplot " + gnuplot_string(name) + " skip 1 using 1:2 with lines lw 2 title 'command y(t)', " +
                gnuplot_string(name) + " skip 1 using 1:6 with lines lw 2 title 'mass x(t)'\n";
    }
  }
  script += "unset multiplot\n";
  if (!r.cases.empty() && !r.cases[0].history_arbitrary.empty()) {
    st = plot(dir, "001_responses", script, out);
    if (st != plant::SimStatus::ok) return st;
  }
  // Figs. 4-7: residual over eps(w_n) and eps(zeta), one surface per method; and the eps(zeta) = 0
  // slices of all methods on one plot.
  for (const Grid001& g : r.grids) {
    const std::string name = "001_grid_" + g.method + ".csv";
    std::string csv = "eps_omega,eps_zeta,residual\n";
    const std::size_t n = g.eps.size();
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        csv += fmt("%.6g", g.eps[i]) + "," + fmt("%.6g", g.eps[j]) + "," + fmt("%.9e", g.residual[i * n + j]) + "\n";
      }
      csv += "\n";  // gnuplot's grid format: a blank line ends each row
    }
    if (!write_text((fs::path{dir} / name).string(), csv)) return plant::SimStatus::io_error;
    out.csv.push_back((fs::path{dir} / name).string());
    st = plot(dir, "001_robust_" + g.method,
              "set title " + gnuplot_string("Seed 001, tau = 0.167 s, " + g.method + fmt(": residual / L at t = %.3f s", r.residual_at)) +
                  "\nset xlabel 'eps(w_n)'\nset ylabel 'eps(zeta)'\nset zlabel "
                  "'residual / L' rotate by 90\nset view 60,30\nset xyplane at 0\nset hidden3d\nsplot " +
                  gnuplot_string(name) + " skip 1 using 1:2:3 with lines title ''\n",
              out);
    if (st != plant::SimStatus::ok) return st;
  }
  if (!r.grids.empty()) {
    const std::size_t n = r.grids[0].eps.size();
    std::string csv = "eps_omega";
    for (const Grid001& g : r.grids) csv += "," + g.method;
    csv += "\n";
    for (std::size_t i = 0; i < n; ++i) {
      csv += fmt("%.6g", r.grids[0].eps[i]);
      for (const Grid001& g : r.grids) csv += "," + fmt("%.9e", g.residual[i * n + n / 2]);
      csv += "\n";
    }
    const std::string name = "001_slices.csv";
    if (!write_text((fs::path{dir} / name).string(), csv)) return plant::SimStatus::io_error;
    out.csv.push_back((fs::path{dir} / name).string());
    std::string slices = "set title 'Seed 001, tau = 0.167 s: residual against eps(w_n) at eps(zeta) = 0'\n"
                         "set xlabel 'eps(w_n) = w_n*/w_n - 1'\nset ylabel 'residual amplitude / L, referred to t = tau'\n"
                         "set key top center\nplot ";
    for (std::size_t gi = 0; gi < r.grids.size(); ++gi) {
      slices += std::string{gi == 0 ? "" : ", "} + gnuplot_string(name) + " skip 1 using 1:" +
                std::to_string(gi + 2) + " with linespoints lw 2 title " + gnuplot_string(r.grids[gi].method);
    }
    st = plot(dir, "001_robust_slices", slices + "\n", out);
    if (st != plant::SimStatus::ok) return st;
  }
  return plant::SimStatus::ok;
}

plant::SimStatus write_figures_004(const Result004& r, const std::string& dir, FigureFiles& out) {
  plant::SimStatus st = prepare(dir, out);
  if (st != plant::SimStatus::ok) return st;
  if (r.history_initial.empty()) return plant::SimStatus::ok;
  const char* names[2] = {"004_history_345.csv", "004_history_optimised.csv"};
  constexpr plant::PlantKind belt = plant::PlantKind::belt;
  constexpr plant::PositionUnit rad = plant::PositionUnit::rad;
  st = write_history_csv(r.history_initial, (fs::path{dir} / names[0]).string(), belt, rad);
  if (st == plant::SimStatus::ok) st = write_history_csv(r.history_optimised, (fs::path{dir} / names[1]).string(), belt, rad);
  if (st != plant::SimStatus::ok) return st;
  for (const char* n : names) out.csv.push_back((fs::path{dir} / n).string());
  // Fig. 3: platform velocity and acceleration (command lambda phi_m dashed), kinetic and potential
  // energy; non-optimised left, optimised right.
  const double lambda = r.target.lambda;
  std::string script = "set multiplot layout 4,2 title 'Seed 004, Table III platform: gamma = (3, 4, 5) (left) "
                       "against optimised (right)'\nset xlabel 't (s)'\nset key right top\n";
  const char* rows[4][2] = {{"angular velocity (rad/s)", "7"},
                            {"angular acceleration (rad/s^2)", "8"},
                            {"kinetic energy (J)", "9"},
                            {"elastic potential energy (J)", "10"}};
  const char* cmd_cols[2] = {"3", "4"};
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 2; ++col) {
      const std::string f = names[col];
      script += "set title " + gnuplot_string(std::string{rows[row][0]} + (col == 0 ? ", gamma = (3,4,5)" : ", optimised")) +
                "\nplot " + gnuplot_string(f) + " skip 1 using 1:" + rows[row][1] + " with lines lw 2 title 'platform'";
      if (row < 2) {
        script += ", " + gnuplot_string(f) + " skip 1 using 1:($" + cmd_cols[row] + "*" + fmt("%.17g", lambda) +
                  ") with lines dt 2 lw 2 title 'command'";
      }
      script += "\n";
    }
  }
  script += "unset multiplot\n";
  st = plot(dir, "004_fig3", script, out);
  if (st != plant::SimStatus::ok) return st;
  std::string csv = "count,h_index,slope,width,gammas\n";
  for (const Exponents004& e : r.exponents) {
    csv += std::to_string(e.count) + "," + fmt("%.6e", e.h_index) + "," + fmt("%.6e", e.slope) + "," +
           fmt("%.6g", e.width.width) + ",";
    for (std::size_t i = 0; i < e.gammas.size(); ++i) csv += (i ? " " : "") + fmt("%.6f", e.gammas[i]);
    csv += "\n";
  }
  const std::string epath = (fs::path{dir} / "004_exponents.csv").string();
  if (!write_text(epath, csv)) return plant::SimStatus::io_error;
  out.csv.push_back(epath);
  return plant::SimStatus::ok;
}

}  // namespace settle::papers
