// SPDX-License-Identifier: Apache-2.0
#pragma once
// `settle stream` as a library call: the servo loop streams a planned move to a drive over CAN,
// and the report says whether the machine ended at rest: the residual vibration measured from the
// drive's CAN feedback, next to the offline replay of the same setpoints (no bus) and the
// continuous profile (no sampling). run_stream(spec, bus) -> StreamReport; where it runs is the
// ClockedBus (clocked_bus.hpp), how it is printed the reporters (stream_report.hpp).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "settle/core/move.hpp"
#include "settle/core/online.hpp"
#include "settle/core/status.hpp"
#include "settle/runtime/linux/periodic.hpp"
#include "settle/runtime/servo_loop.hpp"
#include "settle/runtime/session.hpp"
#include "settle/hal/can_bus.hpp"
#include "settle/hal/eds_drive_config.hpp"
#include "settle/hal/eds_reader.hpp"
#include "settle/testbed/drive_axis.hpp"
#include "settle/plant/modal_plant.hpp"
#include "settle/testbed/stream_check.hpp"

namespace settle::testbed {

// The loop's evaluation: FloatEvaluation<double>, FloatEvaluation<float>, or the firmware's
// fixed-point one with room for the pseudo-polynomial's pieces (PolyFixedEvaluation).
enum class StreamScalar : std::uint8_t { double_precision, single_precision, fixed_point };
[[nodiscard]] const char* to_string(StreamScalar s) noexcept;  // "double", "float", "fixed"

// What to stream, to what machine, and how the loop supervises the drive. The caller bounds the
// sizes (move + settle time in periods, counts within 32 bits) before asking.
// --halt-at / --retarget-at (docs/online.md): the loop's halt() or retarget() of the move, asked
// for kOnlineLeadTicks periods before `at` (a whole number of periods, at least that lead) and
// switched in at `at`; `blend` is what core plans there, for the offline replay and reference.
struct StreamChange {
  double at{0.0};
  std::optional<double> target;
  std::vector<core::Mode> modes;
  core::OnlineLimits limits{};
  core::Blend blend{};
  // The halt finishes the move (core::OnlineChoice::finish): the loop keeps streaming it, and the
  // replay is the move's.
  bool finish{false};
  // The axis is one of a path's (--axes N --sync path): the loop plans the path's halt, or its
  // retarget on the line, once for every such axis (runtime::OnlineConfig::path).
  bool path{false};
};

// One axis of the run: its move, its drive's node and, with a halt or retarget, its change (every
// axis that has one changes at the same `at`; with --axes N core::axis_online gives its modes and
// limits).
struct StreamAxis {
  core::Move<double> move{};
  hal::canopen::NodeId node{1};
  std::optional<StreamChange> change;  // every scalar: the blend is evaluated in it
};

// --load-feedback INDEX:SUB: the drive's object that measures the load (or any vibration),
// mapped into a TPDO like the rest. index 0: none named.
struct LoadFeedback {
  std::uint16_t index{0};
  std::uint8_t sub{0};
  // Where a simulated drive of another vendor serves its load position (SimulatedDriveSpec's
  // load_position): none when none is named.
  [[nodiscard]] std::optional<hal::eds::MappedObject> served_at() const {
    if (index == 0) return std::nullopt;
    return hal::eds::MappedObject{index, sub, 32};
  }
};

struct StreamSpec {
  // Every axis of the run, axis 1 first (--axes N, docs/multi_axis.md: one drive per node, one
  // bus), every one started on the same SYNC and streamed, supervised and measured alike, with the
  // same plant, drive and loop options below (each its own copy of the plant: one PlantNode per
  // node on loopback). With a change, every axis that has one is asked in the same period between
  // the same two ticks, as an application halting the machine would. One axis on node 1 unless set.
  std::vector<StreamAxis> axes{StreamAxis{}};
  plant::ModalPlant plant{};       // the machine behind the drive: the in-process drive's and the replay's
  DriveAxisConfig drive{};  // the simulated drive and the replay; drive.scale is the loop's axis scale too
  std::uint16_t heartbeat_ms{500};
  std::uint32_t sdo_timeout_us{1'000'000};
  std::uint16_t feedback_timeout_periods{runtime::kDefaultFeedbackTimeoutPeriods};
  std::optional<double> axis_vmax{};  // units/s; default: stream_axis_vmax()
  double settle_time_s{1.0};          // periods observed after the move, at rest
  StreamScalar scalar{StreamScalar::double_precision};
  // --eds: the drive's description. The master configures and verifies the drive from it
  // (hal::eds::drive_config_from_eds with streaming_feedback), and on loopback the simulated drive
  // is the one it describes (testbed::build_simulated_drive). Null: Settle's own drive, as assumed.
  std::shared_ptr<const hal::eds::Description> eds;
  LoadFeedback load_feedback{};  // with eds: the load position object the user named
};

// The vmax the loop's step guard holds `axis`'s setpoints to (runtime::AxisLoopConfig::vmax,
// units/s): spec.axis_vmax when given; else 1.5 x the move's peak velocity, and with a change at
// least the vmax the loop plans its blend within (StreamChange::limits), so that every blend the
// loop plans makes only steps the guard admits (the loop refuses online limits over the axis's vmax).
[[nodiscard]] double stream_axis_vmax(const StreamSpec& spec, const StreamAxis& axis);

// What the loop would refuse before streaming anything, found without a bus: on `axis` (an index into spec.axes),
// the move or its change's vmax over the axis's vmax (exceeds_axis_velocity), the evaluation of
// the spec's scalar refusing the move or the blend (evaluation_refused, `why` says the core status),
// and with `simulated_drive` (the loopback bus: the drive is the one this process simulates, the
// default one or the --eds one) a velocity over its 0x607F (exceeds_drive_velocity). ok when the
// loop takes every axis's move and change as far as they are known before the drive answers (a
// drive on a real bus says its limits at start-up; the loop checks them then).
struct StreamRefusal {
  runtime::LoopStatus status{runtime::LoopStatus::ok};
  std::size_t axis{0};
  core::Status why{core::Status::ok};
  bool in_change{false};  // the blend of the halt or retarget, not the move
  double limit{0.0};      // exceeds_axis_velocity: the axis's vmax, units/s; exceeds_drive_velocity: 0x607F, counts/s
  double peak{0.0};       // and the velocity over it, in the same unit
};
[[nodiscard]] StreamRefusal check_streamable(const StreamSpec& spec, bool simulated_drive);

// One drive per node: the first node id in `nodes` (axis order) that an earlier one has, with both
// axes' indices; none when every node is distinct. run_stream refuses a spec whose axes share a
// node (naming both axes), `settle stream --nodes` the list (naming the node).
struct NodeClash {
  std::size_t earlier{0};
  std::size_t later{0};
  hal::canopen::NodeId node{0};
};
[[nodiscard]] std::optional<NodeClash> shared_node(const std::vector<hal::canopen::NodeId>& nodes);

// The feedback a stream maps besides statusword and position: the velocity actual 0x606C when
// the description has it, and the load position: the object `load` names (--load-feedback), else
// the one the description marks ([SettleDrive] LoadPosition: 0x2000 on Settle's own drive), else
// none (the residual, PRV and at-rest verdict are then not measured).
[[nodiscard]] hal::eds::FeedbackRequest streaming_feedback(const hal::eds::Description& eds,
                                                          const LoadFeedback& load = {});

// Why a drive's start-up failed, in one line: the object, what was expected and read, or the SDO
// status and abort code.
[[nodiscard]] std::string start_up_failure_text(const hal::canopen::RemoteDriveFailure& failure);

// A drive's EMCY in one phrase: its code, what the code means and, for the simulated drive's
// manufacturer-specific byte (hal's emcy_cause), which rule fired: "EMCY 0x8100 (communication:
// the drive lost SYNC)".
[[nodiscard]] std::string emcy_text(const hal::canopen::EmcyMessage& emcy);

// What the real-time clock saw (all zero on a virtual clock).
struct StreamTiming {
  runtime::linux_rt::LatencyHistogram latency{};
  std::uint64_t overruns{0};
  runtime::linux_rt::RealtimeSetup realtime{};
};

// Where a run happens: the one bus with a clock (clocked_bus.hpp).
class ClockedBus;

// One axis of a run, every number the reporters print for it. A residual that could not be
// measured is NaN.
struct AxisReport {
  hal::canopen::NodeId node{1};
  core::ProfileKind profile{};
  core::Status evaluation{core::Status::ok};  // why the selected evaluation refused the move
  double distance{0.0};
  double duration{0.0};  // of the move (s)

  std::string drive_state;
  std::string drive_failure;  // empty unless the drive's start-up failed
  // The first error EMCY (code not 0) the drive sent during the run: what it said went wrong,
  // whatever the loop concluded (a drive that quick-stops on SYNC loss then looks lost).
  std::optional<hal::canopen::EmcyMessage> drive_emcy;
  runtime::AxisStats axis{};
  std::vector<runtime::TickRecord> log;           // one per tick
  std::vector<runtime::FeedbackSample> feedback;  // every TPDO pair, in arrival order

  std::vector<std::int32_t> setpoints;  // the selected evaluation's (empty when it refused)
  // Against the double evaluator's setpoints (absent when either evaluation refused the move).
  std::optional<std::int64_t> setpoints_vs_double_max_counts;
  std::int64_t setpoints_differing_from_double{0};
  Replay replay{};                        // the setpoints through the same drive and plant, no bus
  std::optional<std::size_t> alignment;   // where the replay's positions start in the feedback
  std::uint64_t feedback_late_ticks{0};

  // Whether the drive reports a load-side position at all: decided before streaming from what the
  // master maps (the layout's load slot: Settle's own drive maps 0x2000 in TPDO2; an --eds drive
  // only when its description has a load-position object in a TPDO). Without it the CAN residual,
  // its PRV and the at-rest verdict are not measured (NaN, null in JSON), never fitted to zeros;
  // load_note says why.
  bool load_measured{true};
  std::string load_note;
  SampledResidual residual_can{};      // from the CAN feedback (NaN: not measured)
  SampledResidual residual_offline{};  // from the replay
  double residual_double{0.0};         // the double evaluator's replay
  double agreement{0.0};               // |CAN - offline|
  double residual_vs_double_percent{0.0};
  double residual_vs_double_load_counts{0.0};
  bool continuous_simulated{false};
  double residual_continuous{0.0};     // the continuous profile, unsampled
  double prv_continuous_percent{0.0};
  std::size_t window_samples{0};
  // The ticks (log indices) of the move's first setpoint sent and of its last (absent: never).
  std::optional<std::uint64_t> move_start_tick, move_end_tick;

  [[nodiscard]] bool aligned() const noexcept { return alignment.has_value(); }
  // Aligned, with every measurement the drive allows present and finite (a drive without a load
  // position: every setpoint applied once and in order, the offline replay).
  [[nodiscard]] bool measured() const noexcept;
};

// One run: what is the run's (the bus, the session, the counters, the timing) and one report per
// axis, in the spec's order.
struct StreamReport {
  std::string failure;  // non-empty: the run could not be made (a bus or file that cannot be opened)

  std::string bus;
  bool realtime{false};
  StreamScalar scalar{StreamScalar::double_precision};
  core::AxisScale scale{};

  runtime::SessionResult session{};
  // From the session's first tick to the first with every drive operation enabled (NMT, the SDO
  // configuration, the enable sequence), on the bus's clock; absent when it never got there.
  std::optional<std::uint64_t> start_up_us;
  // The loop's timeouts the run used (the spec's): reported so that a failure can name them.
  std::uint16_t heartbeat_ms{0};
  std::uint32_t sdo_timeout_us{0};
  std::uint16_t feedback_timeout_periods{0};
  hal::BusCounters counters{};
  std::uint64_t units_held{0};
  StreamTiming timing{};
  std::uint64_t frames_lost{0};

  std::vector<AxisReport> axes;

  // With several axes: how far apart their moves started and ended (ticks; 0 = the same SYNC, as
  // the session promises; axes that do not move are left out), and the largest distance from the
  // straight line from the start to (D_1, ..., D_N), in counts, of the points the axes were sent
  // (setpoints) and of the positions the drives reported for the same SYNCs (feedback, aligned
  // with each axis's replay). With --sync path the line is the path: it is bounded by one count.
  std::optional<std::uint64_t> start_tick_spread, end_tick_spread;
  double line_deviation_setpoints_counts{0.0};
  double line_deviation_feedback_counts{0.0};

  // Success: the session completed, every axis measured(), and with several axes how they moved
  // together measured too.
  [[nodiscard]] bool measured() const noexcept;
  // measured(), and the machine's rest verified from the CAN load feedback on every axis.
  [[nodiscard]] bool rest_measured() const noexcept;
};

// Streams every axis's move over `bus` and measures it. A report with `failure` set says why it
// could not run; otherwise the report is complete whatever the outcome (measured() says whether it
// succeeded).
[[nodiscard]] StreamReport run_stream(const StreamSpec& spec, ClockedBus& bus);

}  // namespace settle::testbed
