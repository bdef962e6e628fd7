// SPDX-License-Identifier: Apache-2.0
// A test double for the master's start-up: an SDO server over a small object dictionary with the
// objects RemoteDrive configures (and, for the PDO tests, four RPDO and four TPDO communication and
// mapping objects, all writable), scripted to misbehave: to acknowledge a write and ignore it, or
// to stay silent to a number of requests for one object. No process data, no state machine: the
// tests take start-up to the point where the master sends NMT start (state enabling).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "settle/hal/can_frame.hpp"
#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/object_dictionary.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/sdo.hpp"
#include "settle/hal/frame_sink.hpp"

namespace settle::hal::canopen::test {

struct ScriptedPdo {
  std::uint32_t cob_id{0};
  std::uint8_t transmission_type{0xFF};
  std::uint8_t count{0};
  std::array<std::uint32_t, 8> entries{};
};

class ScriptedDrive {
 public:
  // without_limits: no 0x607D and 0x607F, as some drives have neither.
  explicit ScriptedDrive(NodeId node, bool without_limits = false) : node_{node} {
    using A = OdAccess;
    auto& e = entries_;
    e.push_back(od_entry(obj::device_type, 0, device_type, A::ro));
    e.push_back(od_entry(obj::communication_cycle_period, 0, cycle_period_us, A::rw));
    e.push_back(od_entry(obj::consumer_heartbeat_time, 1, consumer_heartbeat, A::rw));
    e.push_back(od_entry(obj::producer_heartbeat_time, 0, producer_heartbeat_ms, A::rw));
    for (std::uint8_t i = 0; i < 4; ++i) e.push_back(od_entry(obj::identity, i + 1, identity[i], A::ro));
    for (std::uint16_t n = 0; n < 4; ++n) {
      add_pdo(0x1400 + n, 0x1600 + n, rpdo[n]);
    }
    for (std::uint16_t n = 0; n < 4; ++n) {
      add_pdo(0x1800 + n, 0x1A00 + n, tpdo[n]);
    }
    e.push_back(od_entry(obj::communication_loss_periods, 0, loss_periods, A::rw));
    e.push_back(od_entry(obj::controlword, 0, controlword, A::rw, true));
    e.push_back(od_entry(obj::statusword, 0, statusword, A::ro, true));
    e.push_back(od_entry(obj::modes_of_operation, 0, mode, A::rw));
    e.push_back(od_entry(obj::modes_of_operation_display, 0, mode_display, A::ro));
    e.push_back(od_entry(obj::position_actual, 0, position_actual, A::ro, true));
    e.push_back(od_entry(obj::following_error_window, 0, following_error_window, A::rw));
    e.push_back(od_entry(obj::following_error_timeout, 0, following_error_timeout_ms, A::rw));
    e.push_back(od_entry(obj::velocity_actual, 0, velocity_actual, A::ro, true));
    e.push_back(od_entry(obj::target_position, 0, target_position, A::rw, true));
    if (!without_limits) {
      e.push_back(od_entry(obj::software_position_limit, 1, position_min, A::rw));
      e.push_back(od_entry(obj::software_position_limit, 2, position_max, A::rw));
      e.push_back(od_entry(obj::max_profile_velocity, 0, max_profile_velocity, A::rw));
    }
    e.push_back(od_entry(0x60C2, 1, ip_value, A::rw));
    e.push_back(od_entry(0x60C2, 2, ip_index, A::rw));
    e.push_back(od_entry(0x60F4, 0, following_error_actual, A::ro, true));
    std::sort(entries_.begin(), entries_.end(),
              [](const OdEntry& a, const OdEntry& b) { return a.index != b.index ? a.index < b.index : a.sub < b.sub; });
    od_ = ObjectDictionary{entries_};
    od_.set_hooks(nullptr, &ScriptedDrive::written, this);
  }
  ScriptedDrive(const ScriptedDrive&) = delete;
  ScriptedDrive& operator=(const ScriptedDrive&) = delete;

  // Answers one frame from the master (SDO requests; everything else is only recorded).
  void on_frame(const CanFrame& f, std::uint64_t now_us, FrameSink& out) {
    received.push_back(f);
    const auto m = decode_sdo_request(f, node_);
    if (m && (m->kind == SdoKind::upload_request || m->kind == SdoKind::download_request) &&
        m->index == silent_index && m->sub == silent_sub && silent_requests > 0) {
      --silent_requests;
      return;
    }
    if (m && m->kind == SdoKind::download_request && m->index == ignored_index && m->sub == ignored_sub) {
      (void)out.put(encode_sdo_download_response(node_, m->index, m->sub));  // "done", and nothing stored
      return;
    }
    (void)server_.on_frame(f, now_us, out);
  }

  ObjectDictionary& od() { return od_; }
  [[nodiscard]] bool is_well_formed() const { return od_.is_well_formed(); }

  // Script.
  std::uint16_t ignored_index{0};
  std::uint8_t ignored_sub{0};
  std::uint16_t silent_index{0};
  std::uint8_t silent_sub{0};
  int silent_requests{0};

  // The objects.
  std::uint32_t device_type{cia402_device_type};
  std::uint32_t cycle_period_us{0};
  std::uint32_t consumer_heartbeat{0};
  std::uint16_t producer_heartbeat_ms{0};
  std::array<std::uint32_t, 4> identity{0x0000'0ABC, 0x0000'0402, 0x0001'0000, 0x1234'5678};
  std::array<ScriptedPdo, 4> rpdo{};
  std::array<ScriptedPdo, 4> tpdo{};
  std::uint8_t loss_periods{1};
  std::uint16_t controlword{0};
  std::uint16_t statusword{0};
  std::int8_t mode{0};
  std::int8_t mode_display{0};
  std::int32_t position_actual{0};
  std::uint32_t following_error_window{0};
  std::uint16_t following_error_timeout_ms{0};
  std::int32_t velocity_actual{0};
  std::int32_t target_position{0};
  std::int32_t position_min{-1'000'000};
  std::int32_t position_max{2'000'000};
  std::uint32_t max_profile_velocity{500'000};
  std::uint8_t ip_value{0};
  std::int8_t ip_index{0};
  std::int32_t following_error_actual{0};
  bool display_follows_mode{true};

  std::vector<CanFrame> received;

 private:
  void add_pdo(std::uint16_t comm, std::uint16_t map, ScriptedPdo& p) {
    using A = OdAccess;
    entries_.push_back(od_entry(comm, 1, p.cob_id, A::rw));
    entries_.push_back(od_entry(comm, 2, p.transmission_type, A::rw));
    entries_.push_back(od_entry(map, 0, p.count, A::rw, false, 0, 8));
    for (std::uint8_t i = 0; i < 8; ++i) entries_.push_back(od_entry(map, i + 1, p.entries[i], A::rw));
  }
  static void written(void* context, const OdEntry& entry) {
    auto* self = static_cast<ScriptedDrive*>(context);
    if (entry.index == obj::modes_of_operation && self->display_follows_mode) self->mode_display = self->mode;
  }

  NodeId node_;
  std::vector<OdEntry> entries_;
  ObjectDictionary od_;
  SdoServer server_{node_, od_};
};

}  // namespace settle::hal::canopen::test
