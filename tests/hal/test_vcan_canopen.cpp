// SPDX-License-Identifier: Apache-2.0
// Two processes exchange CANopen traffic through vcan0: this test is the master (RemoteDrive
// on a SocketCanBus), tests/hal/vcan_peer is the drive (DriveNode). candump logs the same
// frames in its own format and a test reads that log back. Throughput both ways is printed.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/candump_log.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "vcan_support.hpp"

namespace settle::hal {
namespace {

using namespace std::chrono_literals;

constexpr canopen::NodeId drive_id = 2;
// Marks the point from which candump is known to be logging; extended, so CANopen ignores it.
constexpr std::uint32_t probe_id = 0x1FFF'FFF0;

std::string output_path(const std::string& name) { return std::string{SETTLE_HAL_TEST_OUTPUT_DIR} + "/" + name; }

std::string read_file(const std::string& path) {
  std::ifstream in{path};
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::map<std::string, std::string> key_values(const std::string& text) {
  std::map<std::string, std::string> kv;
  std::istringstream in{text};
  std::string line;
  while (std::getline(in, line)) {
    if (const auto eq = line.find('='); eq != std::string::npos) {
      kv[line.substr(0, eq)] = line.substr(eq + 1);
    }
  }
  return kv;
}

bool wait_for_text(const std::string& path, const std::string& text, std::chrono::milliseconds limit,
                   const std::function<void()>& between = {}) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (read_file(path).find(text) != std::string::npos) {
      return true;
    }
    if (between) {
      between();
    }
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

// Everything the master put on the bus, in order.
class RecordingSink final : public FrameSink {
 public:
  explicit RecordingSink(CanBus& bus) : bus_{bus} {}
  [[nodiscard]] bool put(const CanFrame& frame) noexcept override {
    if (bus_.send(frame) != SendStatus::sent) {
      return false;
    }
    sent.push_back(frame);
    return true;
  }
  std::vector<CanFrame> sent;

 private:
  CanBus& bus_;
};

struct Exchange {
  bool ready{false};
  int setpoints{0};
  int setpoint_mismatches{0};
  std::uint64_t rpdos_sent{0};
  std::uint64_t syncs_sent{0};
  std::vector<CanFrame> sent;
  std::vector<CanFrame> received;
  std::map<std::string, std::string> drive_counters;
  double cycles_per_second{0};
  BusCounters bus{};
};

// Starts the drive process, brings it up with the master's start-up sequence and streams
// `ticks` CSP setpoints in lock step (RPDO + SYNC, then wait for TPDO1/TPDO2).
Exchange run_exchange(int ticks, const std::string& candump_log) {
  Exchange x;
  SocketCanBus bus;
  EXPECT_EQ(bus.open(test::vcan_interface), OpenStatus::ok);
  RecordingSink out{bus};
  CanFrame f{};

  test::Child candump;
  if (!candump_log.empty()) {
    // A 16 MB receive buffer (-r, forced as root): a candump that is not scheduled for a while on a
    // loaded host keeps every frame queued instead of dropping them.
    EXPECT_TRUE(candump.start({"candump", "-r", "16777216", "-L", test::vcan_interface}, candump_log));
    CanFrame probe{};
    probe.id = probe_id;
    probe.flags = can_flag::extended;
    EXPECT_TRUE(wait_for_text(candump_log, "1FFFFFF0#", 10s, [&] { (void)out.put(probe); }))
        << "candump did not start logging";
  }

  test::Child drive;
  const std::string drive_out = output_path("vcan-drive.out");
  EXPECT_TRUE(drive.start({SETTLE_HAL_VCAN_PEER, "drive", std::to_string(drive_id)}, drive_out));
  // The drive announces itself with a boot-up message; configuring before that would race
  // the process start.
  const auto boot_deadline = test::monotonic_us() + 10'000'000;
  bool booted = false;
  while (!booted && test::monotonic_us() < boot_deadline) {
    if (bus.receive(f, 10'000) == ReceiveStatus::received) {
      x.received.push_back(f);
      booted = f == canopen::encode_heartbeat(drive_id, canopen::NmtState::initialising);
    }
  }
  EXPECT_TRUE(booted) << "no boot-up from the drive process";

  canopen::RemoteDriveConfig rc{};
  rc.node = drive_id;
  rc.heartbeat_timeout_ms = 2000;
  rc.sdo_timeout_us = 500'000;
  rc.enable_timeout_us = 5'000'000;
  // An emulated single-CPU guest may deschedule either process for a while; the safety
  // rules are tested exactly on the virtual clock, here they only must not get in the way.
  rc.communication_loss_periods = 200;
  canopen::RemoteDrive remote{rc};
  canopen::SyncProducer sync{rc.sync_period_us};
  remote.start(test::monotonic_us(), out);

  const auto receive_until = [&](auto done, std::uint64_t limit_us) {
    const std::uint64_t deadline = test::monotonic_us() + limit_us;
    while (!done() && test::monotonic_us() < deadline) {
      if (bus.receive(f, 1000) == ReceiveStatus::received) {
        x.received.push_back(f);
        remote.on_frame(f, test::monotonic_us(), out);
      }
    }
  };
  const auto tick = [&](std::int32_t target) {
    remote.poll(test::monotonic_us(), out);
    const std::uint64_t periods_before = remote.feedback().periods_complete;
    const bool process_data = remote.state() == canopen::RemoteDriveState::enabling || remote.ready();
    if (CanFrame rpdo{}; remote.rpdo(target, rpdo) && out.put(rpdo)) {
      ++x.rpdos_sent;
    }
    if (out.put(sync.next())) {
      ++x.syncs_sent;
    }
    if (process_data) {
      receive_until([&] { return remote.feedback().periods_complete > periods_before; }, 200'000);
    } else {
      receive_until([] { return false; }, 2'000);  // SDO answers during configuration
    }
  };

  for (int i = 0; i < 5000 && !remote.ready() && remote.state() != canopen::RemoteDriveState::failed; ++i) {
    tick(0);
  }
  x.ready = remote.ready();
  EXPECT_TRUE(x.ready) << canopen::to_string(remote.state()) << " failure index 0x" << std::hex
                       << remote.failure().index;
  const std::uint64_t t0 = test::monotonic_us();
  for (int k = 1; x.ready && k <= ticks; ++k) {
    const std::int32_t target = 3 * k + (k % 7);
    tick(target);
    ++x.setpoints;
    if (remote.feedback().position_actual != target) {
      ++x.setpoint_mismatches;
    }
  }
  const double seconds = static_cast<double>(test::monotonic_us() - t0) * 1e-6;
  x.cycles_per_second = seconds > 0 ? x.setpoints / seconds : 0;

  EXPECT_EQ(drive.stop(SIGTERM), 0);
  x.drive_counters = key_values(read_file(drive_out));
  // Frames still in flight when the drive stopped (its last heartbeat) belong to the log too.
  while (bus.receive(f, 20'000) == ReceiveStatus::received) {
    x.received.push_back(f);
  }
  if (!candump_log.empty()) {
    // candump logs in order: once a closing probe is in the log, so is every frame before it.
    // (A fixed sleep here lost the tail when the guest was starved of CPU.)
    CanFrame closing{};
    closing.id = probe_id;
    closing.flags = can_flag::extended;
    closing.len = 1;
    closing.data[0] = 0xEE;
    EXPECT_TRUE(wait_for_text(candump_log, "1FFFFFF0#EE", 10s, [&] { (void)out.put(closing); }))
        << "candump did not log the closing probe";
    candump.stop(SIGINT);
  }
  x.sent = out.sent;
  x.bus = bus.counters();
  return x;
}

class VcanCanopen : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::vcan_present()) {
      GTEST_SKIP() << test::vcan_missing;
    }
  }
};

TEST_F(VcanCanopen, DriveProcessIsConfiguredEnabledAndFollowsEverySetpointOnce) {
  const Exchange x = run_exchange(2000, "");
  ASSERT_TRUE(x.ready);
  EXPECT_EQ(x.setpoints, 2000);
  EXPECT_EQ(x.setpoint_mismatches, 0) << "TPDO1 position actual must equal the setpoint of the same SYNC";
  ASSERT_FALSE(x.drive_counters.empty()) << "drive process printed no counters";
  EXPECT_EQ(std::stoull(x.drive_counters.at("rpdos_applied")), x.rpdos_sent);
  EXPECT_EQ(std::stoull(x.drive_counters.at("syncs")), x.syncs_sent);
  EXPECT_EQ(x.drive_counters.at("rpdos_missing"), "0");
  EXPECT_EQ(x.drive_counters.at("rpdos_overwritten"), "0");
  EXPECT_EQ(x.drive_counters.at("rpdos_rejected"), "0");
  EXPECT_EQ(x.drive_counters.at("state"), "operation enabled");
  EXPECT_EQ(x.bus.tx_busy, 0U);
  EXPECT_EQ(x.bus.rx_overflow_drops, 0U);
  std::printf("[ vcan ] lock-step CSP cycles through two processes: %.0f per second (%d setpoints)\n",
              x.cycles_per_second, x.setpoints);
  RecordProperty("cycles_per_second", std::to_string(static_cast<long>(x.cycles_per_second)));
}

TEST_F(VcanCanopen, CandumpLogOfTheExchangeReadsBackFrameForFrame) {
  const std::string log = output_path("vcan-canopen.log");
  const Exchange x = run_exchange(300, log);
  ASSERT_TRUE(x.ready);

  std::ifstream in{log};
  std::string line;
  std::vector<CandumpRecord> records;
  int unparsed = 0;
  while (std::getline(in, line)) {
    const auto rec = parse_candump_line({line.data(), line.size()});
    if (!rec) {
      ++unparsed;
      continue;
    }
    EXPECT_STREQ(rec->iface.data(), test::vcan_interface);
    if (!(rec->frame.is_extended() && rec->frame.id == probe_id)) {
      records.push_back(*rec);
    }
  }
  EXPECT_EQ(unparsed, 0);
  // The master and the drive are the only talkers and the master hears everything the drive
  // says, so the log is exactly what the master sent plus what it received.
  const auto probes = static_cast<std::size_t>(
      std::count_if(x.sent.begin(), x.sent.end(), [](const CanFrame& f) { return f.is_extended() && f.id == probe_id; }));
  EXPECT_EQ(records.size(), x.sent.size() - probes + x.received.size());
  const auto in_order = [&records](const std::vector<CanFrame>& frames) {
    std::size_t r = 0;
    for (const CanFrame& f : frames) {
      if (f.is_extended() && f.id == probe_id) {
        continue;
      }
      while (r < records.size() && !(records[r].frame == f)) {
        ++r;
      }
      if (r == records.size()) {
        return false;
      }
      ++r;
    }
    return true;
  };
  EXPECT_TRUE(in_order(x.sent)) << "every frame the master sent is in the log, in order";
  EXPECT_TRUE(in_order(x.received)) << "every frame the master received is in the log, in order";
  for (std::size_t i = 1; i < records.size(); ++i) {
    EXPECT_LE(records[i - 1].frame.timestamp_us, records[i].frame.timestamp_us);
  }
  std::printf("[ vcan ] candump logged %zu frames to %s\n", records.size(), log.c_str());
}

TEST_F(VcanCanopen, ThroughputBothWaysUnderFlowControl) {
  constexpr unsigned long count = 20'000;
  SocketCanOptions options{};
  options.receive_buffer_bytes = 4 << 20;
  SocketCanBus bus;
  ASSERT_EQ(bus.open(test::vcan_interface, options), OpenStatus::ok);

  // Master -> peer.
  const std::string sink_out = output_path("vcan-sink.out");
  test::Child sink;
  ASSERT_TRUE(sink.start({SETTLE_HAL_VCAN_PEER, "sink", std::to_string(count)}, sink_out));
  ASSERT_TRUE(wait_for_text(sink_out, "ready", 10s));
  const test::FlowResult sent = test::send_windowed(bus, 0x123, 0x124, count);
  EXPECT_EQ(sink.wait(), 0);
  const auto sink_result = key_values(read_file(sink_out));
  EXPECT_TRUE(sent.complete);
  EXPECT_EQ(sink_result.at("frames"), std::to_string(count));
  EXPECT_EQ(sink_result.at("drops"), "0");

  // Peer -> master: the acknowledging receiver listens before the source starts.
  ASSERT_TRUE(test::listen_only_to(bus, 0x321));
  const std::string source_out = output_path("vcan-source.out");
  test::Child source;
  ASSERT_TRUE(source.start({SETTLE_HAL_VCAN_PEER, "source", std::to_string(count)}, source_out));
  const test::FlowResult received = test::receive_acking(bus, 0x321, 0x322, count);
  EXPECT_EQ(source.wait(), 0);
  const auto source_result = key_values(read_file(source_out));
  EXPECT_TRUE(received.complete);
  EXPECT_EQ(received.frames, count);
  EXPECT_EQ(bus.counters().rx_overflow_drops, 0U);

  std::printf("[ vcan ] throughput master->peer: %.0f frames/s (%lu frames, window %llu, %llu busy)\n",
              sent.frames_per_second(), count, static_cast<unsigned long long>(test::flow_window),
              static_cast<unsigned long long>(sent.busy));
  std::printf("[ vcan ] throughput peer->master: %s frames/s (%lu frames, %s busy)\n",
              source_result.at("frames_per_second").c_str(), count, source_result.at("busy").c_str());
  RecordProperty("master_to_peer_fps", std::to_string(static_cast<long>(sent.frames_per_second())));
  RecordProperty("peer_to_master_fps", source_result.at("frames_per_second"));
}

}  // namespace
}  // namespace settle::hal
