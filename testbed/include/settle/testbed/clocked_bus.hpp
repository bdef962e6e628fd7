// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one bus with a clock (ClockedBus) and its two kinds: where a stream runs and where
// `settle drive` talks to a drive. LoopbackClockedBus: simulated drives (build_simulated_drive) on
// the in-process bus, in virtual time, deterministic. SocketCanClockedBus: a SocketCAN interface
// (vcan0, can0) in real time, against a `settle plant` process or a drive. Either can write a
// candump log of a stream (`candump -l` format, replayable with canplayer).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "settle/runtime/linux/periodic.hpp"
#include "settle/runtime/session.hpp"
#include "settle/hal/candump_file.hpp"
#include "settle/hal/recording_bus.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "settle/testbed/simulated_drive.hpp"
#include "settle/testbed/stream.hpp"

namespace settle::testbed {

// The one bus with a clock: where a stream runs (the link the loop sends and receives on, the clock
// that paces its ticks, and what happens on the bus between ticks) and where `settle drive`'s SDO
// transfers run (receive()). LoopbackClockedBus and SocketCanClockedBus (below) are the
// two; nothing here allocates between begin() and finish().
class ClockedBus {
 public:
  ClockedBus() = default;
  ClockedBus(const ClockedBus&) = delete;
  ClockedBus& operator=(const ClockedBus&) = delete;
  virtual ~ClockedBus() = default;

  // As the report names it.
  [[nodiscard]] virtual std::string name() const = 0;
  // A real-time clock (its timing is reported) rather than a virtual one.
  [[nodiscard]] virtual bool realtime() const = 0;
  // Everything the run needs, before the loop exists: "" or why not (a one-line message).
  [[nodiscard]] virtual std::string open(const StreamSpec& spec) = 0;
  [[nodiscard]] virtual hal::CanBus& link() = 0;
  // Right before the first tick.
  virtual void begin() = 0;
  // The session's clock (runtime::run_session's Clock).
  virtual std::uint64_t wait() = 0;
  [[nodiscard]] virtual std::uint64_t now_us() const = 0;
  // After every tick, within its period.
  virtual void between_ticks() = 0;
  // After the session: frames still on their way go to `take`; "" or why the run's records are
  // incomplete.
  using FrameTaker = std::function<void(const hal::CanFrame& frame, std::uint64_t now_us)>;
  [[nodiscard]] virtual std::string finish(const FrameTaker& take) = 0;
  // Request and answer, unpaced (settle drive's SDO transfers): the next frame that arrives within
  // wait_us, the clock running meanwhile (loopback: after the drives have taken what was sent and
  // answered; when nothing comes, virtual time moves on by wait_us). False when none came.
  [[nodiscard]] virtual bool receive(hal::CanFrame& frame, std::uint32_t wait_us) {
    return link().receive(frame, wait_us) == hal::ReceiveStatus::received;
  }
  // This side's bus counters (the controller's, not a recorder's).
  [[nodiscard]] virtual hal::BusCounters counters() const = 0;
  [[nodiscard]] virtual StreamTiming timing() const = 0;
};

// How long a session's end waits for frames still on their way (the last TPDOs answer the last
// SYNC within a period; a drive on a loaded host can be seconds behind). Waiting stops after
// `quiet_us` without a frame that is not a heartbeat (the drives' heartbeats go on for ever:
// several drives' together can leave no gap at all), in every case after `limit_us` (a peer that
// never falls silent cannot hold the master), and after `max_frames` (a bound that holds even on
// a clock that does not move: 8-byte frames at 1 Mbit/s, about 8000 a second, fill it in about
// 8 s, longer than the limit). Frames already
// queued when the window closes are still taken (up to max_frames): a process held off the CPU
// past the window finds its late feedback waiting.
struct LateFrameWindow {
  std::uint32_t quiet_us{50'000};
  std::uint32_t limit_us{5'000'000};
  std::size_t max_frames{65'536};
};

// Takes the late frames from `bus` into `take` within `window`; returns how many it took. now_us:
// the time now, a clock that runs on its own (not one that moves by periods, such as
// PeriodicTimer::now_us, which stands still once the session stops waiting on it).
std::size_t take_late_frames(hal::CanBus& bus, const std::function<std::uint64_t()>& now_us,
                             const ClockedBus::FrameTaker& take, LateFrameWindow window = {});

// On loopback every axis of the spec has its drive in this process.
class LoopbackClockedBus final : public ClockedBus {
 public:
  // candump_path: where to log every frame on the bus (a listening port sees them all); "" none.
  explicit LoopbackClockedBus(std::string candump_path = {});
  ~LoopbackClockedBus() override;

  [[nodiscard]] std::string name() const override { return "loopback (in-process, virtual time)"; }
  [[nodiscard]] bool realtime() const override { return false; }
  // One simulated drive per axis of the spec, each with the spec's plant and drive model.
  [[nodiscard]] std::string open(const StreamSpec& spec) override;
  // The drives given (each on its own port of the hub), the clock pacing `period_us`; "" or why a
  // drive cannot be built (a description's error prefixed "--eds: ").
  [[nodiscard]] std::string open(std::uint32_t period_us, const std::vector<SimulatedDriveSpec>& drives);
  [[nodiscard]] hal::CanBus& link() override { return master_; }
  void begin() override;
  std::uint64_t wait() override {
    now_us_ += period_us_;
    return 0;
  }
  [[nodiscard]] std::uint64_t now_us() const override { return now_us_; }
  void between_ticks() override;
  [[nodiscard]] bool receive(hal::CanFrame& frame, std::uint32_t wait_us) override;
  [[nodiscard]] std::string finish(const FrameTaker& take) override;
  [[nodiscard]] hal::BusCounters counters() const override { return master_.counters(); }
  [[nodiscard]] StreamTiming timing() const override { return {}; }

 private:
  std::string candump_path_;
  hal::LoopbackHub hub_;
  hal::LoopbackBus<256> master_{hub_};
  hal::LoopbackBus<256> sniffer_{hub_};
  // One simulated drive per axis (--axes N: one per node), each on its own port of the hub and
  // with its own copy of the plant.
  struct Drive {
    std::unique_ptr<hal::LoopbackBus<256>> port;
    SimulatedDrive drive;
  };
  std::vector<Drive> drives_;
  hal::CandumpFile dump_;
  std::uint32_t period_us_{1000};
  std::uint64_t now_us_{0};  // virtual time

  // Every drive takes what was sent to it and answers at `now`; the sniffer's frames go to the log.
  void serve_drives(std::uint64_t now);
};

class SocketCanClockedBus final : public ClockedBus {
 public:
  // `opened`: the interface, already open (it must outlive this). Without open() (settle drive's
  // transfers: receive() and now_us()) nothing else is set up. rt_priority 1..99 asks for
  // SCHED_FIFO (and locked memory) at open; 0 runs as scheduled. candump_path: this process's own
  // log of every frame it sends and receives (complete, unlike a sniffer's: its line count equals
  // frames_sent + frames_received); "" none. pm_qos: hold /dev/cpu_dma_latency at 0 µs from open
  // to destruction (CpuLatencyRequest; reported in timing().realtime, not fatal when refused).
  SocketCanClockedBus(hal::SocketCanBus& opened, std::string interface, std::string candump_path = {},
                     int rt_priority = 0, bool pm_qos = true);
  ~SocketCanClockedBus() override;

  [[nodiscard]] std::string name() const override { return interface_; }
  [[nodiscard]] bool realtime() const override { return true; }
  [[nodiscard]] std::string open(const StreamSpec& spec) override;
  [[nodiscard]] hal::CanBus& link() override;
  void begin() override;
  std::uint64_t wait() override { return timer_->wait(); }
  // The timer's period start once open() made it, else the monotonic clock (settle drive).
  [[nodiscard]] std::uint64_t now_us() const override;
  void between_ticks() override;
  [[nodiscard]] std::string finish(const FrameTaker& take) override;
  [[nodiscard]] hal::BusCounters counters() const override { return bus_.counters(); }
  [[nodiscard]] StreamTiming timing() const override;

 private:
  hal::SocketCanBus& bus_;
  std::string interface_;
  std::string candump_path_;
  int rt_priority_;
  bool pm_qos_;
  std::unique_ptr<hal::RecordingBus<4096>> recorder_;  // only with a candump log
  std::optional<runtime::linux_rt::CpuLatencyRequest> cpu_latency_;
  hal::CandumpFile dump_;
  std::optional<runtime::linux_rt::PeriodicTimer> timer_;
  runtime::linux_rt::RealtimeSetup realtime_{};
};

}  // namespace settle::testbed
