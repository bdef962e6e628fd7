// SPDX-License-Identifier: Apache-2.0
// run_stream on the in-process loopback bus, held to what is known without it: the frames a
// sniffer saw on the bus (one SYNC per tick, one RPDO per streamed tick carrying every setpoint
// once, in order), the setpoint count from the move's duration, the settling window from the
// settle time, the refusals a loop makes at submit; and no heap use while the loop streams. With
// several axes (issue 17) each node's RPDOs carry its own setpoints, and all begin after the same SYNC.
// Allocations are counted by heap_counter.hpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <new>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "heap_counter.hpp"
#include "planned_moves.hpp"
#include "scratch.hpp"
#include "settle/core/multi_axis.hpp"
#include "settle/core/online.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/testbed/stream.hpp"
#include "settle/testbed/clocked_bus.hpp"
#include "settle/testbed/stream_report.hpp"

namespace settle::testbed {
namespace {

using testing::poly345;
using testing::scurve;

// What a text writer printed, through a temporary file.
template <typename Write>
std::string captured_text(Write write) {
  std::FILE* f = std::tmpfile();
  if (f == nullptr) return {};
  write(f);
  std::rewind(f);
  std::string text;
  for (int c = std::fgetc(f); c != EOF; c = std::fgetc(f)) text.push_back(static_cast<char>(c));
  std::fclose(f);
  return text;
}

std::string temp_path(const std::string& name) { return settle::test::scratch_path(name); }

plant::ModalPlant beam() {
  plant::ModalPlant p;
  EXPECT_EQ(plant::ModalPlant::make_beam(plant::BeamOptions{}, p), plant::SimStatus::ok);
  return p;
}

StreamSpec spec_for(const core::Move<double>& move, double settle_time_s = 0.2) {
  StreamSpec s{};
  s.axes[0].move = move;
  s.plant = beam();
  s.settle_time_s = settle_time_s;
  return s;
}

// One frame of a candump -l line: "(sec.usec) iface ID#DATA".
struct Logged {
  std::uint32_t id{0};
  std::vector<std::uint8_t> data;
};

std::vector<Logged> read_candump(const std::string& path) {
  std::vector<Logged> out;
  std::ifstream f{path};
  for (std::string line; std::getline(f, line);) {
    const std::size_t hash = line.find('#');
    const std::size_t space = line.rfind(' ', hash);
    EXPECT_NE(hash, std::string::npos) << line;
    if (hash == std::string::npos || space == std::string::npos) continue;
    Logged l{};
    l.id = static_cast<std::uint32_t>(std::stoul(line.substr(space + 1, hash - space - 1), nullptr, 16));
    for (std::size_t i = hash + 1; i + 1 < line.size(); i += 2) {
      l.data.push_back(static_cast<std::uint8_t>(std::stoul(line.substr(i, 2), nullptr, 16)));
    }
    out.push_back(l);
  }
  return out;
}

// RPDO1 (the default mapping): controlword 0x6040 in bytes 0-1, target position 0x607A in 2-5.
std::int32_t rpdo_target(const std::vector<std::uint8_t>& d) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(d.at(2)) | (static_cast<std::uint32_t>(d.at(3)) << 8U) |
                                   (static_cast<std::uint32_t>(d.at(4)) << 16U) |
                                   (static_cast<std::uint32_t>(d.at(5)) << 24U));
}

TEST(RunStream, LoopbackRunMatchesTheFramesOnTheBus) {
  const std::string dump = temp_path("run.log");
  const StreamSpec spec = spec_for(poly345(0.01, 0.5), 0.2);
  LoopbackClockedBus bus{dump};
  const StreamReport r = run_stream(spec, bus);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::completed);
  EXPECT_TRUE(r.axes[0].aligned());
  EXPECT_TRUE(r.measured());
  EXPECT_EQ(r.bus, "loopback (in-process, virtual time)");
  EXPECT_FALSE(r.realtime);

  // From the move and the spec alone: 0.5 s at 1 ms is ticks 0..500, a 0.2 s window 200 samples.
  EXPECT_EQ(r.axes[0].setpoints.size(), 501U);
  EXPECT_EQ(r.axes[0].setpoints.front(), 0);
  EXPECT_EQ(r.axes[0].setpoints.back(), 10000);  // 0.01 m at 1e6 counts/m
  EXPECT_EQ(r.axes[0].window_samples, 200U);
  // Ticks 0 .. session.ticks, then the drive's release (runtime::release_drives): two ticks.
  EXPECT_TRUE(r.session.released);
  EXPECT_EQ(r.session.release_ticks, 2U);
  EXPECT_EQ(r.axes[0].drive_state, "released");
  EXPECT_EQ(r.axes[0].log.size(), r.session.ticks + r.session.release_ticks + 1);
  // Start-up on the virtual clock: the first tick is one period after the start, the ready one
  // ready_tick periods later; the move is submitted then, so the drive is enabled before it.
  ASSERT_TRUE(r.start_up_us.has_value());
  EXPECT_EQ(*r.start_up_us, (r.session.ready_tick + 1) * 1000U);
  EXPECT_GT(r.session.ready_tick, 2U);  // NMT, SDO configuration and three enabling controlwords take ticks
  EXPECT_LT(r.session.ready_tick, 100U);

  const std::vector<Logged> frames = read_candump(dump);
  std::uint64_t syncs = 0, from_master = 0;
  std::vector<std::int32_t> targets;
  for (const Logged& f : frames) {
    // The master sends NMT (0x000), SYNC (0x080), RPDO1 (0x201) and SDO requests (0x601).
    if (f.id == 0x000 || f.id == 0x080 || f.id == 0x201 || f.id == 0x601) ++from_master;
    if (f.id == 0x080) ++syncs;
    if (f.id == 0x201) targets.push_back(rpdo_target(f.data));
  }
  EXPECT_EQ(syncs, r.session.ticks + r.session.release_ticks + 1);  // one SYNC per tick
  EXPECT_EQ(from_master, r.counters.sent);
  EXPECT_EQ(targets.size(), r.axes[0].axis.rpdo_sent);
  // Every setpoint once and in order: the RPDOs hold the origin, carry the move, then hold its end.
  const auto move = std::search(targets.begin(), targets.end(), r.axes[0].setpoints.begin(), r.axes[0].setpoints.end());
  ASSERT_NE(move, targets.end()) << "the setpoints are not in the RPDOs in order";
  EXPECT_TRUE(std::all_of(targets.begin(), move, [](std::int32_t t) { return t == 0; }));
  EXPECT_TRUE(std::all_of(move + 501, targets.end(), [](std::int32_t t) { return t == 10000; }));
  EXPECT_GT(targets.end() - (move + 501), 200);  // the settling window
  // The session ends with the drive taken out of operation enabled: the last RPDO is Shutdown
  // (0x0006) holding the final setpoint, the drive's last statusword says ready to switch on, and
  // the drive never sent an EMCY.
  const auto last_rpdo = std::find_if(frames.rbegin(), frames.rend(), [](const Logged& f) { return f.id == 0x201; });
  ASSERT_NE(last_rpdo, frames.rend());
  EXPECT_EQ(last_rpdo->data.at(0) | (last_rpdo->data.at(1) << 8U), 0x0006);
  const auto last_tpdo1 = std::find_if(frames.rbegin(), frames.rend(), [](const Logged& f) { return f.id == 0x181; });
  ASSERT_NE(last_tpdo1, frames.rend());
  EXPECT_EQ((last_tpdo1->data.at(0) | (last_tpdo1->data.at(1) << 8U)) & 0x6F, 0x21) << "ready to switch on";
  EXPECT_TRUE(std::none_of(frames.begin(), frames.end(), [](const Logged& f) { return f.id == 0x081; }));

  // The ideal drive and plant on the bus are the replay's: the same loads, to the count.
  EXPECT_EQ(r.axes[0].agreement, 0.0);
  EXPECT_EQ(r.axes[0].residual_can.amplitude, r.axes[0].residual_offline.amplitude);
  EXPECT_EQ(r.axes[0].setpoints_vs_double_max_counts, 0);
  // Sampled at 1 kHz, the residual is the continuous profile's within a few per cent.
  EXPECT_NEAR(r.axes[0].residual_can.amplitude, r.axes[0].residual_continuous, 0.02 * r.axes[0].residual_continuous);
  EXPECT_EQ(r.frames_lost, 0U);
  std::filesystem::remove(dump);
}

TEST(RunStream, EveryScalarStreamsTheDoubleSetpointsWithinOneCount) {
  const core::Move<double> move = scurve(0.05, 0.3, 22.04871);
  for (const StreamScalar scalar :
       {StreamScalar::double_precision, StreamScalar::single_precision, StreamScalar::fixed_point}) {
    StreamSpec spec = spec_for(move);
    spec.scalar = scalar;
    LoopbackClockedBus bus;
    const StreamReport r = run_stream(spec, bus);
    ASSERT_TRUE(r.failure.empty()) << r.failure;
    EXPECT_TRUE(r.measured()) << to_string(scalar);
    EXPECT_EQ(r.scalar, scalar);
    ASSERT_TRUE(r.axes[0].setpoints_vs_double_max_counts.has_value());
    EXPECT_LE(*r.axes[0].setpoints_vs_double_max_counts, scalar == StreamScalar::double_precision ? 0 : 1);
    EXPECT_EQ(r.axes[0].setpoints.back(), 50000);
    EXPECT_NEAR(r.axes[0].residual_can.amplitude, r.axes[0].residual_double, 0.01 * r.axes[0].residual_double) << to_string(scalar);
  }
}

// The fixed-point evaluation cannot hold a transition shorter than a tick: the loop refuses the
// move at submit, nothing of it is streamed, and there is nothing to measure.
// Issue 14: each bundled drive description, the master configuring and verifying the drive from
// it (dynamic mapping where it is writable, the static one read and checked otherwise) and the
// simulated drive built from it, streams the move to the end, every setpoint once and in order,
// and leaves the same residual as Settle's own drive (the mapping changes where the bytes go, not
// what the drive does). A description without 0x60C2 streams too, its period told through 0x1006.
TEST(RunStream, EachBundledDriveIsConfiguredFromItsEdsAndStreamed) {
  const StreamSpec plain = spec_for(poly345(0.01, 0.5), 0.2);
  LoopbackClockedBus own_bus{""};
  const StreamReport own = run_stream(plain, own_bus);
  ASSERT_TRUE(own.measured()) << own.failure;
  for (const char* name : {"settle_drive", "split_rpdo_drive", "velocity_feedback_drive", "static_mapping_drive"}) {
    SCOPED_TRACE(name);
    hal::eds::LoadResult loaded = hal::eds::load(std::string{SETTLE_EDS_DIR} + "/" + name + ".eds");
    ASSERT_TRUE(loaded.description) << loaded.error;
    StreamSpec spec = plain;
    spec.eds = std::make_shared<const hal::eds::Description>(std::move(*loaded.description));
    LoopbackClockedBus bus{""};
    const StreamReport r = run_stream(spec, bus);
    ASSERT_TRUE(r.failure.empty()) << r.failure;
    EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::completed) << r.axes[0].drive_failure;
    EXPECT_TRUE(r.axes[0].aligned());
    EXPECT_TRUE(r.measured());
    EXPECT_EQ(r.axes[0].setpoints, own.axes[0].setpoints);
    EXPECT_EQ(r.axes[0].residual_can.amplitude, own.axes[0].residual_can.amplitude);
    ASSERT_TRUE(r.start_up_us.has_value());
  }
  hal::eds::LoadResult lacking = hal::eds::load(std::string{SETTLE_TEST_DATA_DIR} + "/no_interpolation_period_drive.eds");
  ASSERT_TRUE(lacking.description) << lacking.error;
  StreamSpec spec = plain;
  spec.eds = std::make_shared<const hal::eds::Description>(std::move(*lacking.description));
  // A drive without 0x60C2 is told the period through 0x1006 alone, and streams the same move.
  LoopbackClockedBus bus{""};
  const StreamReport r = run_stream(spec, bus);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::completed) << r.axes[0].drive_failure;
  EXPECT_EQ(r.axes[0].setpoints, own.axes[0].setpoints);
}

// Issue 35: a drive whose description has no load-side position (no 0x2000, TPDO2 carrying the
// velocity alone) streams as any other, every setpoint checked from 0x6064, but its rest is not
// measured: the CAN residual and PRV are NaN (null in JSON, "not measured" in the text), never
// fitted to a column of zeros. Settle's own description keeps the numbers.
TEST(RunStream, ADriveWithoutALoadPositionHasItsResidualNotMeasured) {
  const StreamSpec plain = spec_for(poly345(0.01, 0.5), 0.2);
  const auto with_eds = [&plain](const std::string& path) {
    hal::eds::LoadResult loaded = hal::eds::load(path);
    EXPECT_TRUE(loaded.description) << loaded.error;
    StreamSpec spec = plain;
    if (loaded.description) spec.eds = std::make_shared<const hal::eds::Description>(std::move(*loaded.description));
    LoopbackClockedBus bus{""};
    return run_stream(spec, bus);
  };
  const StreamReport own = with_eds(std::string{SETTLE_EDS_DIR} + "/settle_drive.eds");
  ASSERT_TRUE(own.failure.empty()) << own.failure;
  EXPECT_TRUE(own.axes[0].load_measured);
  EXPECT_TRUE(own.rest_measured());
  EXPECT_TRUE(std::isfinite(own.axes[0].residual_can.amplitude));
  EXPECT_GT(own.axes[0].residual_can.amplitude, 0.0);
  const nlohmann::json own_json = nlohmann::json::parse(stream_json(own));
  EXPECT_TRUE(own_json["residual_can"].is_number());
  EXPECT_TRUE(own_json["prv_can_percent"].is_number());
  EXPECT_TRUE(own_json["residual_can_note"].is_null());
  EXPECT_EQ(own_json["rest_measured"], true);

  const StreamReport r = with_eds(std::string{SETTLE_TEST_DATA_DIR} + "/no_load_position_drive.eds");
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::completed) << r.axes[0].drive_failure;
  EXPECT_TRUE(r.axes[0].aligned());  // every setpoint applied once, in order, from 0x6064
  EXPECT_EQ(r.axes[0].setpoints, own.axes[0].setpoints);
  EXPECT_FALSE(r.axes[0].load_measured);
  EXPECT_TRUE(r.measured());
  EXPECT_FALSE(r.rest_measured());
  EXPECT_TRUE(std::isnan(r.axes[0].residual_can.amplitude));
  EXPECT_TRUE(std::isnan(r.axes[0].residual_can.prv_percent));
  EXPECT_EQ(r.axes[0].residual_offline.amplitude, own.axes[0].residual_offline.amplitude);
  const nlohmann::json j = nlohmann::json::parse(stream_json(r));
  EXPECT_TRUE(j["residual_can"].is_null());
  EXPECT_TRUE(j["prv_can_percent"].is_null());
  EXPECT_TRUE(j["agreement"].is_null());
  EXPECT_EQ(j["load_measured"], false);
  EXPECT_EQ(j["rest_measured"], false);
  EXPECT_EQ(j["residual_can_note"], "not measured (the drive reports no load position)");
  const std::string text = captured_text([&r](std::FILE* f) { write_stream_text(r, f); });
  EXPECT_NE(text.find("residual (CAN)     not measured (the drive reports no load position)"), std::string::npos)
      << text;
}

TEST(RunStream, ARefusedMoveIsReportedAndNotStreamed) {
  StreamSpec spec = spec_for(scurve(1e-4, 0.002, 22.0));
  spec.scalar = StreamScalar::fixed_point;
  const std::string dump = temp_path("refused.log");
  LoopbackClockedBus bus{dump};
  const StreamReport r = run_stream(spec, bus);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::rejected);
  EXPECT_EQ(r.session.rejection, runtime::LoopStatus::evaluation_refused);
  EXPECT_EQ(r.axes[0].evaluation, core::Status::transition_shorter_than_tick);
  EXPECT_TRUE(r.axes[0].setpoints.empty());
  EXPECT_FALSE(r.axes[0].setpoints_vs_double_max_counts.has_value());
  EXPECT_FALSE(r.axes[0].aligned());
  EXPECT_FALSE(r.measured());
  EXPECT_TRUE(std::isfinite(r.axes[0].residual_double));  // the double evaluation took it
  for (const Logged& f : read_candump(dump)) {
    if (f.id == 0x201) {
      EXPECT_EQ(rpdo_target(f.data), 0) << "a target of the refused move was sent";
    }
  }
  std::filesystem::remove(dump);
}

TEST(RunStream, AMoveOverTheAxisVelocityIsRejected) {
  StreamSpec spec = spec_for(poly345(0.01, 0.5));
  spec.axis_vmax = 0.001;  // the move peaks at 0.0375 m/s
  LoopbackClockedBus bus;
  const StreamReport r = run_stream(spec, bus);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::rejected);
  EXPECT_EQ(r.session.rejection, runtime::LoopStatus::exceeds_axis_velocity);
  EXPECT_EQ(r.axes[0].evaluation, core::Status::ok);  // the evaluation took it; the loop's limit did not
  EXPECT_FALSE(r.measured());
}

// A session that ends before its halt (here: the move is refused) reports why it ended, not that
// the halt did not happen.
TEST(RunStream, ASessionThatEndsBeforeItsHaltReportsItsOwnOutcome) {
  StreamSpec spec = spec_for(poly345(0.01, 0.5));
  spec.axis_vmax = 0.001;  // the move peaks at 0.0375 m/s
  StreamChange c{};
  c.at = 0.2;
  c.modes = {core::Mode{spec.plant.fundamental().omega, spec.plant.fundamental().zeta}};
  c.limits = {0.001, 1.0, 100.0};  // within the axis's vmax: the move, not the change, is refused
  spec.axes[0].change = c;
  LoopbackClockedBus bus;
  const StreamReport r = run_stream(spec, bus);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::rejected);
  EXPECT_EQ(r.session.rejection, runtime::LoopStatus::exceeds_axis_velocity);
  EXPECT_FALSE(r.measured());
}

// A bus that plays back a schedule of frames on a clock of its own: receive() waits (moves the
// clock) until the next frame is due, or for its whole timeout when none is due within it.
class ScheduledBus final : public hal::CanBus {
 public:
  struct Due {
    std::uint64_t at_us;
    hal::CanFrame frame;
  };
  explicit ScheduledBus(std::vector<Due> due) : due_{std::move(due)} {}
  std::uint64_t now_us{0};

 private:
  hal::SendStatus do_send(const hal::CanFrame&) noexcept override { return hal::SendStatus::sent; }
  hal::ReceiveStatus do_receive(hal::CanFrame& f, std::uint32_t timeout_us) noexcept override {
    if (next_ == due_.size() || due_[next_].at_us > now_us + timeout_us) {
      now_us += timeout_us;
      return hal::ReceiveStatus::empty;
    }
    now_us = std::max(now_us, due_[next_].at_us);
    f = due_[next_++].frame;
    return hal::ReceiveStatus::received;
  }
  hal::BusStatus do_set_filters(std::span<const hal::CanFilter>) noexcept override { return hal::BusStatus::ok; }
  std::vector<Due> due_;
  std::size_t next_{0};
};

// The end of a session waits for the last TPDOs, not for the drives to fall silent: three drives'
// heartbeats every 100 ms, 33 ms apart, never leave 50 ms of quiet. A TPDO late by 30 ms is still
// taken; a peer that never falls silent is cut off at the window's limit, and on a clock that does
// not move, at its frame count.
TEST(RunStream, TheLateFramesAreTakenWithinABoundedWindow) {
  namespace co = hal::canopen;
  const auto heartbeat = [](co::NodeId node) { return co::encode_heartbeat(node, co::NmtState::operational); };
  hal::CanFrame tpdo{};
  tpdo.id = co::cob_id(co::cob::tpdo1, 5);
  tpdo.len = 8;
  std::vector<ScheduledBus::Due> due{{30'000, tpdo}};
  for (std::uint64_t t = 0; t < 10'000'000; t += 100'000) {
    due.push_back({t + 10'000, heartbeat(1)});
    due.push_back({t + 43'000, heartbeat(5)});
    due.push_back({t + 76'000, heartbeat(9)});
  }
  std::sort(due.begin(), due.end(), [](const auto& a, const auto& b) { return a.at_us < b.at_us; });
  ScheduledBus bus{due};
  std::vector<std::uint32_t> ids;
  const std::size_t taken = take_late_frames(
      bus, [&] { return bus.now_us; }, [&](const hal::CanFrame& f, std::uint64_t) { ids.push_back(f.id); });
  // Quiet from 30 ms (the TPDO) to 80 ms: the heartbeats at 10, 43 and 76 ms do not count.
  EXPECT_EQ(bus.now_us, 80'000U);
  EXPECT_EQ(taken, 4U);
  EXPECT_EQ(ids, (std::vector<std::uint32_t>{0x701, 0x185, 0x705, 0x709}));

  // A node that sends a PDO every 20 ms for ever: cut off at the limit.
  std::vector<ScheduledBus::Due> chatter;
  for (std::uint64_t t = 20'000; t < 10'000'000; t += 20'000) chatter.push_back({t, tpdo});
  ScheduledBus busy{chatter};
  const std::size_t cut = take_late_frames(
      busy, [&] { return busy.now_us; }, [](const hal::CanFrame&, std::uint64_t) {},
      LateFrameWindow{50'000, 500'000, 8192});
  EXPECT_LE(busy.now_us, 500'000U);
  EXPECT_GE(cut, 24U);

  // On a clock that stands still (the periodic timer's period start, once the session stopped
  // waiting on it: what hung the master) the frame count still ends it.
  std::vector<ScheduledBus::Due> endless;
  for (std::uint64_t t = 10'000; endless.size() < 20'000; t += 10'000) endless.push_back({t, heartbeat(1)});
  ScheduledBus frozen{endless};
  const std::size_t counted =
      take_late_frames(frozen, [] { return std::uint64_t{1'000'000}; }, [](const hal::CanFrame&, std::uint64_t) {},
                       LateFrameWindow{50'000, 500'000, 8192});
  EXPECT_EQ(counted, 8192U);

  // Held off the CPU past the whole window between the start and the first look (a loaded host):
  // the 100 TPDOs that arrived meanwhile are queued and every one is taken (the stress test's
  // ten-thousand-ticks run lost its alignment when they were not).
  std::vector<ScheduledBus::Due> backlog;
  for (std::uint64_t t = 1'000; t <= 100'000; t += 1'000) backlog.push_back({t, tpdo});
  ScheduledBus stalled{backlog};
  stalled.now_us = 200'000;  // every one has arrived
  int looks = 0;
  const std::size_t late = take_late_frames(
      stalled, [&] { return looks++ == 0 ? std::uint64_t{0} : stalled.now_us + 10'000'000; },
      [](const hal::CanFrame&, std::uint64_t) {}, LateFrameWindow{50'000, 500'000, 8192});
  EXPECT_EQ(late, 100U);
}

// Three axes on nodes 1, 4 and 2 of one loopback bus, each its own drive and copy of the plant:
// from the bus alone (a sniffer's log), every node's RPDO carries its own axis's setpoints once and
// in order, and every move's first setpoint goes out in the same SYNC period.
TEST(RunStream, ThreeAxesStartOnTheSameSyncEachWithItsOwnSetpoints) {
  const std::string dump = temp_path("axes.log");
  StreamSpec spec = spec_for(poly345(0.01, 0.5), 0.2);
  spec.drive.scale.period_us = 1200;  // three axes at 1 Mbit/s
  spec.axes.push_back({poly345(-0.02, 0.5), 4, std::nullopt});
  spec.axes.push_back({poly345(0.005, 0.5), 2, std::nullopt});
  LoopbackClockedBus bus{dump};
  const StreamReport r = run_stream(spec, bus);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::completed);
  EXPECT_TRUE(r.measured());
  EXPECT_TRUE(r.session.released);
  ASSERT_EQ(r.axes.size(), 3U);
  const std::uint8_t nodes[3] = {1, 4, 2};
  // Per SYNC period (the frames after one SYNC up to the next), each node's RPDO target.
  const std::vector<Logged> frames = read_candump(dump);
  std::vector<std::vector<std::int32_t>> per_node(3);
  std::vector<std::vector<std::size_t>> period_of(3);
  std::size_t period = 0;
  for (const Logged& f : frames) {
    if (f.id == 0x080) ++period;
    for (std::size_t i = 0; i < 3; ++i) {
      if (f.id == 0x200U + nodes[i]) {
        per_node[i].push_back(rpdo_target(f.data));
        period_of[i].push_back(period);
      }
    }
  }
  std::size_t first_period[3]{};
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const AxisReport& a = r.axes[i];
    EXPECT_EQ(a.node, nodes[i]);
    EXPECT_TRUE(a.aligned());
    EXPECT_EQ(a.drive_state, "released");
    EXPECT_EQ(a.setpoints.size(), 418U);  // 0.5 s at 1.2 ms: ticks 0..417
    const auto move = std::search(per_node[i].begin(), per_node[i].end(), a.setpoints.begin() + 1, a.setpoints.end());
    ASSERT_NE(move, per_node[i].end()) << "node " << int{nodes[i]} << "'s RPDOs do not carry its setpoints in order";
    first_period[i] = period_of[i][static_cast<std::size_t>(move - per_node[i].begin())];
  }
  EXPECT_EQ(first_period[1], first_period[0]);
  EXPECT_EQ(first_period[2], first_period[0]);
  ASSERT_TRUE(r.end_tick_spread.has_value());
  EXPECT_EQ(*r.end_tick_spread, 0U);
  EXPECT_EQ(*r.start_tick_spread, 0U);
  EXPECT_LE(r.line_deviation_setpoints_counts, 1.0);
  EXPECT_LE(r.line_deviation_feedback_counts, 1.0);
  std::filesystem::remove(dump);

  // Two axes on one node: refused before anything streams.
  StreamSpec twice = spec;
  twice.axes[2].node = 1;
  LoopbackClockedBus other;
  const StreamReport refused = run_stream(twice, other);
  EXPECT_EQ(refused.failure, "axes 1 and 3 are both on node 1: one drive per node");
  EXPECT_TRUE(refused.axes[0].log.empty());
}

// Issue 17: a coordinated three-axis move (path sync) halted at 100 random times, every axis's halt
// asked for in the same period with what core::axis_online gives it, as a path's axes
// (OnlineConfig::path: the loop plans the halt once), as `settle stream --axes 3 --halt-at T` does. Every time, on the sdof plant (whose damping the S-curve's design ignores, so
// the uninterrupted move leaves a residual): every axis aligned with the replay of its halted
// setpoints, at rest on its mode (the continuous residual of its changed command within 1e-9 of its
// distance, what its drive reports within a count of the load encoder), all ending on the same
// tick and within a count of the line, and the session releases every drive.
TEST(RunStream, ThreeAxesHaltedAtRandomTimesEndTogetherOnTheLineAtRest) {
  plant::ModalPlant plant;
  ASSERT_EQ(plant::ModalPlant::make_sdof(plant::SdofParams{}, plant), plant::SimStatus::ok);
  const plant::Mode& f = plant.fundamental();
  core::MultiAxisRequest req{};
  req.base.profile = core::ProfileKind::scurve;
  req.base.time = 0.5;
  req.count = 3;
  const double d[3] = {0.1, 0.05, -0.2};
  for (std::size_t i = 0; i < 3; ++i) req.axes[i] = {d[i], std::nullopt, std::nullopt, std::nullopt, f.omega, f.zeta};
  core::MultiAxisPlan plan{};
  std::size_t culprit = 0;
  ASSERT_EQ(core::plan_axes(req, plan, culprit), core::Status::ok);
  std::array<core::Move<double>, 3> moves{};
  std::array<core::AxisOnline, 3> online{};
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_EQ(core::axis_command(req, plan, i, moves[i]), core::Status::ok);
    ASSERT_EQ(core::axis_online(req, plan, i, online[i]), core::Status::ok);
  }
  std::mt19937_64 rng{20261203};
  const double period = 1.2e-3;  // three axes at 1 Mbit/s
  for (int n = 0; n < 100; ++n) {
    SCOPED_TRACE(n);
    const double at = std::round(std::uniform_real_distribution<double>{0.01, 0.49}(rng) / period) * period;
    std::array<StreamChange, 3> changes{};
    std::array<core::OnlineRequest, 3> q{};
    std::array<const core::OnlineRequest*, 3> qp{};
    std::array<core::OnlinePlan, 3> halt{};
    for (std::size_t i = 0; i < 3; ++i) {
      const core::AxisOnline& o = online[i];
      StreamChange& c = changes[i];
      c.at = at;
      c.modes.assign(o.modes.begin(), o.modes.begin() + static_cast<std::ptrdiff_t>(o.mode_count));
      c.limits = o.limits;
      c.path = true;  // the loop plans the path's halt once, as core does here
      ASSERT_EQ(core::online_request(moves[i], at, o.modes.data(), o.mode_count, o.limits, std::nullopt, q[i]),
                core::Status::ok);
      qp[i] = &q[i];
    }
    std::size_t ref = 3;
    ASSERT_EQ(core::plan_path_online(qp.data(), d, 3, halt.data(), ref), core::Status::ok) << "halted at " << at;
    for (std::size_t i = 0; i < 3; ++i) {
      changes[i].blend = halt[i].blend;
      changes[i].finish = halt[i].choice == core::OnlineChoice::finish;  // the halt finishes the move
    }
    StreamSpec spec{};
    spec.plant = plant;
    spec.settle_time_s = 0.3;
    spec.drive.scale.period_us = 1200;
    spec.axes = {{moves[0], 1, changes[0]}, {moves[1], 2, changes[1]}, {moves[2], 3, changes[2]}};
    LoopbackClockedBus bus;
    const StreamReport r = run_stream(spec, bus);
    ASSERT_TRUE(r.failure.empty()) << r.failure;
    EXPECT_TRUE(r.measured()) << runtime::to_string(r.session.outcome);
    EXPECT_TRUE(r.session.released);
    ASSERT_EQ(r.axes.size(), 3U);
    for (std::size_t i = 0; i < 3; ++i) {
      const AxisReport& a = r.axes[i];
      EXPECT_TRUE(a.aligned()) << "axis " << i;
      EXPECT_LE(a.residual_continuous, 1e-9 * std::fabs(d[i])) << "axis " << i << " halted at " << at;
      EXPECT_LE(a.residual_can.amplitude, 1.0 / spec.drive.load_counts_per_unit) << "axis " << i;
      // Every axis's blend is D_i / D_1 times axis 1's, of its segment length bit for bit: it
      // stops on the line, at the same instant.
      EXPECT_NEAR(changes[i].blend.end_position(), d[i] / d[0] * changes[0].blend.end_position(), 1e-12);
      EXPECT_EQ(changes[i].blend.segment_length(), changes[0].blend.segment_length());
    }
    ASSERT_TRUE(r.end_tick_spread.has_value());
    EXPECT_EQ(*r.start_tick_spread, 0U);
    EXPECT_EQ(*r.end_tick_spread, 0U);
    EXPECT_LE(r.line_deviation_setpoints_counts, 1.0);
    EXPECT_LE(r.line_deviation_feedback_counts, 1.0);
  }
  // Two axes asked to change at different times cannot be asked in one period: refused.
  StreamSpec apart{};
  apart.plant = plant;
  apart.drive.scale.period_us = 1200;
  apart.axes = {{moves[0], 1, StreamChange{}}, {moves[1], 2, StreamChange{}}};
  apart.axes[0].change->at = 0.1;
  apart.axes[1].change->at = 0.2;
  LoopbackClockedBus other;
  EXPECT_EQ(run_stream(apart, other).failure,
            "axes 1 and 2 change at different times: every axis's halt or retarget is asked for in the same period");
}

// The loop's step guard admits every blend the planner makes: halts and retargets of moves on one to
// three path-synchronised axes, of several profiles, designed for random modes, with limits above
// the moves' own peaks (--vmax, --amax, --jmax given, as `settle stream --axes N --halt-at` passes
// them: a blend may go faster than the move it stops), at random times, in double and float,
// streamed with the default axis vmax (stream_axis_vmax). None trips the guard; every one completes.
// (The guard used to be 1.5 x the move's peak: the blend of `--profile jerk-limited --distance
// 0.01,0.005,-0.02 --vmax 1 --amax 20 --jmax 800 --halt-at 0.05` passed it and ended step_guard.)
TEST(RunStream, NoPlannedHaltOrRetargetTripsTheStepGuard) {
  plant::ModalPlant plant;
  ASSERT_EQ(plant::ModalPlant::make_sdof(plant::SdofParams{}, plant), plant::SimStatus::ok);
  const core::Mode fundamental{plant.fundamental().omega, plant.fundamental().zeta};
  std::mt19937_64 rng{20261205};
  const auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>{lo, hi}(rng); };
  const core::ProfileKind profiles[] = {core::ProfileKind::jerk_limited, core::ProfileKind::scurve,
                                        core::ProfileKind::scurve_damped};
  const double period = 1.2e-3;
  int streamed = 0, blends = 0;
  for (int n = 0; n < 24; ++n) {
    core::MultiAxisRequest req{};
    req.base.profile = profiles[static_cast<std::size_t>(n) % std::size(profiles)];
    req.count = 1 + static_cast<std::size_t>(n / 3) % 3;
    const double vmax = uniform(0.3, 2.0), amax = uniform(5.0, 50.0), jmax = uniform(300.0, 3000.0);
    for (std::size_t i = 0; i < req.count; ++i) {
      const double d = uniform(0.003, 0.04) * (uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0);
      req.axes[i] = {d, vmax, amax, jmax, std::exp(uniform(std::log(10.0), std::log(40.0))), uniform(0.0, 0.1)};
    }
    const bool retarget = n % 4 == 3;
    SCOPED_TRACE("case " + std::to_string(n) + ": " + core::to_string(req.base.profile) + ", " +
                 std::to_string(req.count) + " axes" + (retarget ? ", retarget" : ", halt"));
    core::MultiAxisPlan plan{};
    std::size_t culprit = 0;
    ASSERT_EQ(core::plan_axes(req, plan, culprit), core::Status::ok);
    const double at = std::fmax(std::round(uniform(0.05, 0.95) * plan.duration() / period), 3.0) * period;
    if (!(at < plan.duration())) continue;
    const double fraction = uniform(-0.5, 1.5);  // of each axis's distance: the new target of a retarget
    StreamSpec spec{};
    spec.plant = plant;
    spec.settle_time_s = 0.05;
    spec.drive.scale.period_us = 1200;
    spec.scalar = n % 2 == 0 ? StreamScalar::double_precision : StreamScalar::single_precision;
    bool planned = true;
    for (std::size_t i = 0; i < req.count; ++i) {
      core::Move<double> move{};
      core::AxisOnline o{};
      ASSERT_EQ(core::axis_command(req, plan, i, move), core::Status::ok);
      ASSERT_EQ(core::axis_online(req, plan, i, o, &fundamental), core::Status::ok);
      StreamChange c{};
      c.at = at;
      c.modes.assign(o.modes.begin(), o.modes.begin() + static_cast<std::ptrdiff_t>(o.mode_count));
      c.limits = o.limits;
      if (retarget) c.target = fraction * move.distance();
      core::OnlineRequest q{};
      ASSERT_EQ(core::online_request(move, at, o.modes.data(), o.mode_count, o.limits, c.target, q), core::Status::ok);
      core::OnlinePlan blend{};
      // A change with no blend within the limits (a trapezoid's acceleration step near vmax) is
      // refused by the CLI before anything streams: not a case for the guard.
      planned = planned && core::plan_online(q, blend) == core::Status::ok;
      if (!planned) break;
      c.blend = blend.blend;
      c.finish = blend.choice == core::OnlineChoice::finish;
      blends += c.finish ? 0 : 1;
      if (i == 0) spec.axes.clear();
      spec.axes.push_back({move, static_cast<hal::canopen::NodeId>(i + 1), c});
    }
    if (!planned) continue;
    const StreamRefusal refusal = check_streamable(spec, true);
    ASSERT_EQ(refusal.status, runtime::LoopStatus::ok) << "axis " << refusal.axis << ": " << core::to_string(refusal.why);
    LoopbackClockedBus bus;
    const StreamReport r = run_stream(spec, bus);
    ASSERT_TRUE(r.failure.empty()) << r.failure;
    EXPECT_EQ(r.session.outcome, runtime::SessionOutcome::completed) << runtime::to_string(r.session.outcome);
    for (const AxisReport& a : r.axes) EXPECT_EQ(a.axis.step_guard_trips, 0u);
    EXPECT_TRUE(r.measured());
    ++streamed;
  }
  EXPECT_GE(streamed, 20);
  EXPECT_GE(blends, 20);  // blends, not only halts that finish the move
}

// A halt whose blend may go faster than the axis's vmax cannot be configured: the loop refuses the
// limits (what the guard would otherwise trip on), and check_streamable says so before any frame.
TEST(RunStream, AChangeFasterThanTheAxisIsRefusedBeforeStreaming) {
  StreamSpec spec = spec_for(poly345(0.01, 0.5));
  StreamChange c{};
  c.at = 0.2;
  c.modes = {core::Mode{spec.plant.fundamental().omega, spec.plant.fundamental().zeta}};
  c.limits = {1.0, 10.0, 1000.0};
  spec.axes[0].change = c;
  spec.axis_vmax = 0.5;  // the move peaks at 0.0375 m/s; its blend may reach 1 m/s
  const StreamRefusal r = check_streamable(spec, true);
  EXPECT_EQ(r.status, runtime::LoopStatus::exceeds_axis_velocity);
  EXPECT_TRUE(r.in_change);
  EXPECT_EQ(r.peak, 1.0);
  EXPECT_EQ(r.limit, 0.5);
  LoopbackClockedBus bus;
  EXPECT_EQ(run_stream(spec, bus).failure, "the loop refused axis 1's online configuration: exceeds_axis_velocity");
  spec.axis_vmax.reset();  // by default the axis's vmax is the blend's
  EXPECT_EQ(stream_axis_vmax(spec, spec.axes[0]), 1.0);
  EXPECT_EQ(check_streamable(spec, true).status, runtime::LoopStatus::ok);
  // The simulated drive's 0x607F (1e7 counts/s) at 1e8 counts per metre: 0.1 m/s at most.
  spec.drive.scale.counts_per_unit = 1e8;
  const StreamRefusal drive = check_streamable(spec, true);
  EXPECT_EQ(drive.status, runtime::LoopStatus::exceeds_drive_velocity);
  EXPECT_TRUE(drive.in_change);
  EXPECT_EQ(drive.limit, 1e7);
  EXPECT_EQ(check_streamable(spec, false).status, runtime::LoopStatus::ok);  // another bus: not known before start-up
}

TEST(RunStream, WhatCannotRunIsAFailureBeforeAnythingStreams) {
  LoopbackClockedBus unwritable{"/nonexistent-settle-dir/run.log"};
  const StreamReport a = run_stream(spec_for(poly345(0.01, 0.5)), unwritable);
  EXPECT_EQ(a.failure, "cannot write /nonexistent-settle-dir/run.log");
  EXPECT_TRUE(a.axes[0].log.empty());

  StreamSpec no_period = spec_for(poly345(0.01, 0.5));
  no_period.drive.scale.period_us = 0;
  LoopbackClockedBus bus;
  EXPECT_FALSE(run_stream(no_period, bus).failure.empty());

  StreamSpec no_axis = spec_for(poly345(0.01, 0.5));
  no_axis.axes.clear();
  LoopbackClockedBus empty;
  const StreamReport none = run_stream(no_axis, empty);
  EXPECT_EQ(none.failure, "no axis to stream");
  EXPECT_FALSE(none.measured());
}

// The bus with a clock unpaced, as settle drive uses it: the loopback drive (the one builder's, at
// the node asked for) answers an SDO request at once, in the same virtual instant; with nothing to
// answer, a receive moves virtual time on by exactly the wait.
TEST(LoopbackClockedBus, ReceiveAnswersAtOnceAndOtherwiseMovesVirtualTimeByTheWait) {
  LoopbackClockedBus bus;
  SimulatedDriveSpec drive{};
  drive.node = 5;
  ASSERT_EQ(bus.open(1000, {drive}), "");
  EXPECT_EQ(bus.now_us(), 0U);
  hal::CanFrame f{};
  while (bus.receive(f, 0)) {  // the drive's boot-up and first heartbeat
  }
  const std::uint64_t t0 = bus.now_us();
  hal::canopen::SdoClient client{5, 1'000'000};
  ASSERT_TRUE(client.upload(0x1000, 0, bus.now_us(), bus.link()));
  ASSERT_TRUE(bus.receive(f, 7000));
  EXPECT_EQ(bus.now_us(), t0);
  (void)client.on_frame(f, bus.now_us(), bus.link());
  ASSERT_EQ(client.result().status, hal::canopen::SdoClientStatus::done);
  EXPECT_EQ(client.result().value, hal::canopen::cia402_device_type);
  EXPECT_FALSE(bus.receive(f, 7000));
  EXPECT_EQ(bus.now_us(), t0 + 7000);
  // A node no drive answers to: nothing comes.
  hal::canopen::SdoClient nobody{6, 1'000'000};
  ASSERT_TRUE(nobody.upload(0x1000, 0, bus.now_us(), bus.link()));
  EXPECT_FALSE(bus.receive(f, 3));
  EXPECT_EQ(bus.now_us(), t0 + 7003);
}

// The in-process loopback bus with one call replaced: the test buses below change only what
// happens between ticks.
class LoopbackWrapper : public ClockedBus {
 public:
  [[nodiscard]] std::string name() const override { return inner_.name(); }
  [[nodiscard]] bool realtime() const override { return false; }
  [[nodiscard]] std::string open(const StreamSpec& spec) override { return inner_.open(spec); }
  [[nodiscard]] hal::CanBus& link() override { return inner_.link(); }
  void begin() override { inner_.begin(); }
  std::uint64_t wait() override { return inner_.wait(); }
  [[nodiscard]] std::uint64_t now_us() const override { return inner_.now_us(); }
  void between_ticks() override { inner_.between_ticks(); }
  [[nodiscard]] std::string finish(const FrameTaker& take) override { return inner_.finish(take); }
  [[nodiscard]] hal::BusCounters counters() const override { return inner_.counters(); }
  [[nodiscard]] StreamTiming timing() const override { return inner_.timing(); }

 protected:
  LoopbackClockedBus inner_;
};

// A bus that counts the heap allocations made between its between-ticks calls: everything the
// loop, the session and run_stream's observer do in ticks 1..N, but not the in-process drive's
// own work (its plant integrates with Eigen, which allocates: it stands for the hardware).
class CountingBus final : public LoopbackWrapper {
 public:
  void between_ticks() override {
    if (ticks_ > 0) outside_ += g_allocations.load() - after_;
    LoopbackWrapper::between_ticks();
    after_ = g_allocations.load();
    ++ticks_;
  }
  [[nodiscard]] std::uint64_t allocations() const { return outside_; }
  [[nodiscard]] std::uint64_t ticks() const { return ticks_; }

 private:
  std::uint64_t after_{0};
  std::uint64_t outside_{0};
  std::uint64_t ticks_{0};
};

// A drive that stalls for 40 periods in the settling window and then answers every SYNC at once
// (a host process held off the CPU): the loop keeps every sample (a microcontroller's 16-sample log
// would drop 24), so the run is aligned and measures the residual of the run without the stall.
class StallingBus final : public LoopbackWrapper {
 public:
  explicit StallingBus(bool stall) : stall_{stall} {}
  void between_ticks() override {
    if (!stall_ || ++ticks_ < 700 || ticks_ >= 740) LoopbackWrapper::between_ticks();
  }

 private:
  bool stall_;
  std::uint64_t ticks_{0};
};

TEST(RunStream, ADriveThatFallsBehindLosesNoFeedback) {
  StreamSpec spec = spec_for(poly345(0.01, 0.5), 0.5);
  spec.feedback_timeout_periods = 0;  // the stall is not a lost drive here
  StallingBus steady{false}, stalling{true};
  const StreamReport plain = run_stream(spec, steady);
  const StreamReport r = run_stream(spec, stalling);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  ASSERT_TRUE(plain.measured());
  EXPECT_GT(r.axes[0].feedback_late_ticks, 0U);
  EXPECT_EQ(r.axes[0].axis.feedback_overflows, 0U);
  EXPECT_TRUE(r.measured());
  EXPECT_EQ(r.axes[0].residual_can.amplitude, plain.axes[0].residual_can.amplitude);
  EXPECT_EQ(r.axes[0].window_samples, plain.axes[0].window_samples);
}

TEST(RunStream, NothingIsAllocatedWhileStreaming) {
  for (const StreamScalar scalar :
       {StreamScalar::double_precision, StreamScalar::single_precision, StreamScalar::fixed_point}) {
    StreamSpec spec = spec_for(poly345(0.01, 0.5), 0.5);
    spec.scalar = scalar;
    if (scalar == StreamScalar::fixed_point) {  // and with three axes
      spec.drive.scale.period_us = 1200;
      spec.axes.push_back({poly345(-0.02, 0.5), 2, std::nullopt});
      spec.axes.push_back({poly345(0.005, 0.5), 3, std::nullopt});
    }
    CountingBus bus;
    const StreamReport r = run_stream(spec, bus);
    ASSERT_TRUE(r.failure.empty()) << r.failure;
    EXPECT_TRUE(r.measured()) << to_string(scalar);
    EXPECT_GT(bus.ticks() * spec.drive.scale.period_us, 1'000'000U);  // the move and the window: 1 s
    EXPECT_EQ(bus.allocations(), 0U) << to_string(scalar);
    EXPECT_EQ(r.axes.size(), spec.axes.size());
  }
}

}  // namespace
}  // namespace settle::testbed

namespace settle::testbed {
namespace {

// The loopback bus with the drive's statusword held at 0x0240 (switch on disabled) in every
// TPDO1 the master receives: a slave that never leaves it.
class StuckStatusBus final : public LoopbackWrapper, private hal::CanBus {
 public:
  [[nodiscard]] std::string open(const StreamSpec& spec) override {
    node_ = spec.axes[0].node;
    return inner_.open(spec);
  }
  [[nodiscard]] hal::CanBus& link() override { return *this; }

 private:
  hal::SendStatus do_send(const hal::CanFrame& frame) noexcept override { return inner_.link().send(frame); }
  hal::ReceiveStatus do_receive(hal::CanFrame& frame, std::uint32_t timeout_us) noexcept override {
    const hal::ReceiveStatus s = inner_.link().receive(frame, timeout_us);
    if (s == hal::ReceiveStatus::received && frame.id == 0x180U + node_ && frame.len >= 2) {
      frame.data[0] = 0x40;
      frame.data[1] = 0x02;
    }
    return s;
  }
  hal::BusStatus do_set_filters(std::span<const hal::CanFilter> filters) noexcept override {
    return inner_.link().set_filters(filters);
  }
  unsigned node_{1};
};

// A slave that never leaves switch on disabled: the report says what its statusword showed,
// never an empty drive_failure.
TEST(RunStream, ADriveThatNeverEnablesIsReportedWithItsStatusword) {
  const StreamSpec spec = spec_for(poly345(0.01, 0.5), 0.2);
  StuckStatusBus bus;
  const StreamReport r = run_stream(spec, bus);
  ASSERT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_FALSE(r.start_up_us.has_value());
  EXPECT_NE(r.axes[0].drive_failure.find("the drive's statusword stayed 0x0240 (switch on disabled), not operation enabled"),
            std::string::npos)
      << "drive_failure: '" << r.axes[0].drive_failure << "'";
}

}  // namespace
}  // namespace settle::testbed
