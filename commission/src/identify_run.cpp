// SPDX-License-Identifier: Apache-2.0
#include "settle/commission/identify_run.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "settle/commission/identify_excitation.hpp"

namespace settle::commission {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Rest samples kept before the excitation's first setpoint (the start-up before them says nothing).
constexpr std::size_t kRestBefore = 500;

void fail(IdentifyRunReport& r, std::string code, std::string why) {
  r.failure_code = std::move(code);
  r.failure = std::move(why);
}

// The measured and fitted deflection (load minus the fitted rigid motion and offset), output units.
void deflections(const IdentifyRunReport& r, const testbed::StreamSpec& s, std::vector<double>& measured,
                 std::vector<double>& fitted) {
  const IdentifyResult& f = r.result;
  measured.resize(r.load.size());
  fitted.resize(r.load.size());
  for (std::size_t k = 0; k < r.load.size(); ++k) {
    const double rigid = f.rigid_gain * r.motor[k] / s.drive.scale.counts_per_unit + f.offset;
    measured[k] = r.load[k] / s.drive.load_counts_per_unit - rigid;
    fitted[k] = f.fitted_load[k] - rigid;
  }
}

}  // namespace

IdentifyRunReport run_identify(const IdentifyRunSpec& spec, testbed::ClockedBus& bus) {
  IdentifyRunReport r{};
  r.period_s = spec.stream.drive.scale.period_s();
  if (spec.stream.eds &&
      testbed::streaming_feedback(*spec.stream.eds, spec.stream.load_feedback).load_position_index == 0) {
    fail(r, "no_load_feedback",
         "the drive's description marks no load position to map (name one with --load-feedback INDEX:SUB): no "
         "load-side feedback, nothing to identify from");
    return r;
  }
  r.stream = testbed::run_stream(spec.stream, bus);
  const testbed::StreamReport& s = r.stream;
  if (!s.failure.empty()) {
    fail(r, "run_failed", s.failure);
    return r;
  }
  const testbed::AxisReport& a = s.axes.front();  // the excitation's only axis
  if (!s.start_up_us) {
    fail(r, "drive_not_enabled",
         "the drive never reached operation enabled" + (a.drive_failure.empty() ? std::string{} : ": " + a.drive_failure) +
             " (state " + a.drive_state + ")");
    return r;
  }
  if (s.session.outcome != runtime::SessionOutcome::completed) {
    fail(r, "excitation_not_completed",
         std::string{"the excitation did not complete: "} + runtime::to_string(s.session.outcome) +
             (s.session.outcome == runtime::SessionOutcome::rejected
                  ? " (the loop refused the move before streaming it: a step per period beyond what it streams)"
                  : ""));
    return r;
  }
  if (!a.aligned()) {
    fail(r, "feedback_incomplete",
         "the drive's feedback does not show every setpoint applied once and in order (frames lost or late): the "
         "record cannot be trusted");
    return r;
  }
  const std::size_t from = *a.alignment > kRestBefore ? *a.alignment - kRestBefore : 0;
  const std::size_t to = *a.alignment + a.replay.feedback.size();
  for (std::size_t i = from; i < to; ++i) {
    r.motor.push_back(a.feedback[i].position_actual);
    r.load.push_back(a.feedback[i].load_position);
  }
  if (std::all_of(r.load.begin(), r.load.end(), [&](std::int32_t v) { return v == r.load.front(); })) {
    fail(r, "no_load_feedback",
         "the load-side position never changed while the motor moved: no load-side feedback is mapped (TPDO2)");
    return r;
  }
  IdentifyInput in{};
  in.period_s = r.period_s;
  in.counts_per_unit = spec.stream.drive.scale.counts_per_unit;
  in.load_counts_per_unit = spec.stream.drive.load_counts_per_unit;
  in.motor = r.motor;
  in.load = r.load;
  r.result = identify_modes(in, spec.options);
  if (r.result.status != IdentifyStatus::ok) fail(r, to_string(r.result.status), describe(r.result.status));
  return r;
}

void write_identify_text(const IdentifyRunSpec& spec, const IdentifyRunReport& r, std::FILE* out) {
  const IdentifyResult& f = r.result;
  const core::Move<double>& mv = spec.stream.axes.front().move;
  std::fprintf(out, "excitation   %s, %g after %zu round trips, over %.4g s, then %.4g s held; %zu samples at %g s (%s)\n",
               core::to_string(mv.profile().kind()), mv.distance(), train_round_trips(mv), mv.duration(),
               spec.stream.settle_time_s, r.motor.size(), r.period_s, r.stream.bus.c_str());
  const int pct = static_cast<int>(std::lround(spec.options.confidence * 100.0));
  for (std::size_t i = 0; i < f.modes.size(); ++i) {
    const UncertainMode& m = f.modes[i];
    std::fprintf(out,
                 "mode %zu       omega %.6g rad/s (%.5g Hz) [%.6g, %.6g]  zeta %.4g [%.4g, %.4g]  gain %.4g +- %.2g  "
                 "(%d %% intervals)\n",
                 i + 1, m.omega, m.omega / (2.0 * kPi), m.omega_lo, m.omega_hi, m.zeta, m.zeta_lo, m.zeta_hi, m.gain,
                 m.gain_sd, pct);
  }
  std::fprintf(out, "fit          order %zu, rms residual %.3g (noise %.3g), peak deflection %.3g, rigid gain %.6g\n",
               f.order, f.rms_residual, f.noise_rms, f.peak_deflection, f.rigid_gain);
}

namespace {

// One header line of three columns: `first`, then measured_<what> and fitted_<what> in `u`.
bool write_three_columns(std::FILE* out, const std::string& first, const char* what, plant::PositionUnit u) {
  const std::string unit = plant::motion_suffix(u, 0);
  const std::string line = first + "," + plant::column(std::string{"measured_"} + what, unit) + "," +
                           plant::column(std::string{"fitted_"} + what, unit) + "\n";
  return std::fputs(line.c_str(), out) >= 0;
}

}  // namespace

bool write_identify_time_csv(const IdentifyRunSpec& spec, const IdentifyRunReport& r, plant::PositionUnit u,
                             std::FILE* out) {
  if (!r.ok()) return false;
  std::vector<double> measured;
  std::vector<double> fitted;
  deflections(r, spec.stream, measured, fitted);
  bool ok = write_three_columns(out, plant::column("t", "s"), "deflection", u);
  const double t0 = static_cast<double>(r.result.motion_start) * r.period_s;
  for (std::size_t k = 0; k < measured.size() && ok; ++k) {
    ok = std::fprintf(out, "%.6f,%.9g,%.9g\n", static_cast<double>(k) * r.period_s - t0, measured[k], fitted[k]) > 0;
  }
  return ok;
}

bool write_identify_spectrum_csv(const IdentifyRunSpec& spec, const IdentifyRunReport& r, plant::PositionUnit u,
                                 std::FILE* out) {
  if (!r.ok()) return false;
  std::vector<double> measured;
  std::vector<double> fitted;
  deflections(r, spec.stream, measured, fitted);
  // The free response (the motor at rest), Hann-windowed, at 400 log-spaced frequencies from
  // 1 / (its length) to Nyquist: where each mode's peak sits.
  const std::size_t k0 = r.result.motion_end;
  const std::size_t n = measured.size() - k0;
  const double h = r.period_s;
  const double f_lo = 1.0 / (static_cast<double>(n) * h);
  const double f_hi = 0.5 / h;
  bool ok = write_three_columns(out, plant::column("frequency", "hz"), "amplitude", u);
  constexpr int kPoints = 400;
  for (int i = 0; i < kPoints && ok; ++i) {
    const double f = f_lo * std::pow(f_hi / f_lo, static_cast<double>(i) / (kPoints - 1));
    std::complex<double> m{};
    std::complex<double> p{};
    const std::complex<double> step = std::polar(1.0, -2.0 * kPi * f * h);
    std::complex<double> rot{1.0, 0.0};
    for (std::size_t k = 0; k < n; ++k) {
      const double w = 0.5 - 0.5 * std::cos(2.0 * kPi * static_cast<double>(k) / static_cast<double>(n));
      m += w * measured[k0 + k] * rot;
      p += w * fitted[k0 + k] * rot;
      rot *= step;
      if ((k & 255U) == 255U) rot /= std::abs(rot);  // keep the rotation on the unit circle
    }
    ok = std::fprintf(out, "%.6g,%.6g,%.6g\n", f, std::abs(m) * 2.0 / static_cast<double>(n),
                      std::abs(p) * 2.0 / static_cast<double>(n)) > 0;
  }
  return ok;
}

}  // namespace settle::commission
