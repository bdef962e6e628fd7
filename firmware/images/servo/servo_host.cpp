// SPDX-License-Identifier: Apache-2.0
// The servo-loop image's program built for the host (settle_servo_image_host): the same source as
// the Cortex-M images (servo_session.hpp), writing the candump log with stdio instead of
// semihosting, so that the cross test can compare the two logs frame for frame.
//   settle_servo_image_host [--fixed] <log>  writes the log, prints a one-line summary; --fixed runs
//                                            the loop on FixedEvaluation (the servo_fixed images)
//   settle_servo_image_host --check-plan     checks that core::plan still gives the pinned move
//   settle_servo_image_host --golden         prints core::fixed::golden_checksum() as the golden
//                                            image writes it (tests/cross/golden-check compares)
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <variant>

#include "servo_session.hpp"
#include "settle/core/fixed/golden.hpp"
#include "settle/core/planner.hpp"

namespace {

namespace si = settle::firmware::servo_image;

class FileSink {
 public:
  explicit FileSink(std::FILE* f) noexcept : f_{f} {}
  void line(std::string_view text) noexcept {
    if (std::fwrite(text.data(), 1, text.size(), f_) != text.size()) ok_ = false;
  }
  [[nodiscard]] bool ok() const noexcept { return ok_; }

 private:
  std::FILE* f_;
  bool ok_{true};
};

struct NoTimer {
  void begin() noexcept {}
  void end(bool) noexcept {}
};

int check_plan() {
  settle::core::MoveRequest req{};
  req.profile = settle::core::ProfileKind::scurve;
  req.distance = 0.05;
  req.time = 0.8 * 2 * 3.141592653589793 / 22.04871;
  req.set_mode(22.04871);
  settle::core::Move<double> m{};
  if (settle::core::plan(req, m) != settle::core::Status::ok) return 1;
  const auto* rc = std::get_if<settle::core::RampCycloid<double>>(&m.profile().variant());
  if (rc == nullptr) return 1;
  const auto& p = rc->params();
  const auto& k = si::kParams;
  const bool same = p.distance == k.distance && p.tau == k.tau && p.cruise == k.cruise &&
                    p.amplitude == k.amplitude && p.c2 == k.c2 && p.c3 == k.c3 && m.shaper().count == 1 &&
                    m.profile().kind() == settle::core::ProfileKind::scurve &&
                    m.peaks().v == si::kPeaks.v && m.peaks().a == si::kPeaks.a && m.peaks().j == si::kPeaks.j;
  std::printf("pinned move %s core::plan\n", same ? "matches" : "DIFFERS FROM");
  return same ? 0 : 1;
}

// The golden image's line, character for character (firmware/images/golden/golden.cpp).
int golden() {
  const settle::core::fixed::GoldenResult g = settle::core::fixed::golden_checksum();
  std::printf("build %016" PRIX64 " ticks %016" PRIX64 " plan %016" PRIX64 " positions %016" PRIX64
              " moves %u samples %u position_samples %u status %s\n",
              g.build, g.ticks, g.plan, g.positions, g.moves, g.samples, g.position_samples,
              settle::core::to_string(g.status));
  return g.status == settle::core::Status::ok ? 0 : 1;
}

template <typename Evaluation>
si::RunResult run_program(FileSink& sink) {
  static NoTimer timer{};
  // Static: the program holds the loop and two loopback ports, as the image does.
  static si::Program<FileSink, NoTimer, Evaluation> program{sink, timer};
  return program.run(si::pinned_move());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "--check-plan") == 0) return check_plan();
  if (argc == 2 && std::strcmp(argv[1], "--golden") == 0) return golden();
  const bool fixed = argc == 3 && std::strcmp(argv[1], "--fixed") == 0;
  if (argc != 2 && !fixed) {
    std::fprintf(stderr, "usage: settle_servo_image_host [--fixed] <candump log> | --check-plan\n");
    return 2;
  }
  const char* path = argv[argc - 1];
  std::FILE* f = std::fopen(path, "w");
  if (f == nullptr) {
    std::fprintf(stderr, "settle_servo_image_host: cannot write %s\n", path);
    return 1;
  }
  FileSink sink{f};
  const si::RunResult r = fixed ? run_program<si::FixedImageEvaluation>(sink)
                                : run_program<settle::runtime::FloatEvaluation<float>>(sink);
  const bool written = sink.ok() && std::fclose(f) == 0;
  std::printf("outcome %s ticks %llu ready %llu stream_end %llu frames %llu final_target %d final_position %d "
              "rx_overflows %llu\n",
              settle::runtime::to_string(r.session.outcome), static_cast<unsigned long long>(r.session.ticks),
              static_cast<unsigned long long>(r.session.ready_tick),
              static_cast<unsigned long long>(r.session.stream_end_tick),
              static_cast<unsigned long long>(r.frames_logged), r.final_target, r.final_position,
              static_cast<unsigned long long>(r.rx_overflows));
  const bool ok = written && r.session.outcome == settle::runtime::SessionOutcome::completed &&
                  r.format_errors == 0 && r.final_position == r.final_target && r.rx_overflows == 0;
  return ok ? 0 : 1;
}
