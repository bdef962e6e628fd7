// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/sync_log.hpp"

namespace settle::testbed {

SyncCsvLog::~SyncCsvLog() { (void)close(); }

bool SyncCsvLog::open(const std::string& path, plant::PositionUnit u) {
  (void)close();
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  buffer_.assign(kBufferBytes, '\0');
  if (std::setvbuf(f, buffer_.data(), _IOFBF, buffer_.size()) != 0) {
    std::fclose(f);
    return false;
  }
  file_ = f;
  using plant::column;
  const std::string position = plant::motion_suffix(u, 0);
  const std::string header = column("sync", "index") + "," + column("time", "us") + "," + column("following", "flag") +
                             "," + column("target", "counts") + "," + column("position_actual", "counts") + "," +
                             column("velocity_actual", "counts_per_s") + "," + column("load_position", "counts") + "," +
                             column("load", position) + "," + column("base", position) + "\n";
  failed_ = std::fputs(header.c_str(), f) < 0;
  records_ = 0;
  return true;
}

void SyncCsvLog::on_record(const SyncRecord& r) noexcept {
  if (file_ == nullptr) return;
  char line[256];
  const int n = std::snprintf(line, sizeof line, "%llu,%llu,%d,%d,%d,%d,%d,%.12g,%.12g\n",
                              static_cast<unsigned long long>(r.sync), static_cast<unsigned long long>(r.time_us),
                              r.following ? 1 : 0, r.target, r.feedback.position_actual, r.feedback.velocity_actual,
                              r.feedback.load_position, r.load, r.base);
  if (n <= 0 || static_cast<std::size_t>(n) >= sizeof line ||
      std::fwrite(line, 1, static_cast<std::size_t>(n), file_) != static_cast<std::size_t>(n)) {
    failed_ = true;
    return;
  }
  ++records_;
}

bool SyncCsvLog::close() {
  if (file_ == nullptr) return false;
  const bool ok = std::fclose(file_) == 0 && !failed_;
  file_ = nullptr;
  buffer_.clear();
  buffer_.shrink_to_fit();
  return ok;
}

}  // namespace settle::testbed
