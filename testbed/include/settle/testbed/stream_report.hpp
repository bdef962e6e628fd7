// SPDX-License-Identifier: Apache-2.0
#pragma once
// A stream's report as people and programs read it: the text summary `settle stream` prints, its
// --json document (one line; the field names are an interface: settle demo, tests/e2e and the
// examples parse them), and the CSV files of its --log (every tick) and --feedback-log (commanded
// and measured motion, aligned with the offline replay).
#include <cstdio>
#include <string>

#include "settle/testbed/stream.hpp"

namespace settle::testbed {

// The text summary, five to seven lines (--axes N: one more per axis, and how they moved together).
void write_stream_text(const StreamReport& r, std::FILE* out);
// The JSON document, one line without its newline. "status" is "ok" only when r.measured();
// measurements that are absent (not aligned, not finite) are null; strings that are not UTF-8
// (a hostile interface name) carry U+FFFD.
[[nodiscard]] std::string stream_json(const StreamReport& r);

// Column names: plant/csv_columns.hpp. The tick log, one row per tick (axis 1's; and the feedback
// CSV below too): tick_index, t_s, target_counts, sent_flag, moving_flag, move_end_flag,
// position_actual_counts, load_position_counts, velocity_actual_drive_velocity_units (0x606C as the
// drive sends it: Settle's simulated drive sends counts/s, another drive its own unit),
// tpdo1_received_count. False when writing failed.
[[nodiscard]] bool write_tick_csv(const StreamReport& r, std::FILE* out);
// period_index, t_s, commanded_counts, position_can_counts, load_can_counts, load_offline_counts: from
// up to 50 periods before the first setpoint to the end of the settling window, period 0 being the
// first setpoint. Only for an aligned run (false otherwise, or when writing failed).
[[nodiscard]] bool write_feedback_csv(const StreamReport& r, std::FILE* out);

}  // namespace settle::testbed
