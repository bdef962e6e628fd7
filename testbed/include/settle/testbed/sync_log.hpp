// SPDX-License-Identifier: Apache-2.0
#pragma once
// The simulated drive's record of every SYNC, bounded: `settle plant` runs for hours at one record
// per period, so nothing here grows with the run. PlantNode keeps the last records in a ring of
// fixed capacity (allocated when it is made) and hands each record to a SyncSink as it is made;
// SyncCsvLog is the sink that streams them to a CSV file through a buffer allocated up front. The
// receive path never allocates.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "settle/plant/csv_columns.hpp"
#include "settle/testbed/drive_axis.hpp"

namespace settle::testbed {

// One SYNC as the drive saw it: what it applied and where the machine was one period later.
struct SyncRecord {
  std::uint64_t sync{0};       // index of the SYNC since start
  std::uint64_t time_us{0};
  bool following{false};       // a target was applied (operation enabled)
  std::int32_t target{0};      // counts (the applied setpoint, or the held position)
  AxisFeedback feedback{};
  double load{0.0};            // unquantised output position at the end of the period
  double base{0.0};
};

// Receives each record as it is made, in the receive path: must not allocate or block for long.
class SyncSink {
 public:
  SyncSink() = default;
  SyncSink(const SyncSink&) = delete;
  SyncSink& operator=(const SyncSink&) = delete;
  virtual ~SyncSink() = default;
  virtual void on_record(const SyncRecord& r) noexcept = 0;
};

// Every record as one CSV line, in order (column names: plant/csv_columns.hpp):
//   sync_index, time_us, following_flag, target_counts, position_actual_counts,
//   velocity_actual_counts_per_s (what this simulated drive sends in 0x606C), load_position_counts,
//   load_<u> (the unquantised output position), base_<u> (the base, the drive's own position)
// formatted on the stack and written through a stdio buffer of kBufferBytes allocated by open().
class SyncCsvLog final : public SyncSink {
 public:
  static constexpr std::size_t kBufferBytes = 1 << 16;

  SyncCsvLog() = default;
  ~SyncCsvLog() override;

  // Creates (truncates) the file and writes the header, positions in `u`. False if it cannot be opened.
  [[nodiscard]] bool open(const std::string& path, plant::PositionUnit u);
  void on_record(const SyncRecord& r) noexcept override;
  // Flushes and closes. False if any write failed or nothing was open.
  [[nodiscard]] bool close();
  [[nodiscard]] std::uint64_t records() const noexcept { return records_; }

 private:
  std::FILE* file_{nullptr};
  std::vector<char> buffer_;
  std::uint64_t records_{0};
  bool failed_{false};
};

}  // namespace settle::testbed
