// SPDX-License-Identifier: Apache-2.0
// settle drive nmt (app/drive_nmt.hpp) against a peer on the in-process bus that the simulated
// drive never is: a node whose heartbeats go on carrying another state than the command leads to
// (exit 1, nmt_state, the state it reported named), and, as the control, the same peer obeying.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "drive_nmt.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/loopback_bus.hpp"

namespace settle::app {
namespace {

using hal::canopen::NmtCommand;
using hal::canopen::NmtState;

// The in-process bus in virtual time with one peer on it: node `node`, pre-operational, sending
// its heartbeat every 20 ms. It obeys an NMT command addressed to it only when `obeys`; otherwise
// it stays where it is and goes on saying so.
class PeerBus final : public testbed::ClockedBus {
 public:
  PeerBus(hal::canopen::NodeId node, bool obeys) : node_{node}, obeys_{obeys} { beat_.start(0); }

  [[nodiscard]] std::string name() const override { return "peer loopback"; }
  [[nodiscard]] bool realtime() const override { return false; }
  [[nodiscard]] std::string open(const testbed::StreamSpec&) override { return {}; }
  [[nodiscard]] hal::CanBus& link() override { return master_; }
  void begin() override {}
  std::uint64_t wait() override { return 0; }
  [[nodiscard]] std::uint64_t now_us() const override { return now_us_; }
  void between_ticks() override {}
  [[nodiscard]] std::string finish(const FrameTaker&) override { return {}; }
  [[nodiscard]] hal::BusCounters counters() const override { return master_.counters(); }
  [[nodiscard]] testbed::StreamTiming timing() const override { return {}; }

  // As LoopbackClockedBus: the peer takes what was sent and answers; time moves only when
  // nothing is left to take.
  [[nodiscard]] bool receive(hal::CanFrame& frame, std::uint32_t wait_us) override {
    serve();
    if (master_.receive(frame, 0) == hal::ReceiveStatus::received) return true;
    now_us_ += wait_us > 0 ? wait_us : 1;
    hub_.set_time_us(now_us_);
    serve();
    return false;
  }

  [[nodiscard]] int commands() const { return commands_; }
  [[nodiscard]] NmtState state() const { return state_; }

 private:
  void serve() {
    hal::CanFrame f{};
    while (peer_.receive(f, 0) == hal::ReceiveStatus::received) {
      const auto m = hal::canopen::decode_nmt(f);
      if (!m || m->node != node_) continue;
      ++commands_;
      if (!obeys_) continue;
      if (m->command == NmtCommand::start) state_ = NmtState::operational;
      if (m->command == NmtCommand::stop) state_ = NmtState::stopped;
      if (m->command == NmtCommand::enter_pre_operational) state_ = NmtState::pre_operational;
    }
    (void)beat_.poll(now_us_, state_, peer_);
  }

  hal::canopen::NodeId node_;
  bool obeys_;
  NmtState state_{NmtState::pre_operational};
  int commands_{0};
  std::uint64_t now_us_{0};
  hal::LoopbackHub hub_;
  hal::LoopbackBus<256> master_{hub_};
  hal::LoopbackBus<256> peer_{hub_};
  hal::canopen::HeartbeatProducer beat_{node_, 20};
};

struct Ran {
  int status;
  std::string out;
  std::string err;
};

std::string contents(std::FILE* f) {
  std::rewind(f);
  std::string s;
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) s.append(buf, n);
  std::fclose(f);
  return s;
}

Ran run(PeerBus& bus, const std::string& word, bool json) {
  std::FILE* out = std::tmpfile();
  std::FILE* err = std::tmpfile();
  if (out == nullptr || err == nullptr) return {-1, {}, {}};
  const int status = run_drive_nmt(bus, {5, word, 300'000, json, "peer"}, out, err);
  return {status, contents(out), contents(err)};
}

TEST(DriveNmt, HeartbeatsOfAnotherStateExitOneNamingTheState) {
  PeerBus bus{5, false};
  const Ran t = run(bus, "stop", false);
  EXPECT_EQ(t.status, 1) << t.out << t.err;
  EXPECT_EQ(bus.commands(), 1) << "the command went out once, to node 5";
  EXPECT_TRUE(t.out.empty()) << t.out;
  EXPECT_EQ(t.err, "settle drive nmt: node 5: its heartbeat says pre-operational, not stopped, 300 ms after NMT stop\n");
  PeerBus again{5, false};
  const Ran j = run(again, "start", true);
  EXPECT_EQ(j.status, 1) << j.out << j.err;
  EXPECT_TRUE(j.err.empty()) << j.err;
  EXPECT_EQ(j.out, "{\"status\":\"error\",\"error\":\"nmt_state\",\"message\":\"node 5: its heartbeat says pre-operational, "
                   "not operational, 300 ms after NMT start\",\"node\":5,\"command\":\"start\",\"state\":\"pre-operational\"}\n");
}

// The control: the same peer, obeying, is confirmed within one heartbeat period (exit 0).
TEST(DriveNmt, ThePeerObeyingIsConfirmed) {
  PeerBus bus{5, true};
  const Ran t = run(bus, "stop", false);
  EXPECT_EQ(t.status, 0) << t.out << t.err;
  EXPECT_EQ(bus.state(), NmtState::stopped);
  EXPECT_EQ(t.out.rfind("node 5: NMT stop sent; its heartbeat says stopped (after ", 0), 0u) << t.out;
  EXPECT_TRUE(t.err.empty()) << t.err;
}

}  // namespace
}  // namespace settle::app
