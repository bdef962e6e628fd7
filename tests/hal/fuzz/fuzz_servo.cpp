// SPDX-License-Identifier: Apache-2.0
// libFuzzer harness: the master (firmware ServoLoop + hal RemoteDrive) against the drive (hal
// DriveNode + an ideal plant behind it) over the in-process bus, each side behind hal's
// FaultInjectingBus, in virtual time. The input chooses the move and, tick by tick, what goes
// wrong: frames dropped, refused (busy/error), delayed, duplicated or reordered in either
// direction, and a third node's frames (NMT, SYNC, RPDOs and TPDOs, SDO requests, EMCY,
// heartbeats, garbage) injected before the master's tick, after it, or just before its SYNC.
//
// Invariants, checked on every tick (a violation prints which and aborts, so libFuzzer keeps
// the input):
//  (a) the drive's position never steps more than its limit: per SYNC, and per period of
//      virtual time (two SYNCs in one period must not make two steps). The limit is defined
//      once, in limits_for().
//  (b) master: an RPDO is sent with a new target only while the master's view of the drive is
//      operation enabled (RemoteDrive::ready()); before, the only RPDOs are the enable sequence's,
//      whose target is the position the master last received.
//      drive: a SYNC moves the axis only when the drive was operation enabled before that SYNC
//      (so the SYNC that enables the drive never moves it).
//  (c) a move the loop reports completed ended at its target: its final setpoint is the move's
//      target (origin + distance, in counts), and once the bus has been quiet for kSettleTicks
//      with no third-party frame since the report, while the loop is idle and ready, the
//      drive's position is within one count of it.
// Deterministic: virtual time only; the only randomness is the fault double's generator,
// seeded from the input.
//
// Input (bytes past the end read as zero):
//   header, 14 bytes:
//     h0      bits 0-1 profile (0, 3 scurve; 1 poly345; 2 ramp-versine), bit 2 interpolated
//             position instead of CSP, bit 3 drive following-error window on, bit 4 master
//             watches the drive's heartbeat, bit 5 drive's 0x6007 = quick stop instead of fault
//     h1..h2  distance = int16 LE / 32768 * 0.25 units (m)
//     h3      time = 0.03 + h3 * 0.001 s;  h4 omega = 10 + h4 * 0.25 rad/s (a move core refuses,
//             or whose peak velocity is over kMaxPeakVelocity, is not submitted: no move)
//     h5      tick at which the move is submitted
//     h6..h9  seed of the fault double's random mode;  h10..h13 drive's initial position (i32 LE)
//   then events, 4 bytes each [ticks after the previous event] [op] [a] [b]; the injecting ops
//   take 4 more bytes [e0..e3]. See apply() for the ops and inject_frame() for the frames.
//   servo_input.py writes inputs from a readable description (and the seed corpus); to read what
//   an input does, run the harness on it with FUZZ_SERVO_TRACE=1 (2: every SYNC too).
// After the last event every fault is cleared and the run goes on quietly for kTailTicks.
// regressions/ holds one minimised input per violation found; fuzz.cmake says which are expected
// to fail until their fix is merged.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>

#include "settle/core/planner.hpp"
#include "settle/runtime/servo_loop.hpp"
#include "settle/hal/can_bus.hpp"
#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/default_mapping.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/canopen/emcy.hpp"
#include "settle/hal/canopen/heartbeat.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sync.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/testing/fault_injecting_bus.hpp"

namespace {

using namespace settle;
using namespace settle::hal;
using namespace settle::hal::canopen;

constexpr std::uint32_t kPeriodUs = 1000;
constexpr double kCountsPerUnit = 1e6;
constexpr NodeId kDrive = 1;
constexpr std::size_t kMaxEvents = 128;
constexpr std::uint64_t kMaxEventTick = 1200;
constexpr std::uint64_t kSettleTicks = 30;  // quiet ticks before (c) is judged: > every delay
constexpr std::uint64_t kTailTicks = 250;   // quiet ticks after the last event (and the move)
constexpr std::size_t kMaxDriveFramesPerTick = 64;
// The valid moves: planned by core and no faster than this (units/s). A planned move of a few
// centimetres in 30 ms designed for a slow mode peaks at thousands of m/s, and its step limit
// would then let any hostile step through.
constexpr double kMaxPeakVelocity = 5.0;

std::uint64_t g_tick = 0;  // for the messages
// FUZZ_SERVO_TRACE=1 in the environment: a line per event and per change of state, to read what
// a (minimised) input does. Output only; it changes nothing the run does.
const int g_trace = std::getenv("FUZZ_SERVO_TRACE") != nullptr ? std::atoi(std::getenv("FUZZ_SERVO_TRACE")) : 0;
// Triage aid, never set by the tests: FUZZ_SERVO_EMULATE=<bits> makes the plant behave as the
// fixed drive will, so that a campaign finds the other defects instead of these again:
// 1 = refuse (fault) a step over the limit (item 7), 2 = hold at the enabling SYNC (item 6),
// 4 = ignore a second SYNC within one period (item 8), 8 = judge (c) only while the drive is
// operational and following (hides items 9 and 10: a drive stopped behind the master's back).
const unsigned g_emulate = std::getenv("FUZZ_SERVO_EMULATE") != nullptr
                               ? static_cast<unsigned>(std::atoi(std::getenv("FUZZ_SERVO_EMULATE")))
                               : 0U;
#define TRACE(...)                                                                        \
  do {                                                                                    \
    if (g_trace > 0) {                                                                    \
      std::fprintf(stderr, "[%5llu] ", static_cast<unsigned long long>(g_tick));          \
      std::fprintf(stderr, __VA_ARGS__);                                                  \
      std::fputc('\n', stderr);                                                           \
    }                                                                                     \
  } while (false)

[[noreturn]] void violated(const char* invariant, const char* what, long long got, long long bound) {
  std::fprintf(stderr, "fuzz_servo: invariant (%s) violated at tick %llu: %s (%lld vs %lld)\n", invariant,
               static_cast<unsigned long long>(g_tick), what, got, bound);
  std::abort();
}

// |a - b| on the wrapping int32 count scale (the shorter way round).
std::uint32_t distance_counts(std::int32_t a, std::int32_t b) {
  const std::uint32_t d = static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b);
  return d <= 0x8000'0000U ? d : 0U - d;
}

std::int32_t wrap_add(std::int32_t a, std::int64_t b) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) + static_cast<std::uint32_t>(static_cast<std::uint64_t>(b)));
}

// ---- (a)'s bound: the ONE place it is defined. ----
// Today's DriveNode has no max profile velocity (0x607F) and no step limit of its own, so the
// drive's limit is taken to be the planned move's true peak velocity times kVelocityMargin.
// The same velocity is the axis's vmax (so the loop's own step guard allows exactly the moves
// that respect it). Once DriveNode has 0x607F: write limit.velocity * kCountsPerUnit (counts/s)
// to it in drive_config() and keep step_counts as the bound (it rounds up, plus two counts, so
// it is never tighter than a drive that rounds its own limit either way). The harness already
// writes 0x607F into the drive's dictionary (configure_drive_limit()); today's drive has no such
// object and refuses the write, a drive that has it enforces the same limit.
constexpr std::uint16_t kMaxProfileVelocity = 0x607F;  // CiA 402, u32, counts/s
constexpr double kVelocityMargin = 1.25;
constexpr double kMinLimitVelocity = 0.01;  // units/s, when there is no move

struct Limits {
  double velocity{kMinLimitVelocity};  // units/s: the axis's vmax and the drive's limit
  std::uint32_t step_counts{0};        // the most the drive's position may change per period
};

Limits limits_for(double peak_velocity) {
  Limits l{};
  l.velocity = std::max(peak_velocity * kVelocityMargin, kMinLimitVelocity);
  const double per_period = l.velocity * kCountsPerUnit * kPeriodUs * 1e-6;
  l.step_counts = static_cast<std::uint32_t>(std::ceil(per_period)) + 2U;
  return l;
}

// ---- input ----
class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_{data}, size_{size} {}
  std::uint8_t u8() { return pos_ < size_ ? data_[pos_++] : (++pos_, std::uint8_t{0}); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(u8() | (u8() << 8U)); }
  std::uint32_t u32() { return u16() | (static_cast<std::uint32_t>(u16()) << 16U); }
  [[nodiscard]] bool more() const { return pos_ < size_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_{0};
};

enum Op : std::uint8_t {
  op_target,        // a&1 side, filter (a>>1): which frames that side's fault double touches
  op_drop_tx,       // side a&1: the next b%16+1 matching sends vanish (reported sent)
  op_drop_rx,       // ... receives vanish
  op_fail_tx,       // ... sends answered busy (a&2: error)
  op_delay_tx,      // side a&1: matching sends wait (b%41) * 250 µs
  op_delay_rx,      // ... receives wait
  op_random,        // side a&1: random busy/drop rates from b, seeded from the header and tick
  op_clear,         // a%3: master side, drive side, both: every fault off
  op_dup_rx,        // side a&1, filter (a>>1): the next b%8+1 matching receives arrive twice
  op_dup_tx,        // ... sends go out twice
  op_reorder_rx,    // ... the next b%8+1 matching receives swap with the frame after them
  op_reorder_tx,    // ... the next b%8+1 matching sends go out after the next send
  op_inject_before, // a third node sends a frame before the master's tick
  op_inject_after,  // ... after the master's tick, before the drive runs
  op_inject_sync,   // ... just before the master's next SYNC (between its RPDO and SYNC)
  op_count,
};

struct Event {
  std::uint64_t tick{0};
  std::uint8_t op{0};
  std::uint8_t a{0};
  std::uint8_t b{0};
  std::array<std::uint8_t, 4> e{};
};

// Which frames a fault touches: every frame, or one kind of the drive's / the master's traffic.
std::optional<CanFilter> filter_for(std::uint8_t index) {
  constexpr std::array<std::uint32_t, 9> ids{
      cob::sync, cob::rpdo1 + kDrive, cob::tpdo1 + kDrive, cob::tpdo2 + kDrive, cob::heartbeat + kDrive,
      cob::sdo_rx + kDrive, cob::sdo_tx + kDrive, cob::nmt, cob::emcy + kDrive};
  const std::size_t i = index % (ids.size() + 1);
  if (i == ids.size()) return std::nullopt;
  return CanFilter{ids[i], 0x7FF, FrameFormat::standard};
}

// ---- the adapter: duplicates and reorders (which the fault double does not), records what the
// master sends, and can slip a third node's frame in just before the master's SYNC. ----
class HarnessBus final : public CanBus {
 public:
  explicit HarnessBus(CanBus& inner) noexcept : inner_{inner} {}

  void set_filter(std::optional<CanFilter> f) { filter_ = f; }
  void duplicate_sends(std::uint32_t n) { dup_tx_ = n; }
  void duplicate_receives(std::uint32_t n) { dup_rx_ = n; }
  void reorder_sends(std::uint32_t n) { reorder_tx_ = n; }
  void reorder_receives(std::uint32_t n) { reorder_rx_ = n; }
  void clear() {
    filter_.reset();
    dup_tx_ = dup_rx_ = reorder_tx_ = reorder_rx_ = 0;
  }
  // Sends a frame held back for reordering that nothing overtook this tick.
  void flush() {
    if (held_tx_) {
      (void)inner_.send(*held_tx_);
      held_tx_.reset();
    }
  }
  [[nodiscard]] bool quiet() const {
    return dup_tx_ == 0 && dup_rx_ == 0 && reorder_tx_ == 0 && reorder_rx_ == 0 && !held_tx_ && !stash_ &&
           !inject_;
  }

  // The master's side: check every RPDO it sends against its view of the drive (invariant b).
  void observe(const RemoteDrive* view) { view_ = view; }
  void inject_before_sync(const CanFrame& f, CanBus& foreign) {
    inject_ = f;
    foreign_ = &foreign;
  }

 private:
  [[nodiscard]] bool targeted(const CanFrame& f) const { return !filter_ || matches(*filter_, f); }

  SendStatus do_send(const CanFrame& frame) noexcept override {
    if (view_ != nullptr && frame.id == cob::sync && frame.len <= 1 && frame.flags == 0 && inject_) {
      (void)foreign_->send(*inject_);
      inject_.reset();
    }
    if (view_ != nullptr) check_master_rpdo(frame);
    const bool t = targeted(frame);
    if (t && reorder_tx_ > 0 && !held_tx_) {
      --reorder_tx_;
      held_tx_ = frame;
      return SendStatus::sent;
    }
    const SendStatus st = inner_.send(frame);
    flush();  // the held frame goes out after the one that overtook it
    if (t && st == SendStatus::sent && dup_tx_ > 0) {
      --dup_tx_;
      (void)inner_.send(frame);
    }
    return st;
  }

  ReceiveStatus do_receive(CanFrame& frame, std::uint32_t /*timeout_us*/) noexcept override {
    if (stash_) {
      frame = *stash_;
      stash_.reset();
      return ReceiveStatus::received;
    }
    const ReceiveStatus st = inner_.receive(frame, 0);
    if (st != ReceiveStatus::received) return st;
    if (targeted(frame) && dup_rx_ > 0) {
      --dup_rx_;
      stash_ = frame;
    } else if (targeted(frame) && reorder_rx_ > 0) {
      CanFrame next{};
      if (inner_.receive(next, 0) == ReceiveStatus::received) {
        --reorder_rx_;
        stash_ = frame;
        frame = next;
      }
    }
    return ReceiveStatus::received;
  }

  BusStatus do_set_filters(std::span<const CanFilter> filters) noexcept override { return inner_.set_filters(filters); }

  void check_master_rpdo(const CanFrame& frame) const {
    const auto rpdo = decode_rpdo1(frame, kDrive);
    if (!rpdo || view_->ready()) return;
    // Not operation enabled as the master knows it: only the enable sequence may speak, and it
    // holds the drive where the master last saw it.
    if (view_->state() != RemoteDriveState::enabling) {
      violated("b", "the master sent an RPDO while neither enabling nor ready", static_cast<long long>(view_->state()), 0);
    }
    if (rpdo->target_position != view_->feedback().position_actual) {
      violated("b", "the master streamed a new target to a drive it did not know operation enabled",
               rpdo->target_position, view_->feedback().position_actual);
    }
  }

  CanBus& inner_;
  std::optional<CanFilter> filter_{};
  std::uint32_t dup_tx_{0};
  std::uint32_t dup_rx_{0};
  std::uint32_t reorder_tx_{0};
  std::uint32_t reorder_rx_{0};
  std::optional<CanFrame> held_tx_{};
  std::optional<CanFrame> stash_{};
  const RemoteDrive* view_{nullptr};
  std::optional<CanFrame> inject_{};
  CanBus* foreign_{nullptr};
};

struct Scenario {
  std::uint8_t flags{0};
  core::MoveRequest request{};
  std::optional<core::Move<double>> move{};
  Limits limits{};
  std::uint64_t submit_tick{0};
  std::uint32_t seed{0};
  std::int32_t start_position{0};
  std::array<Event, kMaxEvents> events{};
  std::size_t event_count{0};
};

DriveNodeConfig drive_config(const Scenario& s) {
  DriveNodeConfig c{};
  c.node = kDrive;
  if ((s.flags & 0x08U) != 0) {
    c.following_error_window = 1000;
    c.following_error_timeout_ms = 0;
  }
  if ((s.flags & 0x20U) != 0) c.abort_connection_option = 3;  // quick stop
  // (a): once DriveNode has 0x607F, set it here to s.limits.velocity * kCountsPerUnit.
  return c;
}

runtime::AxisConfig axis_config(const Scenario& s) {
  runtime::AxisConfig a{};
  a.drive.node = kDrive;
  a.drive.mode = (s.flags & 0x04U) != 0 ? OperationMode::interpolated_position : OperationMode::cyclic_synchronous_position;
  a.drive.heartbeat_timeout_ms = (s.flags & 0x10U) != 0 ? 350 : 0;
  a.scale = {kCountsPerUnit, kPeriodUs};
  a.vmax = s.limits.velocity;
  return a;
}

bool parse(const std::uint8_t* data, std::size_t size, Scenario& s) {
  Reader r{data, size};
  s.flags = r.u8();
  const auto raw_distance = static_cast<std::int16_t>(r.u16());
  const std::uint8_t time = r.u8();
  const std::uint8_t omega = r.u8();
  s.submit_tick = r.u8();
  s.seed = r.u32();
  s.start_position = static_cast<std::int32_t>(r.u32());

  core::MoveRequest& q = s.request;
  double zeta = 0.0;
  switch (s.flags & 0x03U) {
    case 1: q.profile = core::ProfileKind::poly345; break;
    case 2: q.profile = core::ProfileKind::ramp_versine; zeta = 0.1; break;
    default: q.profile = core::ProfileKind::scurve; break;
  }
  q.distance = raw_distance / 32768.0 * 0.25;
  q.time = 0.03 + time * 0.001;
  q.set_mode(10.0 + omega * 0.25, zeta);
  core::Move<double> m{};
  if (core::plan(q, m) == core::Status::ok && std::isfinite(m.peaks().v) && m.peaks().v > 0.0 &&
      m.peaks().v <= kMaxPeakVelocity) {
    s.move = m;
  }
  s.limits = limits_for(s.move ? s.move->peaks().v : 0.0);

  std::uint64_t tick = 0;
  while (r.more() && s.event_count < kMaxEvents) {
    Event e{};
    tick += r.u8();
    e.tick = tick;
    e.op = static_cast<std::uint8_t>(r.u8() % op_count);
    e.a = r.u8();
    e.b = r.u8();
    if (e.op == op_inject_before || e.op == op_inject_after || e.op == op_inject_sync) {
      for (auto& x : e.e) x = r.u8();
    }
    if (tick > kMaxEventTick) break;
    s.events[s.event_count++] = e;
  }
  return true;
}

// A third node's frame, built from an injecting event; `position` is where the drive stands,
// so that spoofed targets and feedback can be near it as well as far.
CanFrame inject_frame(const Event& ev, std::int32_t position) {
  const std::uint8_t b = ev.b;
  const auto& e = ev.e;
  const auto near = [&](std::int32_t at) {
    // A step of any size: a signed 16-bit mantissa shifted by 0..15.
    const auto mant = static_cast<std::int16_t>(e[0] | (e[1] << 8U));
    return wrap_add(at, static_cast<std::int64_t>(mant) * (std::int64_t{1} << (e[2] % 16U)));
  };
  const auto absolute = static_cast<std::int32_t>(e[0] | (std::uint32_t{e[1]} << 8U) | (std::uint32_t{e[2]} << 16U) |
                                                  (std::uint32_t{e[3]} << 24U));
  const std::uint8_t other = static_cast<std::uint8_t>(2 + e[3] % 126);
  CanFrame f{};
  switch (ev.a % 12U) {
    case 0: {  // NMT to the drive, to all, or to another node
      constexpr std::array<std::uint8_t, 6> cmds{0x01, 0x02, 0x80, 0x81, 0x82, 0x00};
      std::uint8_t cmd = cmds[b % cmds.size()];
      if (cmd == 0x00) cmd = e[0];
      const std::array<std::uint8_t, 4> nodes{kDrive, 0, other, e[1]};  // the drive, all, another, any
      const std::uint8_t node = nodes[(b >> 3U) & 3U];
      f.id = cob::nmt;
      f.len = 2;
      f.data[0] = cmd;
      f.data[1] = node;
      break;
    }
    case 1:  // SYNC, with or without a counter
      f.id = cob::sync;
      f.len = (b & 1U) != 0 ? 1 : 0;
      f.data[0] = e[0];
      break;
    case 2: {  // RPDO1 to the drive: any controlword, a target near or far
      constexpr std::array<std::uint16_t, 7> cws{0x0F, 0x1F, 0x06, 0x07, 0x00, 0x80, 0x02};
      const std::uint16_t cw = (b % 8U) == 7U ? static_cast<std::uint16_t>(e[3] | (b << 8U)) : cws[b % 8U];
      f = encode_rpdo1(kDrive, Rpdo1{cw, (b & 0x08U) != 0 ? absolute : near(position)});
      break;
    }
    case 3:  // RPDO1 to another node
      f = encode_rpdo1(other, Rpdo1{static_cast<std::uint16_t>(b), near(position)});
      break;
    case 4: {  // TPDO1 in the drive's name: a state, a position near or far
      constexpr std::array<std::uint16_t, 6> sws{0x0237, 0x0233, 0x0231, 0x0250, 0x0208, 0x0217};
      f = encode_tpdo1(kDrive, Tpdo1{sws[b % sws.size()], (b & 0x08U) != 0 ? absolute : near(position)});
      break;
    }
    case 5:  // TPDO2 in the drive's name
      f = encode_tpdo2(kDrive, Tpdo2{near(position), absolute});
      break;
    case 6:  // TPDOs of another node
      f = (b & 1U) != 0 ? encode_tpdo1(other, Tpdo1{0x0237, absolute}) : encode_tpdo2(other, Tpdo2{absolute, absolute});
      break;
    case 7: {  // SDO expedited download to the drive
      constexpr std::array<std::pair<std::uint16_t, std::uint8_t>, 14> objs{{
          {obj::controlword, 0}, {obj::target_position, 0}, {obj::modes_of_operation, 0},
          {obj::communication_cycle_period, 0}, {obj::communication_loss_periods, 0},
          {obj::following_error_window, 0}, {obj::software_position_limit, 1}, {obj::software_position_limit, 2},
          {obj::producer_heartbeat_time, 0}, {obj::consumer_heartbeat_time, 1}, {obj::quick_stop_option, 0},
          {obj::abort_connection_option, 0}, {obj::interpolation_time_period, 1}, {obj::sync_counter_overflow, 0}}};
      const auto& [index, sub] = objs[b % objs.size()];
      const std::int32_t value = index == obj::target_position && (b & 0x80U) == 0 ? near(position) : absolute;
      f.id = cob::sdo_rx + kDrive;
      f.len = 8;
      f.data[0] = 0x23;  // expedited, size indicated, 4 bytes (the server checks the size)
      f.data[1] = static_cast<std::uint8_t>(index);
      f.data[2] = static_cast<std::uint8_t>(index >> 8U);
      f.data[3] = sub;
      for (std::size_t i = 0; i < 4; ++i) f.data[4 + i] = static_cast<std::uint8_t>(static_cast<std::uint32_t>(value) >> (8U * i));
      if ((b & 0x40U) != 0) f.data[0] = static_cast<std::uint8_t>(0x2F - 4 * ((b >> 4U) & 3U));  // 1..4-byte sizes
      break;
    }
    case 8:  // any SDO request to the drive (uploads, aborts, segmented, nonsense)
      f.id = cob::sdo_rx + kDrive;
      f.len = 8;
      f.data[0] = b;
      for (std::size_t i = 0; i < 4; ++i) f.data[1 + i] = e[i];
      break;
    case 9:  // EMCY in the drive's name, or another node's
      f = encode_emcy((b & 1U) != 0 ? other : kDrive,
                      EmcyMessage{static_cast<std::uint16_t>(e[0] | (e[1] << 8U)), e[2], {}});
      break;
    case 10: {  // heartbeat in the drive's name: boot-up, stopped, operational, pre-operational, any
      constexpr std::array<std::uint8_t, 5> states{0x00, 0x04, 0x05, 0x7F, 0xFF};
      f.id = cob::heartbeat + kDrive;
      f.len = 1;
      f.data[0] = states[b % states.size()] == 0xFF ? e[0] : states[b % states.size()];
      break;
    }
    default: {  // garbage: any identifier, format and length
      f.flags = static_cast<std::uint8_t>((b & 0x07U) == 0 ? 0 : (b & 0x07U));
      const auto raw_id = static_cast<std::uint32_t>(absolute);
      f.id = (f.flags & can_flag::extended) != 0 ? (raw_id & can_extended_id_max) : (raw_id & can_standard_id_max);
      f.len = static_cast<std::uint8_t>((f.flags & can_flag::fd) != 0 ? can_dlc_to_len(b >> 4U) : ((b >> 4U) % 9U));
      for (std::size_t i = 0; i < f.len && i < can_fd_max_len; ++i) f.data[i] = e[i % 4];
      if ((f.flags & can_flag::rtr) != 0 && (f.flags & can_flag::fd) != 0) f.flags &= static_cast<std::uint8_t>(~can_flag::fd);
      break;
    }
  }
  return f;
}

struct Plant {
  std::int32_t position{0};
  std::int32_t velocity{0};
};

struct Rig {
  explicit Rig(const Scenario& s) : drive{drive_config(s)} {}
  LoopbackHub hub;
  LoopbackBus<256> m_port{hub};
  LoopbackBus<256> d_port{hub};
  LoopbackBus<64> x_port{hub};  // the third node
  testing::FaultInjectingBus m_fault{m_port};
  testing::FaultInjectingBus d_fault{d_port};
  HarnessBus m_bus{m_fault};
  HarnessBus d_bus{d_fault};
  runtime::ServoLoop<double, 1, 2> loop{m_bus, kPeriodUs};
  DriveNode drive;
  Plant plant{};
};

class Run {
 public:
  explicit Run(const Scenario& s) : s_{s}, rig_{std::make_unique<Rig>(s)} {}

  void go() {
    Rig& r = *rig_;
    r.plant.position = s_.start_position;
    if (r.loop.add_axis(axis_config(s_)) != runtime::LoopStatus::ok) {
      violated("setup", "add_axis refused the harness's axis", 0, 0);
    }
    r.m_bus.observe(&r.loop.drive(0));
    TRACE("move: profile %d distance %.6f time %.3f omega %.2f -> %s, peak v %.4f; limit %.4f units/s = %u counts/period;"
          " submitted at tick %llu; drive starts at %d; %zu events",
          static_cast<int>(s_.request.profile), s_.request.distance, *s_.request.time, s_.request.omega(),
          s_.move ? "planned" : "refused", s_.move ? s_.move->peaks().v : 0.0, s_.limits.velocity, s_.limits.step_counts,
          static_cast<unsigned long long>(s_.submit_tick), s_.start_position, s_.event_count);
    configure_drive_limit();
    r.drive.start(0, r.d_bus);
    r.loop.start(0);

    const std::uint64_t last_event = s_.event_count > 0 ? s_.events[s_.event_count - 1].tick : 0;
    const std::uint64_t move_ticks = s_.move ? static_cast<std::uint64_t>(std::ceil(s_.move->duration() * 1e3)) : 0;
    const std::uint64_t end = std::max(last_event, s_.submit_tick + move_ticks) + kTailTicks;
    std::size_t next_event = 0;
    for (std::uint64_t tick = 1; tick <= end; ++tick) {
      g_tick = tick;
      const std::uint64_t now = tick * kPeriodUs;
      r.hub.set_time_us(now);
      r.m_fault.set_time_us(now);
      r.d_fault.set_time_us(now);
      if (tick > last_event && !tail_) {  // the quiet tail: every fault off
        clear(0);
        clear(1);
        tail_ = true;
      }
      std::size_t after_first = kMaxEvents;
      std::size_t after_count = 0;
      while (next_event < s_.event_count && s_.events[next_event].tick <= tick) {
        const Event& ev = s_.events[next_event];
        if (ev.op == op_inject_after) {
          if (after_count == 0) after_first = next_event;
          ++after_count;
        } else {
          apply(ev);
        }
        last_disturbance_ = tick;
        ++next_event;
      }
      if (s_.move && tick == s_.submit_tick) (void)r.loop.submit(0, *s_.move);

      const std::int32_t tick_start = r.plant.position;
      r.loop.tick(now);
      r.m_bus.flush();
      watch_loop();
      for (std::size_t i = after_first; after_count > 0 && i < s_.event_count; ++i) {
        if (s_.events[i].op == op_inject_after && s_.events[i].tick <= tick) {
          inject(s_.events[i]);
          --after_count;
        }
      }
      run_drive(now);
      r.d_bus.flush();
      if (distance_counts(r.plant.position, tick_start) > s_.limits.step_counts) {
        violated("a", "the drive's position stepped more than its limit within one period",
                 static_cast<long long>(distance_counts(r.plant.position, tick_start)), s_.limits.step_counts);
      }
      check_completed(tick);
    }
  }

 private:
  // The drive's own limit, as commissioning stores it: written at power-on and again after an
  // NMT reset node (which restores the stored parameters). Refused by a drive without 0x607F.
  void configure_drive_limit() {
    const double counts_per_s = s_.limits.velocity * kCountsPerUnit;
    const auto raw = static_cast<std::uint32_t>(std::min(counts_per_s, 4294967295.0));
    (void)rig_->drive.dictionary().write(kMaxProfileVelocity, 0, raw, 4);
  }

  void clear(int side) {
    Rig& r = *rig_;
    testing::FaultInjectingBus& f = side == 0 ? r.m_fault : r.d_fault;
    HarnessBus& h = side == 0 ? r.m_bus : r.d_bus;
    f.clear_faults();
    h.clear();
    faulty_[side] = false;
  }

  void apply(const Event& ev) {
    Rig& r = *rig_;
    static constexpr std::array<const char*, op_count> names{
        "target", "drop_tx", "drop_rx", "fail_tx", "delay_tx", "delay_rx", "random", "clear", "dup_rx",
        "dup_tx", "reorder_rx", "reorder_tx", "inject_before", "inject_after", "inject_sync"};
    if (ev.op == op_inject_before || ev.op == op_inject_sync) {
      TRACE("event %s, a=%u b=%u", names[ev.op], ev.a, ev.b);
    } else {
      TRACE("event %s on the %s side, a=%u b=%u", names[ev.op], (ev.a & 1U) != 0 ? "drive" : "master", ev.a, ev.b);
    }
    const int side = ev.a & 1;
    testing::FaultInjectingBus& f = side == 0 ? r.m_fault : r.d_fault;
    HarnessBus& h = side == 0 ? r.m_bus : r.d_bus;
    const std::uint32_t n16 = ev.b % 16U + 1U;
    const std::uint32_t n8 = ev.b % 8U + 1U;
    switch (ev.op) {
      case op_target: f.set_target(filter_for(static_cast<std::uint8_t>(ev.a >> 1U))); break;
      case op_drop_tx: f.drop_sends(n16); break;
      case op_drop_rx: f.drop_receives(n16); break;
      case op_fail_tx: f.fail_sends(n16, (ev.a & 2U) != 0 ? SendStatus::error : SendStatus::busy); break;
      case op_delay_tx: f.delay_sends_us(std::uint64_t{ev.b % 41U} * 250U); break;
      case op_delay_rx: f.delay_receives_us(std::uint64_t{ev.b % 41U} * 250U); break;
      case op_random: {
        testing::FaultRates rates{};
        rates.tx_busy_ppm = (ev.b & 3U) * 20'000U;
        rates.tx_drop_ppm = ((ev.b >> 2U) & 3U) * 20'000U;
        rates.rx_drop_ppm = ((ev.b >> 4U) & 3U) * 20'000U;
        rates.tx_error_ppm = ((ev.b >> 6U) & 1U) * 10'000U;
        f.set_random(s_.seed ^ static_cast<std::uint32_t>(ev.tick * 2654435761U), rates);
        break;
      }
      case op_clear:
        if (ev.a % 3U != 1U) clear(0);
        if (ev.a % 3U != 0U) clear(1);
        return;
      case op_dup_rx: h.set_filter(filter_for(static_cast<std::uint8_t>(ev.a >> 1U))); h.duplicate_receives(n8); break;
      case op_dup_tx: h.set_filter(filter_for(static_cast<std::uint8_t>(ev.a >> 1U))); h.duplicate_sends(n8); break;
      case op_reorder_rx: h.set_filter(filter_for(static_cast<std::uint8_t>(ev.a >> 1U))); h.reorder_receives(n8); break;
      case op_reorder_tx: h.set_filter(filter_for(static_cast<std::uint8_t>(ev.a >> 1U))); h.reorder_sends(n8); break;
      case op_inject_before: inject(ev); return;
      case op_inject_sync:
        trace_frame("third node, just before the master's next SYNC", inject_frame(ev, r.plant.position));
        r.m_bus.inject_before_sync(inject_frame(ev, r.plant.position), r.x_port);
        foreign_ = true;
        return;
      default: return;
    }
    faulty_[side] = true;
  }

  static void trace_frame(const char* what, const CanFrame& f) {
    if (g_trace == 0) return;
    char bytes[3 * 8 + 1] = {};
    for (std::size_t i = 0; i < f.len && i < 8; ++i) std::snprintf(bytes + 3 * i, 4, " %02X", f.data[i]);
    TRACE("%s: id %03X flags %u len %u:%s", what, static_cast<unsigned>(f.id), f.flags, f.len, bytes);
  }

  void inject(const Event& ev) {
    Rig& r = *rig_;
    const CanFrame f = inject_frame(ev, r.plant.position);
    trace_frame(ev.op == op_inject_before ? "third node, before the master's tick" : "third node, after the master's tick", f);
    (void)r.x_port.send(f);
    foreign_ = true;
  }

  // The loop's side of (c): where the move started, and that its final setpoint is its target.
  void watch_loop() {
    Rig& r = *rig_;
    for (runtime::FeedbackSample fs{}; r.loop.feedback_log(0).pop(fs);) {
    }
    const runtime::AxisStats& st = r.loop.axis_stats(0);
    const RemoteDriveState view = r.loop.drive(0).state();
    if (view != view_) {
      TRACE("master: drive %s -> %s (drive position as the master knows it: %d)", to_string(view_), to_string(view),
            r.loop.drive(0).feedback().position_actual);
      view_ = view;
    }
    if (st.moves_aborted != aborted_ || st.step_guard_trips != guard_trips_) {
      TRACE("master: moves aborted %llu, step guard trips %llu", static_cast<unsigned long long>(st.moves_aborted),
            static_cast<unsigned long long>(st.step_guard_trips));
      aborted_ = st.moves_aborted;
      guard_trips_ = st.step_guard_trips;
    }
    if (st.moves_started != started_) {
      started_ = st.moves_started;
      // The first setpoint is the origin itself (every profile starts at rest at 0).
      const double distance = s_.move ? s_.move->distance() : 0.0;
      origin_ = r.loop.record(0).target;
      distance_counts_ = distance * kCountsPerUnit;
      // Rounded as the setpoint stream rounds (to nearest, ties to even): at a tie either count
      // is within half a count of the target, and the check below allows exactly that.
      target_ = wrap_add(origin_, static_cast<std::int64_t>(std::nearbyint(distance_counts_)));
      TRACE("master: move started from %d, target %d", r.loop.record(0).target, target_);
    }
    if (r.loop.record(0).move_end) {
      // The final setpoint, relative to the origin, is the move's distance within half a count.
      const auto travelled = static_cast<std::int32_t>(static_cast<std::uint32_t>(r.loop.record(0).target) -
                                                       static_cast<std::uint32_t>(origin_));
      if (!(std::fabs(travelled - distance_counts_) <= 0.5 + 1e-6)) {
        violated("c", "the loop's final setpoint is not the move's target", r.loop.record(0).target, target_);
      }
    }
    if (st.moves_completed != completed_) {
      completed_ = st.moves_completed;
      TRACE("master: move reported completed (drive at %d)", r.plant.position);
      foreign_ = false;  // third-party frames from here on may move the axis legitimately
    }
  }

  void run_drive(std::uint64_t now) {
    Rig& r = *rig_;
    CanFrame f{};
    for (std::size_t n = 0; n < kMaxDriveFramesPerTick; ++n) {
      if (r.d_bus.receive(f, 0) != ReceiveStatus::received) break;
      const Cia402State before = r.drive.state();
      const DriveEvent event = r.drive.on_frame(f, now, r.d_bus);
      if (event == DriveEvent::reset) configure_drive_limit();
      if (event != DriveEvent::sync) continue;
      std::int32_t next = r.drive.following() ? r.drive.setpoint() : r.plant.position;
      if ((g_emulate & 2U) != 0 && before != Cia402State::operation_enabled) next = r.plant.position;
      if ((g_emulate & 4U) != 0 && last_sync_us_ == now) next = r.plant.position;
      last_sync_us_ = now;
      if ((g_emulate & 1U) != 0 && distance_counts(next, r.plant.position) > s_.limits.step_counts) {
        r.drive.raise_fault(emcy_code::following_error, now, r.d_bus);
        next = r.plant.position;
      }
      if (next != r.plant.position) {
        if (before != Cia402State::operation_enabled) {
          violated("b", "the drive moved its axis at a SYNC before which it was not operation enabled",
                   static_cast<long long>(distance_counts(next, r.plant.position)), static_cast<long long>(before));
        }
        if (distance_counts(next, r.plant.position) > s_.limits.step_counts) {
          violated("a", "the drive's position stepped more than its limit at one SYNC",
                   static_cast<long long>(distance_counts(next, r.plant.position)), s_.limits.step_counts);
        }
      }
      r.plant.velocity = static_cast<std::int32_t>(
          (static_cast<std::uint32_t>(next) - static_cast<std::uint32_t>(r.plant.position)) * (1'000'000U / kPeriodUs));
      if (g_trace > 1 || (g_trace > 0 && distance_counts(next, r.plant.position) > s_.limits.step_counts)) {
        TRACE("drive: SYNC, %s, position %d -> %d", to_string(r.drive.state()), r.plant.position, next);
      }
      r.plant.position = next;
      if (r.drive.stopping()) r.drive.stop_complete();
      r.drive.publish(DriveFeedback{r.plant.position, r.plant.velocity, r.plant.position}, now, r.d_bus);
    }
    r.drive.poll(now, r.d_bus);
    if (r.drive.state() != drive_state_ || r.drive.nmt_state() != drive_nmt_) {
      TRACE("drive: %s, NMT 0x%02X, at %d", to_string(r.drive.state()), static_cast<unsigned>(r.drive.nmt_state()),
            r.plant.position);
      drive_state_ = r.drive.state();
      drive_nmt_ = r.drive.nmt_state();
    }
  }

  void check_completed(std::uint64_t tick) {
    Rig& r = *rig_;
    const bool quiet = !faulty_[0] && !faulty_[1] && r.m_bus.quiet() && r.d_bus.quiet() && r.m_fault.held_sends() == 0 &&
                       r.m_fault.held_receives() == 0 && r.d_fault.held_sends() == 0 && r.d_fault.held_receives() == 0;
    if (!quiet) last_disturbance_ = tick;
    if (completed_ == 0 || foreign_ || !r.loop.idle() || !r.loop.ready(0)) return;
    if ((g_emulate & 8U) != 0 && (r.drive.nmt_state() != NmtState::operational || !r.drive.following())) return;
    if (tick - last_disturbance_ < kSettleTicks) return;
    if (distance_counts(r.plant.position, target_) > 1) {
      violated("c", "a move the loop reports completed did not end at its target (drive position vs target)",
               r.plant.position, target_);
    }
  }

  const Scenario& s_;
  std::unique_ptr<Rig> rig_;
  bool tail_{false};
  bool faulty_[2]{false, false};
  bool foreign_{false};  // a third node spoke since the last completion report
  std::uint64_t last_disturbance_{0};
  std::uint64_t started_{0};
  std::uint64_t completed_{0};
  std::int32_t target_{0};
  std::int32_t origin_{0};
  std::uint64_t last_sync_us_{~std::uint64_t{0}};
  double distance_counts_{0.0};
  // For the trace only.
  RemoteDriveState view_{RemoteDriveState::idle};
  std::uint64_t aborted_{0};
  std::uint64_t guard_trips_{0};
  Cia402State drive_state_{Cia402State::switch_on_disabled};
  NmtState drive_nmt_{NmtState::initialising};
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto s = std::make_unique<Scenario>();
  if (!parse(data, size, *s)) return 0;
  Run run{*s};
  run.go();
  return 0;
}
