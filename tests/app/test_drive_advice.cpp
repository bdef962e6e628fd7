// SPDX-License-Identifier: Apache-2.0
// A drive that reports why it stopped: the in-process drive (--bus loopback's) loses the master's
// SYNCs mid-move, quick-stops with EMCY 0x8100 (SYNC loss), and the failure settle stream and settle
// identify print names that EMCY, what it means and which option to change (app/drive_advice.hpp).
#include <gtest/gtest.h>

#include <span>
#include <string>

#include "drive_advice.hpp"
#include "settle/core/planner.hpp"
#include "settle/hal/can_bus.hpp"
#include "settle/hal/canopen/cob_id.hpp"
#include "settle/plant/beam.hpp"
#include "settle/testbed/stream.hpp"
#include "settle/testbed/clocked_bus.hpp"
#include "settle/testbed/stream_report.hpp"

namespace settle::app {
namespace {

// The master's link with SYNC frames swallowed once `drop` is set: the drive's SYNC watchdog
// fires, as it does when the master's process is not scheduled on a loaded host.
class SyncDroppingLink final : public hal::CanBus {
 public:
  explicit SyncDroppingLink(hal::CanBus& inner) : inner_{inner} {}
  bool drop{false};

 protected:
  hal::SendStatus do_send(const hal::CanFrame& f) noexcept override {
    if (drop && f.id == hal::canopen::cob::sync) return hal::SendStatus::sent;
    return inner_.send(f);
  }
  hal::ReceiveStatus do_receive(hal::CanFrame& f, std::uint32_t timeout_us) noexcept override {
    return inner_.receive(f, timeout_us);
  }
  hal::BusStatus do_set_filters(std::span<const hal::CanFilter> filters) noexcept override {
    return inner_.set_filters(filters);
  }

 private:
  hal::CanBus& inner_;
};

// The loopback bus whose master loses its SYNCs from tick `from` on.
class SyncLossBus final : public testbed::ClockedBus {
 public:
  explicit SyncLossBus(std::uint64_t from) : from_{from} {}
  [[nodiscard]] std::string name() const override { return inner_.name(); }
  [[nodiscard]] bool realtime() const override { return false; }
  [[nodiscard]] std::string open(const testbed::StreamSpec& spec) override { return inner_.open(spec); }
  [[nodiscard]] hal::CanBus& link() override { return link_; }
  void begin() override { inner_.begin(); }
  std::uint64_t wait() override { return inner_.wait(); }
  [[nodiscard]] std::uint64_t now_us() const override { return inner_.now_us(); }
  void between_ticks() override {
    link_.drop = ++ticks_ >= from_;
    inner_.between_ticks();
  }
  [[nodiscard]] std::string finish(const FrameTaker& take) override { return inner_.finish(take); }
  [[nodiscard]] hal::BusCounters counters() const override { return inner_.counters(); }
  [[nodiscard]] testbed::StreamTiming timing() const override { return inner_.timing(); }

 private:
  testbed::LoopbackClockedBus inner_;
  SyncDroppingLink link_{inner_.link()};
  std::uint64_t from_;
  std::uint64_t ticks_{0};
};

testbed::StreamSpec spec() {
  testbed::StreamSpec s{};
  core::MoveRequest rq;
  rq.profile = core::ProfileKind::poly345;
  rq.distance = 0.01;
  rq.time = 0.5;
  EXPECT_EQ(core::plan(rq, s.axes[0].move), core::Status::ok);
  EXPECT_EQ(plant::ModalPlant::make_beam(plant::BeamOptions{}, s.plant), plant::SimStatus::ok);
  s.settle_time_s = 0.2;
  return s;
}

TEST(DriveAdvice, ADriveThatLosesSyncIsNamedByItsEmcyAndTheOptionToChange) {
  SyncLossBus bus{400};  // start-up is over well before; the move is under way
  const testbed::StreamReport r = testbed::run_stream(spec(), bus);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_FALSE(r.measured());
  ASSERT_TRUE(r.axes[0].drive_emcy.has_value()) << runtime::to_string(r.session.outcome);
  EXPECT_EQ(r.axes[0].drive_emcy->error_code, 0x8100);
  const std::string advice = drive_advice(r);
  EXPECT_NE(advice.find("EMCY 0x8100"), std::string::npos) << advice;
  EXPECT_NE(advice.find("SYNC lost"), std::string::npos) << advice;
  EXPECT_NE(advice.find("--timing sim"), std::string::npos) << advice;
  EXPECT_NE(advice.find("--sync-loss-periods"), std::string::npos) << advice;
  EXPECT_NE(testbed::stream_json(r).find("\"drive_emcy\":{\"code\":\"0x8100\""), std::string::npos);
}

TEST(DriveAdvice, ARunThatWentWellHasNothingToSay) {
  SyncLossBus bus{1'000'000};
  const testbed::StreamReport r = testbed::run_stream(spec(), bus);
  ASSERT_TRUE(r.measured()) << runtime::to_string(r.session.outcome);
  EXPECT_FALSE(r.axes[0].drive_emcy.has_value());
  EXPECT_EQ(drive_advice(r), "");
}

}  // namespace
}  // namespace settle::app
