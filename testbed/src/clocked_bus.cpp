// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/clocked_bus.hpp"

#include <algorithm>
#include <utility>

#include "settle/hal/canopen/heartbeat.hpp"

namespace settle::testbed {

std::size_t take_late_frames(hal::CanBus& bus, const std::function<std::uint64_t()>& now_us,
                             const ClockedBus::FrameTaker& take, LateFrameWindow window) {
  const std::uint64_t start = now_us();
  std::uint64_t last = start;  // the last frame that was not a heartbeat (or the start)
  std::size_t taken = 0;
  while (taken < window.max_frames) {
    const std::uint64_t now = now_us();
    const std::uint64_t quiet_left = now - last >= window.quiet_us ? 0 : window.quiet_us - (now - last);
    const std::uint64_t limit_left = now - start >= window.limit_us ? 0 : window.limit_us - (now - start);
    // 0 once the window has closed: then only what is already queued is taken. A process held off
    // the CPU past the window (a loaded host) finds its late TPDOs waiting and must read them.
    const std::uint64_t wait = std::min(quiet_left, limit_left);
    hal::CanFrame f{};
    if (bus.receive(f, static_cast<std::uint32_t>(wait)) != hal::ReceiveStatus::received) return taken;
    const std::uint64_t at = now_us();
    take(f, at);
    ++taken;
    if (!hal::canopen::decode_heartbeat(f)) last = at;
  }
  return taken;
}

// ---- the in-process bus, in virtual time ----

LoopbackClockedBus::LoopbackClockedBus(std::string candump_path) : candump_path_{std::move(candump_path)} {}

LoopbackClockedBus::~LoopbackClockedBus() = default;

std::string LoopbackClockedBus::open(const StreamSpec& spec) {
  std::vector<SimulatedDriveSpec> drives;
  for (const StreamAxis& axis : spec.axes) {
    SimulatedDriveSpec ds{};
    ds.node = axis.node;
    ds.eds = spec.eds.get();
    ds.axis = spec.drive;
    ds.plant = spec.plant;
    ds.sync_period_us = spec.drive.scale.period_us;
    // The drive the user says they have: its load position where --load-feedback names it.
    ds.load_position = spec.load_feedback.served_at();
    drives.push_back(std::move(ds));
  }
  return open(spec.drive.scale.period_us, drives);
}

std::string LoopbackClockedBus::open(std::uint32_t period_us, const std::vector<SimulatedDriveSpec>& drives) {
  period_us_ = period_us;
  now_us_ = 0;
  if (!candump_path_.empty() && !dump_.open(candump_path_.c_str(), "loopback")) {
    return "cannot write " + candump_path_;
  }
  drives_.clear();
  for (const SimulatedDriveSpec& ds : drives) {
    SimulatedDriveError error;
    SimulatedDrive built = build_simulated_drive(ds, error);
    if (!error.eds.empty()) return "--eds: " + error.eds;
    if (error.any()) return error.message();
    Drive d{std::make_unique<hal::LoopbackBus<256>>(hub_), std::move(built)};
    d.drive.node->start(0, *d.port);
    drives_.push_back(std::move(d));
  }
  return {};
}

void LoopbackClockedBus::begin() { hub_.set_time_us(period_us_); }  // the first tick

void LoopbackClockedBus::serve_drives(std::uint64_t now) {
  hal::CanFrame f{};
  for (Drive& d : drives_) {
    while (d.port->receive(f, 0) == hal::ReceiveStatus::received) (void)d.drive.node->on_frame(f, now, *d.port);
    d.drive.node->poll(now, *d.port);
  }
  // A listening port sees every frame on the in-process bus: the run's candump log.
  while (sniffer_.receive(f, 0) == hal::ReceiveStatus::received) {
    if (dump_.is_open()) (void)dump_.write(f);
  }
}

void LoopbackClockedBus::between_ticks() {
  hub_.set_time_us(now_us_);  // the drive answers within this period
  serve_drives(now_us_);
  hub_.set_time_us(now_us_ + period_us_);  // the loop's next tick sends at that time
}

// Time moves only when nothing is left to take.
bool LoopbackClockedBus::receive(hal::CanFrame& frame, std::uint32_t wait_us) {
  serve_drives(now_us_);
  if (master_.receive(frame, 0) == hal::ReceiveStatus::received) return true;
  now_us_ += std::max<std::uint32_t>(wait_us, 1);
  hub_.set_time_us(now_us_);
  for (Drive& d : drives_) d.drive.node->poll(now_us_, *d.port);
  return false;
}

std::string LoopbackClockedBus::finish(const FrameTaker& /*take*/) {
  // The drive answered within each tick's period: nothing is still on its way.
  if (dump_.is_open() && !dump_.close()) return "the candump log " + candump_path_ + " is incomplete";
  return {};
}

// ---- a SocketCAN interface, in real time ----

SocketCanClockedBus::SocketCanClockedBus(hal::SocketCanBus& opened, std::string interface, std::string candump_path,
                                       int rt_priority, bool pm_qos)
    : bus_{opened},
      interface_{std::move(interface)},
      candump_path_{std::move(candump_path)},
      rt_priority_{rt_priority},
      pm_qos_{pm_qos} {}

SocketCanClockedBus::~SocketCanClockedBus() = default;

hal::CanBus& SocketCanClockedBus::link() {
  return recorder_ ? static_cast<hal::CanBus&>(*recorder_) : static_cast<hal::CanBus&>(bus_);
}

std::string SocketCanClockedBus::open(const StreamSpec& spec) {
  if (!candump_path_.empty()) {
    if (!dump_.open(candump_path_.c_str(), interface_.c_str())) return "cannot write " + candump_path_;
    recorder_ = std::make_unique<hal::RecordingBus<4096>>(bus_, hal::realtime_us);
  }
  if (rt_priority_ > 0) realtime_ = runtime::linux_rt::request_realtime(rt_priority_);
  if (pm_qos_) {
    cpu_latency_.emplace();
    realtime_.pm_qos = cpu_latency_->held();
    realtime_.pm_qos_error = cpu_latency_->error();
  } else {
    realtime_.pm_qos_error = "off";
  }
  timer_.emplace(spec.drive.scale.period_us);
  return {};
}

void SocketCanClockedBus::begin() { timer_->start(); }

std::uint64_t SocketCanClockedBus::now_us() const {
  return timer_ ? timer_->now_us() : runtime::linux_rt::monotonic_ns() / 1000;
}

// Written between ticks: the recorder's ring is bounded.
void SocketCanClockedBus::between_ticks() {
  if (dump_.is_open()) (void)dump_.write_records(*recorder_);
}

std::string SocketCanClockedBus::finish(const FrameTaker& take) {
  // The time now, not the timer's period start: that stopped with the session's last wait (and a
  // wait on it here would stretch every frame to a period). On a clock that stood still, three
  // drives' heartbeats kept this waiting for ever, once in a CI run and in five of six runs of
  // the e2e axes tests in one guest.
  const auto now_us = [] { return runtime::linux_rt::monotonic_ns() / 1000; };
  (void)take_late_frames(link(), now_us, [&](const hal::CanFrame& f, std::uint64_t at_us) {
    take(f, at_us);
    between_ticks();
  });
  if (dump_.is_open() && !(dump_.write_records(*recorder_) && dump_.close())) {
    return "the candump log " + candump_path_ + " is incomplete (" + std::to_string(dump_.records_lost()) +
           " records lost or unwritten)";
  }
  return {};
}

StreamTiming SocketCanClockedBus::timing() const {
  StreamTiming t{};
  t.realtime = realtime_;
  if (timer_) {
    t.latency = timer_->latency();
    t.overruns = timer_->overruns();
  }
  return t;
}

}  // namespace settle::testbed
