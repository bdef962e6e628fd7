// SPDX-License-Identifier: Apache-2.0
// run_identify (settle/commission/identify_run.hpp) on the in-process bus: a known plant identified from
// the drive's frames, and a bus with no drive on it: the drive never enables, which is said as
// such, with no modes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "settle/core/planner.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/commission/identify_run.hpp"
#include "settle/testbed/clocked_bus.hpp"

namespace settle::commission {
namespace {

// The in-process bus with nobody else on it: the loop's NMT, SDOs and SYNCs go unanswered.
class EmptyBus final : public testbed::ClockedBus {
 public:
  [[nodiscard]] std::string name() const override { return "empty loopback"; }
  [[nodiscard]] bool realtime() const override { return false; }
  [[nodiscard]] std::string open(const testbed::StreamSpec& spec) override {
    clock_ = runtime::VirtualClock{spec.drive.scale.period_us};
    return {};
  }
  [[nodiscard]] hal::CanBus& link() override { return master_; }
  void begin() override {}
  std::uint64_t wait() override { return clock_.wait(); }
  [[nodiscard]] std::uint64_t now_us() const override { return clock_.now_us(); }
  void between_ticks() override { hub_.set_time_us(clock_.now_us()); }
  [[nodiscard]] std::string finish(const FrameTaker&) override { return {}; }
  [[nodiscard]] hal::BusCounters counters() const override { return master_.counters(); }
  [[nodiscard]] testbed::StreamTiming timing() const override { return {}; }

 private:
  hal::LoopbackHub hub_;
  hal::LoopbackBus<256> master_{hub_};
  runtime::VirtualClock clock_{1000};
};

IdentifyRunSpec spec_for(const std::vector<plant::Mode>& modes) {
  IdentifyRunSpec spec{};
  EXPECT_EQ(plant::ModalPlant::make_modes(modes, 1.0, plant::PlantKind::modes, spec.stream.plant), plant::SimStatus::ok);
  core::MoveRequest req{};
  EXPECT_TRUE(core::parse_profile_kind("jerk-limited", req.profile));
  req.distance = 0.01;
  req.limits.vmax = 0.1;
  req.limits.amax = 5.0;
  req.limits.jmax = 5000.0;
  EXPECT_EQ(core::plan(req, spec.stream.axes[0].move), core::Status::ok);
  spec.stream.settle_time_s = 3.0;
  return spec;
}

TEST(IdentifyRun, KnownPlantThroughTheLoopbackBus) {
  const IdentifyRunSpec spec = spec_for({{.omega = 30.0, .zeta = 0.03, .gain = 1.0}});
  testbed::LoopbackClockedBus bus{};
  const IdentifyRunReport r = run_identify(spec, bus);
  ASSERT_TRUE(r.ok()) << r.failure;
  ASSERT_EQ(r.result.modes.size(), 1U);
  EXPECT_NEAR(r.result.modes[0].omega, 30.0, 0.005 * 30.0);
  EXPECT_NEAR(r.result.modes[0].zeta, 0.03, 0.01);
  // The record is the drive's frames: as many samples as the move and the hold, plus the rest.
  EXPECT_GE(r.motor.size(), static_cast<std::size_t>((spec.stream.axes[0].move.duration() + 3.0) * 1000.0));
  EXPECT_EQ(r.motor.size(), r.load.size());
}

TEST(IdentifyRun, DriveThatNeverEnablesIsSaidSo) {
  const IdentifyRunSpec spec = spec_for({{.omega = 30.0, .zeta = 0.03, .gain = 1.0}});
  EmptyBus bus{};
  const IdentifyRunReport r = run_identify(spec, bus);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.failure_code, "drive_not_enabled");
  EXPECT_NE(r.failure.find("the drive never reached operation enabled"), std::string::npos) << r.failure;
  EXPECT_TRUE(r.result.modes.empty());
}

}  // namespace
}  // namespace settle::commission
