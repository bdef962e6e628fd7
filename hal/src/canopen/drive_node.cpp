// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/drive_node.hpp"

#include <algorithm>

namespace settle::hal::canopen {

namespace {

[[nodiscard]] DriveObjects defaults_for(const DriveNodeConfig& c) noexcept {
  DriveObjects o{};
  o.comm.cycle_period_us = c.sync_period_us;
  o.comm.cob_id_emcy = cob_id(cob::emcy, c.node);
  o.comm.producer_heartbeat_ms = c.heartbeat_period_ms;
  o.comm.vendor_id = c.vendor_id;
  o.comm.product_code = c.product_code;
  o.comm.revision = c.revision;
  o.comm.serial = c.serial;
  o.comm.sync_counter_overflow = c.sync_counter_overflow;
  o.comm.sdo_cob_rx = cob_id(cob::sdo_rx, c.node);
  o.comm.sdo_cob_tx = cob_id(cob::sdo_tx, c.node);
  const auto describe = [&c](const PdoMapping& m, bool receive, std::size_t number, DriveCommObjects::PdoComm& comm,
                             DriveCommObjects::PdoMap& map) {
    comm.cob_id = drive_pdo_cob_id(m.cob_id, receive, number, c.node);
    comm.transmission_type = m.transmission_type;
    map.count = m.count <= map.entries.size() ? m.count : 0;
    for (std::size_t i = 0; i < map.entries.size(); ++i) {
      map.entries[i] = m.entries[i].raw();
    }
  };
  for (std::size_t i = 0; i < drive_rpdo_capacity; ++i) {
    describe(c.rpdos[i], true, i + 1, o.comm.rpdo_comm[i], o.comm.rpdo_map[i]);
  }
  for (std::size_t i = 0; i < drive_tpdo_capacity; ++i) {
    describe(c.tpdos[i], false, i + 1, o.comm.tpdo_comm[i], o.comm.tpdo_map[i]);
  }
  o.comm.device_type = c.device_type;

  o.app.communication_loss_periods = c.communication_loss_periods;
  o.app.abort_connection_option = c.abort_connection_option;
  o.app.quick_stop_option = c.quick_stop_option;
  o.app.following_error_window = c.following_error_window;
  o.app.following_error_timeout_ms = c.following_error_timeout_ms;
  o.app.position_limit_min = c.position_limit_min;
  o.app.position_limit_max = c.position_limit_max;
  o.app.max_profile_velocity = c.max_profile_velocity;
  // 0x6502 bit n-1 for mode n: interpolated position (7) and cyclic synchronous position (8).
  o.app.supported_modes = (1U << 6U) | (1U << 7U);
  return o;
}

// The mapping a PDO's communication and mapping objects describe, with `count` entries.
[[nodiscard]] PdoMapping mapping_of(const DriveCommObjects::PdoComm& comm, const DriveCommObjects::PdoMap& map,
                                    std::size_t count) noexcept {
  PdoMapping m{};
  m.cob_id = comm.cob_id & pdo_cob_id_mask;
  m.transmission_type = comm.transmission_type;
  m.count = static_cast<std::uint8_t>(count <= map.entries.size() ? count : map.entries.size());
  for (std::size_t i = 0; i < m.count; ++i) {
    const std::uint32_t raw = map.entries[i];
    m.entries[i] = PdoMappingEntry{static_cast<std::uint16_t>(raw >> 16U), static_cast<std::uint8_t>((raw >> 8U) & 0xFFU),
                                   static_cast<std::uint8_t>(raw & 0xFFU)};
  }
  return m;
}

[[nodiscard]] bool is_synchronous(std::int64_t transmission_type) noexcept {
  return transmission_type >= 1 && transmission_type <= 240;  // CiA 301: every n-th SYNC
}

[[nodiscard]] std::uint8_t register_bits_for(std::uint16_t error_code) noexcept {
  switch (error_code >> 8U) {
    case 0x81:
    case 0x82: return error_register::communication;
    case 0x84:  // CiA 402: velocity speed controller (the step limit)
    case 0x86: return error_register::device_profile;
    default: return 0;
  }
}

// The objects the step limit (0x607F x the shorter of 0x1006 and 0x60C2), the SYNC checks
// (0x1006, 0x1019, 0x2001) and the following-error and master-heartbeat checks (0x6065, 0x6066,
// 0x1016) are made of.
[[nodiscard]] bool limits_safety(std::uint16_t index) noexcept {
  switch (index) {
    case obj::communication_cycle_period:
    case obj::consumer_heartbeat_time:
    case obj::sync_counter_overflow:
    case obj::communication_loss_periods:
    case obj::following_error_window:
    case obj::following_error_timeout:
    case obj::max_profile_velocity:
    case obj::interpolation_time_period:
      return true;
    default:
      return false;
  }
}

[[nodiscard]] bool is_supported_mode(std::int64_t mode) noexcept {
  return mode == static_cast<std::int8_t>(OperationMode::interpolated_position) ||
         mode == static_cast<std::int8_t>(OperationMode::cyclic_synchronous_position);
}

// A third party's NMT command that ends the master's control of an enabled drive: the node
// leaves operational (no more setpoints, no more feedback), or its communication is reset.
// Reset node is left out: it resets the application too, power stage included.
[[nodiscard]] bool aborts_connection(NmtCommand command, NmtState state) noexcept {
  switch (command) {
    case NmtCommand::stop: return state != NmtState::stopped;
    case NmtCommand::enter_pre_operational: return state == NmtState::operational;
    case NmtCommand::reset_communication: return true;
    case NmtCommand::start:
    case NmtCommand::reset_node: return false;
  }
  return false;
}

// Position counts wrap modulo 2^32, as a drive's position counter does: the distance from b
// to a is the short way round, in -2^31..2^31-1, widened so that its magnitude cannot overflow.
[[nodiscard]] std::int64_t position_difference(std::int32_t a, std::int32_t b) noexcept {
  return std::int64_t{static_cast<std::int32_t>(static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b))};
}

[[nodiscard]] std::int64_t magnitude(std::int64_t v) noexcept { return v < 0 ? -v : v; }

}  // namespace

EmcyDetail emcy_detail(std::uint8_t cause, std::int64_t value) noexcept {
  constexpr std::int64_t lo = std::numeric_limits<std::int32_t>::min();
  constexpr std::int64_t hi = std::numeric_limits<std::int32_t>::max();
  const auto v = static_cast<std::uint32_t>(static_cast<std::int32_t>(value < lo ? lo : (value > hi ? hi : value)));
  return {cause, static_cast<std::uint8_t>(v & 0xFFU), static_cast<std::uint8_t>((v >> 8U) & 0xFFU),
          static_cast<std::uint8_t>((v >> 16U) & 0xFFU), static_cast<std::uint8_t>(v >> 24U)};
}

DriveNode::DriveNode(const DriveNodeConfig& config) noexcept
    : config_{config},
      objects_{defaults_for(config)},
      od_{make_entries()},
      nmt_{config.node},
      sdo_{config.node, od_},
      heartbeat_{config.node, config.heartbeat_period_ms},
      master_heartbeat_{0, 0},
      sync_{config.sync_period_us, config.communication_loss_periods},
      emcy_{config.node} {
  od_.set_hooks(&DriveNode::check_write, &DriveNode::on_written, this);
  restore(true);
}

std::span<const OdEntry> DriveNode::make_entries() noexcept {
  using A = OdAccess;
  constexpr bool map = true;
  DriveCommObjects& c = objects_.comm;
  DriveAppObjects& a = objects_.app;
  std::size_t n = 0;
  const auto add = [this, &n](const OdEntry& e) noexcept {
    if (n < entries_.size()) {
      entries_[n++] = e;
    }
  };
  add(od_entry(obj::device_type, 0, c.device_type, A::ro));
  add(od_entry(obj::error_register, 0, c.error_register, A::ro, map));
  add(od_entry(obj::cob_id_sync, 0, c.cob_id_sync, A::ro));
  if (config_.has_communication_cycle_period) {
    add(od_entry(obj::communication_cycle_period, 0, c.cycle_period_us, A::rw));
  }
  add(od_bytes_entry(obj::device_name, 0, device_name_, OdType::visible_string, A::constant));
  add(od_bytes_entry(obj::hardware_version, 0, hardware_version_, OdType::visible_string, A::constant));
  add(od_bytes_entry(obj::software_version, 0, software_version_, OdType::visible_string, A::constant));
  add(od_entry(obj::cob_id_emcy, 0, c.cob_id_emcy, A::ro));
  add(od_entry(obj::inhibit_time_emcy, 0, c.inhibit_time_emcy, A::rw));
  add(od_entry(obj::consumer_heartbeat_time, 0, c.consumer_heartbeat_count, A::constant));
  add(od_entry(obj::consumer_heartbeat_time, 1, c.consumer_heartbeat, A::rw));
  add(od_entry(obj::producer_heartbeat_time, 0, c.producer_heartbeat_ms, A::rw));
  add(od_entry(obj::identity, 0, c.identity_count, A::constant));
  add(od_entry(obj::identity, 1, c.vendor_id, A::ro));
  add(od_entry(obj::identity, 2, c.product_code, A::ro));
  add(od_entry(obj::identity, 3, c.revision, A::ro));
  add(od_entry(obj::identity, 4, c.serial, A::ro));
  add(od_entry(obj::sync_counter_overflow, 0, c.sync_counter_overflow, A::rw, false, 0, sync_counter_max));
  add(od_entry(obj::sdo_server_parameter, 0, c.sdo_parameter_count, A::constant));
  add(od_entry(obj::sdo_server_parameter, 1, c.sdo_cob_rx, A::ro));
  add(od_entry(obj::sdo_server_parameter, 2, c.sdo_cob_tx, A::ro));

  // The PDOs: communication (sub 1 COB-ID, sub 2 transmission type) and mapping objects, in
  // index order. Writable ones expose every mapping sub-index; static ones their mapped entries.
  const A pdo_access = config_.pdo_mapping_writable ? A::rw : A::ro;
  const std::size_t rpdos = config_.rpdo_count < drive_rpdo_capacity ? config_.rpdo_count : drive_rpdo_capacity;
  const std::size_t tpdos = config_.tpdo_count < drive_tpdo_capacity ? config_.tpdo_count : drive_tpdo_capacity;
  const auto add_comm = [&](std::uint16_t index, DriveCommObjects::PdoComm& comm) noexcept {
    add(od_entry(index, 0, comm.count, A::constant));
    add(od_entry(index, 1, comm.cob_id, pdo_access));
    add(od_entry(index, 2, comm.transmission_type, pdo_access));
  };
  const auto add_map = [&](std::uint16_t index, DriveCommObjects::PdoMap& m, std::uint8_t listed) noexcept {
    add(od_entry(index, 0, m.count, pdo_access));
    // Writable: every sub-index. Static: the mapped entries, or as many as the description lists
    // past the count (unused ones), never more than the object holds.
    const std::size_t rows = config_.pdo_mapping_writable
                                 ? m.entries.size()
                                 : std::min(std::max<std::size_t>(listed, m.count), m.entries.size());
    for (std::size_t i = 0; i < rows; ++i) {
      add(od_entry(index, static_cast<std::uint8_t>(i + 1), m.entries[i], pdo_access));
    }
  };
  for (std::size_t i = 0; i < rpdos; ++i) {
    add_comm(static_cast<std::uint16_t>(obj::rpdo1_communication + i), c.rpdo_comm[i]);
  }
  for (std::size_t i = 0; i < rpdos; ++i) {
    add_map(static_cast<std::uint16_t>(obj::rpdo1_mapping + i), c.rpdo_map[i], config_.rpdo_mapping_rows[i]);
  }
  for (std::size_t i = 0; i < tpdos; ++i) {
    add_comm(static_cast<std::uint16_t>(obj::tpdo1_communication + i), c.tpdo_comm[i]);
  }
  for (std::size_t i = 0; i < tpdos; ++i) {
    add_map(static_cast<std::uint16_t>(obj::tpdo1_mapping + i), c.tpdo_map[i], config_.tpdo_mapping_rows[i]);
  }

  // The load encoder at its manufacturer index, in index order around 0x2001 (the table is sorted).
  const bool load_elsewhere = config_.load_position_index > obj::communication_loss_periods &&
                              config_.load_position_index <= obj::manufacturer_index_last;
  const std::uint16_t load_index = load_elsewhere || config_.load_position_index == obj::load_position_actual
                                       ? config_.load_position_index
                                       : obj::load_position_actual;
  const std::uint8_t load_sub = load_index == config_.load_position_index ? config_.load_position_sub : 0;
  if (config_.has_load_position && !load_elsewhere) {
    add(od_entry(load_index, load_sub, a.load_position, A::ro, map));
  }
  add(od_entry(obj::communication_loss_periods, 0, a.communication_loss_periods, A::rw, false, 1, 255));
  if (config_.has_load_position && load_elsewhere) {
    add(od_entry(load_index, load_sub, a.load_position, A::ro, map));
  }
  add(od_entry(obj::abort_connection_option, 0, a.abort_connection_option, A::rw, false, 0, 3));
  add(od_entry(obj::error_code, 0, a.error_code, A::ro, map));
  add(od_entry(obj::controlword, 0, a.controlword, A::rw, map));
  add(od_entry(obj::statusword, 0, a.statusword, A::ro, map));
  add(od_entry(obj::quick_stop_option, 0, a.quick_stop_option, A::rw, false, 0, 8));
  add(od_entry(obj::modes_of_operation, 0, a.mode, A::rw, map));
  add(od_entry(obj::modes_of_operation_display, 0, a.mode_display, A::ro, map));
  add(od_entry(obj::position_actual, 0, a.position_actual, A::ro, map));
  add(od_entry(obj::following_error_window, 0, a.following_error_window, A::rw));
  add(od_entry(obj::following_error_timeout, 0, a.following_error_timeout_ms, A::rw));
  if (config_.has_velocity_actual) add(od_entry(obj::velocity_actual, 0, a.velocity_actual, A::ro, map));
  add(od_entry(obj::target_position, 0, a.target_position, A::rw, map));
  add(od_entry(obj::software_position_limit, 0, a.position_limit_count, A::constant));
  add(od_entry(obj::software_position_limit, 1, a.position_limit_min, A::rw));
  add(od_entry(obj::software_position_limit, 2, a.position_limit_max, A::rw));
  add(od_entry(obj::max_profile_velocity, 0, a.max_profile_velocity, A::rw, false, 1));
  add(od_entry(obj::interpolation_data_record, 0, a.ip_data_count, A::constant));
  add(od_entry(obj::interpolation_data_record, 1, a.ip_data, A::rw, map));
  if (config_.has_interpolation_period) {
    add(od_entry(obj::interpolation_time_period, 0, a.ip_period_count, A::constant));
    add(od_entry(obj::interpolation_time_period, 1, a.ip_period_value, A::rw));
    add(od_entry(obj::interpolation_time_period, 2, a.ip_period_index, A::rw, false, -6, 0));
  }
  if (config_.has_following_error_actual) {
    add(od_entry(obj::following_error_actual, 0, a.following_error_actual, A::ro, map));
  }
  add(od_entry(obj::supported_drive_modes, 0, a.supported_modes, A::ro));
  return {entries_.data(), n};
}

void DriveNode::bind_pdos() noexcept {
  // A default mapping that cannot be bound leaves its PDO unbound: neither sent nor applied
  // (default_mapping_error() says why; Settle's default mapping always binds, a test checks it).
  const DriveCommObjects& c = objects_.comm;
  for (std::size_t i = 0; i < drive_rpdo_capacity; ++i) {
    (void)rpdo_[i].bind(mapping_of(c.rpdo_comm[i], c.rpdo_map[i], c.rpdo_map[i].count), od_, PdoDirection::receive);
  }
  for (std::size_t i = 0; i < drive_tpdo_capacity; ++i) {
    (void)tpdo_[i].bind(mapping_of(c.tpdo_comm[i], c.tpdo_map[i], c.tpdo_map[i].count), od_, PdoDirection::transmit);
  }
}

SdoAbort DriveNode::default_mapping_error() noexcept {
  // Each PDO in the dictionary that is valid or maps something must bind.
  const auto check = [this](const auto& pdos, std::size_t count, PdoDirection direction) noexcept {
    PdoBinding trial{};
    for (std::size_t i = 0; i < count && i < pdos.size(); ++i) {
      const PdoMapping& m = pdos[i];
      if (m.count > drive_pdo_entry_capacity) {
        return SdoAbort::pdo_too_long;
      }
      if ((m.cob_id & pdo_cob_invalid) == 0 || m.count != 0) {
        if (const SdoAbort abort = trial.bind(m, od_, direction); abort != SdoAbort::none) {
          return abort;
        }
      }
    }
    return SdoAbort::none;
  };
  const SdoAbort rpdos = check(config_.rpdos, config_.rpdo_count, PdoDirection::receive);
  return rpdos != SdoAbort::none ? rpdos : check(config_.tpdos, config_.tpdo_count, PdoDirection::transmit);
}

bool DriveNode::rpdo_active(std::size_t i) const noexcept {
  return i < config_.rpdo_count && i < drive_rpdo_capacity &&
         (objects_.comm.rpdo_comm[i].cob_id & pdo_cob_invalid) == 0 && rpdo_[i].bound();
}

bool DriveNode::tpdo_active(std::size_t i) const noexcept {
  // CiA 301: a mapping whose sub 0 is 0 is disabled, and its PDO not sent (no empty frames).
  return i < config_.tpdo_count && i < drive_tpdo_capacity &&
         (objects_.comm.tpdo_comm[i].cob_id & pdo_cob_invalid) == 0 && tpdo_[i].bound() &&
         objects_.comm.tpdo_map[i].count != 0;
}

void DriveNode::restore(bool application) noexcept {
  const DriveObjects defaults = defaults_for(config_);
  // The error register reports the device's errors, not a parameter: a reset of the
  // communication alone keeps it (the drive may still be in fault).
  const std::uint8_t error_register = objects_.comm.error_register;
  objects_.comm = defaults.comm;
  if (!application) {
    objects_.comm.error_register = error_register;
  }
  if (application) {
    // The feedback is the machine's, not a parameter: a reset of the drive's software leaves the
    // axis where it is, so the position it holds and latches at enabling stays the axis's.
    const DriveAppObjects before = objects_.app;
    objects_.app = defaults.app;
    objects_.app.position_actual = before.position_actual;
    objects_.app.velocity_actual = before.velocity_actual;
    objects_.app.load_position = before.load_position;
    power_.reset();
    latch_pending_ = false;
    disable_after_stop_ = false;
    setpoint_ = objects_.app.position_actual;
    accepted_target_ = objects_.app.position_actual;
    following_error_ = false;
    limit_active_ = false;
    following_error_timer_.disarm();
    sync_error_reported_ = false;
    pdo_length_error_ = false;
    length_ok_since_error_ = false;
  }
  for (auto& pending : pending_rpdo_) {
    pending.reset();
  }
  bind_pdos();
  rpdo_missing_run_ = 0;
  controlword_written_ = false;
  apply_configuration(0);
  update_statusword();
}

void DriveNode::apply_configuration(std::uint16_t index) noexcept {
  // Only the object that changed is re-applied: reconfiguring a watchdog restarts it, and
  // process data (written every SYNC) must not do that.
  const bool all = index == 0;
  const DriveCommObjects& c = objects_.comm;
  if (all || index == obj::producer_heartbeat_time) {
    heartbeat_.set_period_ms(c.producer_heartbeat_ms);
  }
  if (all || index == obj::consumer_heartbeat_time) {
    master_heartbeat_.configure(static_cast<NodeId>((c.consumer_heartbeat >> 16U) & 0xFFU),
                                static_cast<std::uint16_t>(c.consumer_heartbeat & 0xFFFFU));
  }
  if (all || index == obj::communication_cycle_period || index == obj::communication_loss_periods ||
      index == obj::interpolation_time_period) {
    // 0x1006 = 0 (no period given) never switches the SYNC loss and rate checks off: they run on
    // the period the step limit uses (0x60C2), which the master's SYNCs must keep anyway.
    sync_.configure(c.cycle_period_us != 0 ? c.cycle_period_us : interpolation_period_us(),
                    objects_.app.communication_loss_periods);
  }
  if (all || index == obj::sync_counter_overflow) {
    sync_.set_counter_overflow(c.sync_counter_overflow);
  }
  if (all || index == obj::inhibit_time_emcy) {
    emcy_.set_inhibit_us(std::uint32_t{c.inhibit_time_emcy} * 100U);
  }
  if (all || index == obj::quick_stop_option) {
    power_.set_quick_stop_option(objects_.app.quick_stop_option);
  }
}

void DriveNode::start(std::uint64_t now_us, FrameSink& out) noexcept {
  nmt_.boot(out);
  heartbeat_.start(now_us + std::uint64_t{objects_.comm.producer_heartbeat_ms} * 1000U);
}

DriveEvent DriveNode::on_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept {
  if (!is_canopen_data_frame(frame)) {
    return DriveEvent::none;
  }
  if (frame.id == cob::nmt) {
    const auto message = decode_nmt(frame);
    if (!message || (message->node != 0 && message->node != config_.node)) {
      return DriveEvent::none;
    }
    // 0x6007 before the state changes: a stopped node may send no EMCY, and the master must
    // learn why its drive went away.
    if (power_.enabled() && aborts_connection(message->command, nmt_.state())) {
      connection_lost(emcy_code::communication,
                      emcy_detail(emcy_cause::nmt_command, static_cast<std::uint8_t>(message->command)), now_us, out);
      // Whatever 0x6007 says, the power stage does not stay enabled without setpoints: with
      // 0x6007 = 0 the drive disables itself (the drive-defined reaction, CiA 402), and a quick
      // stop (0x6007 = 3) ends in switch on disabled even when 0x605A would stay in quick stop.
      if (power_.enabled()) {
        (void)power_.apply(Cia402Command::disable_voltage);
      }
      disable_after_stop_ = power_.state() == Cia402State::quick_stop_active;
      update_statusword();
    }
    const NmtState nmt_before = nmt_.state();
    const NmtEvent event = nmt_.on_message(*message, out);
    if (message->command == NmtCommand::start && nmt_before != NmtState::operational &&
        nmt_.state() == NmtState::operational) {
      // The first controlword after NMT start is taken as following a 0: a fault reset (bit 7)
      // in the first RPDO is a rising edge, whatever controlword came before the node stopped.
      power_.forget_controlword();
    }
    if (event == NmtEvent::reset_application || event == NmtEvent::reset_communication) {
      sdo_.reset();
      restore(event == NmtEvent::reset_application);
      heartbeat_.start(now_us + std::uint64_t{objects_.comm.producer_heartbeat_ms} * 1000U);
      return event == NmtEvent::reset_application ? DriveEvent::reset : DriveEvent::handled;
    }
    on_nmt(*message, now_us, out);
    return DriveEvent::handled;
  }
  // Error control runs in every NMT state, stopped included.
  if (is_valid_node(master_heartbeat_.watched()) && frame.id == cob_id(cob::heartbeat, master_heartbeat_.watched())) {
    (void)master_heartbeat_.on_frame(frame, now_us);
    return DriveEvent::handled;
  }
  if (nmt_.state() == NmtState::stopped) {
    return DriveEvent::none;
  }
  if (frame.id == objects_.comm.cob_id_sync) {
    const auto sync = decode_sync(frame);
    if (!sync) {
      // Two to eight bytes: neither no counter (0x1019 = 0) nor one (0x1019 set). CiA 301's
      // unexpected SYNC data length, reported as CANopenNode does; no period is run for it.
      return frame.len >= 2 ? on_sync_length_error(frame.len, now_us, out) : DriveEvent::none;
    }
    // The rate check measures the frame's receive time when the bus gives one (SO_TIMESTAMP, the
    // loopback hub's clock): a receiver that was descheduled reads a burst of SYNCs that were
    // sent one period apart.
    return on_sync(*sync, now_us, frame.timestamp_us != 0 ? frame.timestamp_us : now_us, out);
  }
  if (frame.id == objects_.comm.sdo_cob_rx) {
    if (!sdo_.on_frame(frame, now_us, out)) {
      return DriveEvent::none;
    }
    apply_written_controlword(now_us, out);
    return DriveEvent::handled;
  }
  if (!nmt_.pdo_allowed()) {
    return DriveEvent::none;
  }
  for (std::size_t i = 0; i < drive_rpdo_capacity; ++i) {
    if (!rpdo_active(i) || frame.id != (objects_.comm.rpdo_comm[i].cob_id & pdo_cob_id_mask)) {
      continue;
    }
    // A frame too short for the mapping cannot be processed: refused now, so that it never
    // replaces a good RPDO already latched for this period.
    const std::size_t mapped = rpdo_[i].byte_length();
    if (frame.len < mapped) {
      ++counters_.rpdos_rejected;
      pdo_length_error_ = true;
      length_ok_since_error_ = false;
      signal_error(emcy_code::pdo_length, error_register::communication, emcy_detail(emcy_cause::none), now_us, out);
      return DriveEvent::handled;
    }
    // A frame of the mapped length after a length error shows the condition is gone (cleared
    // when it is applied); a longer one is reported when it is applied.
    length_ok_since_error_ = pdo_length_error_ && frame.len == mapped;
    // Synchronous RPDO: latched now, applied at the next SYNC (CiA 301 transmission type 1..240).
    if (pending_rpdo_[i]) {
      ++counters_.rpdos_overwritten;
    }
    pending_rpdo_[i] = frame;
    return DriveEvent::handled;
  }
  return DriveEvent::none;
}

bool DriveNode::fresh_target() const noexcept {
  for (std::size_t i = 0; i < drive_rpdo_capacity; ++i) {
    if (pending_rpdo_[i] && rpdo_active(i) && (rpdo_[i].carries(obj::target_position, 0) ||
                             rpdo_[i].carries(obj::interpolation_data_record, 1))) {
      return true;
    }
  }
  return false;
}

void DriveNode::on_nmt(const NmtMessage& message, std::uint64_t /*now_us*/, FrameSink& /*out*/) noexcept {
  if (message.command == NmtCommand::start) {
    for (auto& pending : pending_rpdo_) {
      pending.reset();
    }
    rpdo_missing_run_ = 0;
  }
}

DriveEvent DriveNode::on_sync(const SyncMessage& sync, std::uint64_t now_us, std::uint64_t received_us,
                             FrameSink& out) noexcept {
  ++counters_.syncs;
  // The step window's clock: a simulated axis that advances one period per SYNC lives in SYNC
  // time (every SYNC one period after the previous, however they arrived); a real one in the
  // time the drive processes the SYNC.
  period_time_us_ = config_.axis_moves_one_period_per_sync ? period_time_us_ + step_period_us() : now_us;
  SyncEvent event = sync_.on_sync(sync, now_us, received_us);
  if (event == SyncEvent::too_many && fresh_target() && nmt_.pdo_allowed()) {
    // Too early, but it brings its own fresh RPDO: the master's own period delivered late (a
    // replay catching up after a stall), not an extra SYNC. A duplicated SYNC, or a second
    // producer's, has no RPDO of its own: it is the one refused (a foreign SYNC that takes the
    // master's RPDO leaves the master's SYNC without one). The step limit bounds every step,
    // the step window the steps within a period (two such SYNCs move the axis one step).
    event = SyncEvent::in_order;
  }
  if (event == SyncEvent::out_of_sequence) {
    ++counters_.sync_gaps;
  }
  if (is_sync_error(event)) {
    ++counters_.sync_errors;
    // Enforced while the drive drives the axis (operation enabled, or bringing it to rest): a
    // SYNC that is not the next period must not run one. A drive that holds a disabled axis
    // moves nothing either way and only counts it.
    if (power_.enabled() || power_.stopping()) {
      if (!sync_error_reported_) {
        sync_error_reported_ = true;
        // A SYNC whose counter does not match 0x1019 (none while one is configured, or one above
        // 0x1019) is CiA 301's unexpected SYNC data length; a repeated or skipped counter, or a
        // rate beyond one per period, is a communication error.
        const bool mismatch = event == SyncEvent::unexpected_length || event == SyncEvent::out_of_range;
        const std::uint8_t cause = event == SyncEvent::unexpected_length ? emcy_cause::sync_length
                                   : event == SyncEvent::too_many        ? emcy_cause::sync_rate
                                                                         : emcy_cause::sync_counter;
        connection_lost(mismatch ? emcy_code::sync_data_length : emcy_code::communication,
                        emcy_detail(cause, sync.counter), now_us, out);
      }
      update_statusword();
      return DriveEvent::sync_rejected;  // the latched RPDO waits for the next good SYNC
    }
    if (event == SyncEvent::unexpected_length && !sync_error_reported_) {
      // Disabled: the period runs (the axis holds), but a length that does not match 0x1019 is
      // a configuration error the master must hear of (CiA 301, as CANopenNode reports it).
      sync_error_reported_ = true;
      signal_error(emcy_code::sync_data_length, error_register::communication,
                   emcy_detail(emcy_cause::sync_length, sync.counter), now_us, out);
    }
  }
  if (nmt_.pdo_allowed()) {
    // RPDO loss: no fresh RPDO carrying the target (whichever PDO maps it) for this period.
    const bool target_fresh = fresh_target();
    bool target_received = false;  // applied: 0x607A or 0x60C1:01
    bool target_applied = false;    // 0x607A without 0x60C1:01
    for (std::size_t i = 0; i < drive_rpdo_capacity; ++i) {
      if (!pending_rpdo_[i] || !rpdo_active(i)) {
        pending_rpdo_[i].reset();  // a PDO disabled since: not applied
        continue;
      }
      const PdoStatus status = rpdo_[i].unpack(*pending_rpdo_[i]);
      pending_rpdo_[i].reset();
      if (status == PdoStatus::applied_longer) {
        pdo_length_error_ = true;
        signal_error(emcy_code::pdo_length_exceeded, error_register::communication, emcy_detail(emcy_cause::none),
                     now_us, out);
      } else if (status == PdoStatus::ok && length_ok_since_error_) {
        // The length error is gone: clear 0x603F/0x1001 with EMCY 0000, unless a later error
        // (a fault, a SYNC error) is what they now report.
        pdo_length_error_ = false;
        length_ok_since_error_ = false;
        const std::uint16_t code = objects_.app.error_code;
        if ((code == emcy_code::pdo_length || code == emcy_code::pdo_length_exceeded) &&
            power_.state() != Cia402State::fault && !power_.stopping()) {
          clear_errors(now_us, out);
        }
      }
      if (status == PdoStatus::ok || status == PdoStatus::applied_longer) {
        const bool position = rpdo_[i].carries(obj::target_position, 0);
        const bool ip = rpdo_[i].carries(obj::interpolation_data_record, 1);
        target_received = target_received || position || ip;
        target_applied = target_applied || (position && !ip);
        ++counters_.rpdos_applied;
      } else {
        ++counters_.rpdos_rejected;
      }
    }
    // Interpolated position takes its setpoint from 0x60C1:01; an RPDO that carries 0x607A
    // (and not 0x60C1:01) feeds the interpolation record too.
    if (target_applied &&
        objects_.app.mode_display == static_cast<std::int8_t>(OperationMode::interpolated_position)) {
      objects_.app.ip_data = objects_.app.target_position;
    }
    // A target that came but was refused neither counts as missing nor ends a run of them.
    if (target_received) {
      rpdo_missing_run_ = 0;
    } else if (!target_fresh && power_.enabled()) {
      ++counters_.rpdos_missing;
      if (++rpdo_missing_run_ > objects_.app.communication_loss_periods) {
        quick_stop_with_emcy(emcy_code::rpdo_timeout, emcy_detail(emcy_cause::rpdo_loss, rpdo_missing_run_), now_us,
                             out);
      }
    }
    apply_written_controlword(now_us, out);
  }

  apply_setpoint(now_us, out);
  update_statusword();
  return DriveEvent::sync;
}

DriveEvent DriveNode::on_sync_length_error(std::uint8_t length, std::uint64_t now_us, FrameSink& out) noexcept {
  ++counters_.sync_errors;
  if (!sync_error_reported_) {
    sync_error_reported_ = true;
    const EmcyDetail detail = emcy_detail(emcy_cause::sync_length, length);
    if (driving()) {
      connection_lost(emcy_code::sync_data_length, detail, now_us, out);  // and the 0x6007 reaction
    } else {
      signal_error(emcy_code::sync_data_length, error_register::communication, detail, now_us, out);
    }
  }
  update_statusword();
  return DriveEvent::sync_rejected;
}

void DriveNode::apply_setpoint(std::uint64_t now_us, FrameSink& out) noexcept {
  DriveAppObjects& a = objects_.app;
  if (following()) {
    const bool ip = a.mode_display == static_cast<std::int8_t>(OperationMode::interpolated_position);
    const std::int32_t target = ip ? a.ip_data : a.target_position;
    // The software position limits (0x607D) clamp the target, but never pull the axis: an axis
    // already outside them (the limits were written while it stood there) holds, and may move back
    // towards them, never further out. Clamping to the limit itself would move it at the SYNC that
    // enables the drive, by however far outside it stands.
    const std::int32_t lo = std::min(a.position_limit_min, accepted_target_);
    const std::int32_t hi = std::max(a.position_limit_max, accepted_target_);
    const std::int32_t clamped = target < lo ? lo : (target > hi ? hi : target);
    // The step limit: a setpoint the axis cannot reach within 0x607F is never applied, whoever
    // wrote it (RPDO or SDO). The step is the short way round the counter's wrap (a move across
    // it is a small step, a jump of 2^31 is the largest there is), its magnitude in 64 bits.
    // Measured from the previous target accepted (the latched position after enabling), which
    // the setpoint follows unless the window below holds it back.
    const std::int64_t step = position_difference(clamped, accepted_target_);
    const std::uint32_t period_us = step_period_us();
    const std::int64_t limit = step_limit_counts(period_us);
    if (magnitude(step) > limit) {
      ++counters_.steps_refused;
      fault_with(emcy_code::velocity, emcy_detail(emcy_cause::step_limit, step), now_us, out);
      return;  // setpoint() stays the last applied one
    }
    accepted_target_ = clamped;
    // Within one period the axis moves at most the step limit, however many SYNCs that period
    // brought (tolerating SYNCs up to a quarter period early).
    const std::uint32_t window_us = period_us - period_us / 4U;
    setpoint_ = step_window_.bound(period_time_us_, clamped, limit, window_us);
    step_window_.push(period_time_us_, setpoint_, window_us);
    if (setpoint_ != clamped) ++counters_.steps_bounded;
    limit_active_ = clamped != target;
  } else if (!power_.enabled()) {
    // Not following: the drive holds where the axis is.
    setpoint_ = a.position_actual;
    limit_active_ = false;
  }
}

std::uint32_t DriveNode::step_period_us() const noexcept {
  const std::uint32_t period_us = interpolation_period_us();
  const std::uint32_t cycle_us = objects_.comm.cycle_period_us;
  return cycle_us != 0 && cycle_us < period_us ? cycle_us : period_us;
}

std::int64_t DriveNode::step_limit_counts() const noexcept { return step_limit_counts(step_period_us()); }

std::int64_t DriveNode::step_limit_counts(std::uint32_t period_us) const noexcept {
  // Both factors are below 2^32: the product and the rounding fit 64 bits.
  const std::uint64_t counts =
      (std::uint64_t{objects_.app.max_profile_velocity} * period_us + 999'999U) / 1'000'000U;
  return static_cast<std::int64_t>(counts);
}

void DriveNode::latch_target() noexcept {
  // Entering operation enabled: the drive's target becomes where the axis is, so the target
  // that came with the enabling controlword (or was written before) moves nothing, and the
  // first setpoint after it is checked against the position actual by the step limit.
  DriveAppObjects& a = objects_.app;
  // An axis that has not reported its position yet (enabled before the first SYNC after power-on)
  // may stand anywhere: hold it (following() is false) and latch at the first publish().
  latch_pending_ = !position_known_;
  a.target_position = a.position_actual;
  a.ip_data = a.position_actual;
  setpoint_ = a.position_actual;
  accepted_target_ = a.position_actual;
  step_window_.reset(period_time_us_, a.position_actual);
  limit_active_ = false;
  sync_.rearm_rate_check();
}

bool DriveNode::following() const noexcept {
  if (!power_.enabled() || latch_pending_) {
    return false;
  }
  const auto mode = static_cast<OperationMode>(objects_.app.mode_display);
  return mode == OperationMode::cyclic_synchronous_position ||
         (mode == OperationMode::interpolated_position &&
          (objects_.app.controlword & controlword::enable_ip_mode) != 0);
}

std::uint32_t DriveNode::interpolation_period_us() const noexcept {
  if (!config_.has_interpolation_period) {
    // No 0x60C2: the drive interpolates over the communication cycle period.
    return objects_.comm.cycle_period_us != 0 ? objects_.comm.cycle_period_us : default_sync_period_us;
  }
  // 0x60C2: value x 10^index s; the index is limited to -6..0, so this is exact in µs.
  constexpr std::array<std::uint32_t, 7> us_per_unit{1, 10, 100, 1'000, 10'000, 100'000, 1'000'000};
  const auto i = static_cast<std::size_t>(objects_.app.ip_period_index + 6);
  return std::uint32_t{objects_.app.ip_period_value} * us_per_unit[i < us_per_unit.size() ? i : 0];
}

void DriveNode::publish(const DriveFeedback& feedback, std::uint64_t now_us, FrameSink& out) noexcept {
  DriveAppObjects& a = objects_.app;
  a.position_actual = feedback.position_actual;
  a.velocity_actual = feedback.velocity_actual;
  a.load_position = feedback.load_position;
  position_known_ = true;
  if (!power_.enabled()) {
    setpoint_ = a.position_actual;
    latch_pending_ = false;
  } else if (latch_pending_) {
    latch_target();  // enabled before the axis reported where it is: now it has
  }
  a.following_error_actual = static_cast<std::int32_t>(position_difference(setpoint_, a.position_actual));

  if (following() && a.following_error_window != following_error_window_off) {
    const std::int64_t deviation = position_difference(setpoint_, a.position_actual);
    following_error_ = magnitude(deviation) > std::int64_t{a.following_error_window};
    const EmcyDetail detail = emcy_detail(emcy_cause::following_error, deviation);
    if (!following_error_) {
      following_error_timer_.disarm();
    } else if (a.following_error_timeout_ms == 0) {
      fault_with(emcy_code::following_error, detail, now_us, out);
    } else {
      if (!following_error_timer_.armed()) {
        following_error_timer_.arm(std::uint64_t{a.following_error_timeout_ms} * 1000U, now_us);
      }
      if (following_error_timer_.check(now_us)) {
        fault_with(emcy_code::following_error, detail, now_us, out);
      }
    }
  }
  update_statusword();

  if (nmt_.pdo_allowed()) {
    // Transmission type n: after every n-th SYNC.
    CanFrame frame{};
    for (std::size_t i = 0; i < drive_tpdo_capacity; ++i) {
      const std::uint8_t every = objects_.comm.tpdo_comm[i].transmission_type;
      if (tpdo_active(i) && every != 0 && counters_.syncs % every == 0 && tpdo_[i].pack(frame) == PdoStatus::ok) {
        (void)out.put(frame);
      }
    }
  }
}

void DriveNode::set_feedback(const DriveFeedback& feedback) noexcept {
  DriveAppObjects& a = objects_.app;
  a.position_actual = feedback.position_actual;
  a.velocity_actual = feedback.velocity_actual;
  a.load_position = feedback.load_position;
  position_known_ = true;
  if (!power_.enabled()) {
    setpoint_ = a.position_actual;
    accepted_target_ = a.position_actual;
    latch_pending_ = false;
  } else if (latch_pending_) {
    latch_target();
  }
  update_statusword();
}

void DriveNode::poll(std::uint64_t now_us, FrameSink& out) noexcept {
  (void)heartbeat_.poll(now_us, nmt_.state(), out);
  if (master_heartbeat_.poll(now_us) == HeartbeatEvent::lost) {
    connection_lost(emcy_code::life_guard, emcy_detail(emcy_cause::heartbeat), now_us, out);
  }
  if (sync_.check_loss(now_us) && power_.enabled() && nmt_.pdo_allowed()) {
    quick_stop_with_emcy(emcy_code::communication, emcy_detail(emcy_cause::sync_loss), now_us, out);
  }
  (void)emcy_.poll(now_us, out);
  sdo_.poll(now_us, out);
}

void DriveNode::raise_fault(std::uint16_t error_code, std::uint64_t now_us, FrameSink& out) noexcept {
  fault_with(error_code, emcy_detail(emcy_cause::none), now_us, out);
}

void DriveNode::fault_with(std::uint16_t error_code, const EmcyDetail& detail, std::uint64_t now_us,
                           FrameSink& out) noexcept {
  if (power_.fault()) {
    following_error_timer_.disarm();
    signal_error(error_code, register_bits_for(error_code), detail, now_us, out);
    update_statusword();
  }
}

void DriveNode::stop_complete() noexcept {
  if (!power_.stop_complete() && disable_after_stop_ && power_.state() == Cia402State::quick_stop_active) {
    (void)power_.apply(Cia402Command::disable_voltage);  // transition 12
  }
  disable_after_stop_ = false;
  update_statusword();
}

void DriveNode::connection_lost(std::uint16_t error_code, const EmcyDetail& detail, std::uint64_t now_us,
                                FrameSink& out) noexcept {
  if (!power_.enabled()) {
    signal_error(error_code, error_register::communication, detail, now_us, out);
    return;
  }
  switch (static_cast<AbortConnectionAction>(objects_.app.abort_connection_option)) {
    case AbortConnectionAction::fault:
      fault_with(error_code, detail, now_us, out);
      return;
    case AbortConnectionAction::disable_voltage:
      (void)power_.apply(Cia402Command::disable_voltage);
      break;
    case AbortConnectionAction::quick_stop:
      (void)power_.apply(Cia402Command::quick_stop);
      break;
    case AbortConnectionAction::none:
      break;
  }
  signal_error(error_code, error_register::communication, detail, now_us, out);
  update_statusword();
}

void DriveNode::quick_stop_with_emcy(std::uint16_t error_code, const EmcyDetail& detail, std::uint64_t now_us,
                                     FrameSink& out) noexcept {
  if (power_.quick_stop()) {
    signal_error(error_code, error_register::communication, detail, now_us, out);
    update_statusword();
  }
}

void DriveNode::signal_error(std::uint16_t error_code, std::uint8_t register_bits, const EmcyDetail& detail,
                             std::uint64_t now_us, FrameSink& out) noexcept {
  objects_.app.error_code = error_code;
  // CiA 301: the generic bit is set whenever any error is present.
  objects_.comm.error_register = static_cast<std::uint8_t>(objects_.comm.error_register | register_bits |
                                                           error_register::generic);
  if (nmt_.emcy_allowed()) {
    (void)emcy_.emit(EmcyMessage{error_code, objects_.comm.error_register, detail}, now_us, out);
    ++counters_.emcy_sent;
  }
}

void DriveNode::clear_errors(std::uint64_t now_us, FrameSink& out) noexcept {
  if (objects_.comm.error_register == 0 && objects_.app.error_code == 0) {
    return;
  }
  objects_.app.error_code = 0;
  objects_.comm.error_register = 0;
  sync_error_reported_ = false;
  if (nmt_.emcy_allowed()) {
    (void)emcy_.emit(EmcyMessage{emcy_code::no_error, 0, {}}, now_us, out);
    ++counters_.emcy_sent;
  }
}

void DriveNode::apply_written_controlword(std::uint64_t now_us, FrameSink& out) noexcept {
  if (!controlword_written_) {
    return;
  }
  controlword_written_ = false;
  const Cia402State before = power_.state();
  if (power_.on_controlword(objects_.app.controlword)) {
    const Cia402State after = power_.state();
    // Errors end with a fault reset, or, for the communication errors that stop but do not
    // fault the drive, when the master enables it again.
    if ((before == Cia402State::fault && after == Cia402State::switch_on_disabled) ||
        after == Cia402State::operation_enabled) {
      clear_errors(now_us, out);
    }
    if (after == Cia402State::operation_enabled && before != Cia402State::operation_enabled) {
      latch_target();
    }
    if (after == Cia402State::operation_enabled) {
      disable_after_stop_ = false;
      following_error_ = false;
      following_error_timer_.disarm();
      rpdo_missing_run_ = 0;
    }
  }
  update_statusword();
}

void DriveNode::update_statusword() noexcept {
  std::uint16_t sw = power_.statusword_bits() | statusword::remote;
  if (following()) {
    sw |= statusword::mode_specific_12;
  }
  if (limit_active_) {
    sw |= statusword::internal_limit;
  }
  if (following_error_) {
    sw |= statusword::following_error;
  }
  objects_.app.statusword = sw;
}

OdBytes DriveNode::constant_text(const char* text) noexcept {
  std::uint32_t length = 0;
  while (text != nullptr && text[length] != '\0') {
    ++length;
  }
  // The dictionary writes a byte string only through a writable entry; these are constant.
  auto* bytes = const_cast<std::uint8_t*>(reinterpret_cast<const std::uint8_t*>(text));
  return OdBytes{bytes, length, length};
}

SdoAbort DriveNode::check_write(void* self, const OdEntry& entry, std::int64_t value) noexcept {
  const auto& node = *static_cast<const DriveNode*>(self);
  const DriveAppObjects& a = node.objects_.app;
  if (entry.index >= obj::rpdo1_communication && entry.index < obj::tpdo1_mapping + drive_tpdo_capacity) {
    return static_cast<DriveNode*>(self)->check_pdo_write(entry, value);
  }
  // While the power stage drives the axis (operation enabled, quick stop, fault reaction), the
  // objects the step limit, the SYNC period and the drive's checks are made of stay as they were
  // when it was enabled: a write that changes one (0x607F = 0xFFFFFFFF, 0x1006 = 0 and 0x60C2 =
  // 255 s, 0x6065 = off) would let the next setpoint through unchecked. Writing the value an
  // object already holds changes nothing and is accepted.
  if (node.driving() && limits_safety(entry.index) && value != entry.var.value()) {
    return SdoAbort::cannot_store_device_state;
  }
  switch (entry.index) {
    case obj::modes_of_operation:
      return is_supported_mode(value) ? SdoAbort::none : SdoAbort::invalid_value;
    case obj::consumer_heartbeat_time: {
      const auto watched = static_cast<std::uint32_t>(value) >> 16U;
      return watched <= node_id_max ? SdoAbort::none : SdoAbort::invalid_value;
    }
    case obj::software_position_limit:
      if ((entry.sub == 1 && value > a.position_limit_max) || (entry.sub == 2 && value < a.position_limit_min)) {
        return SdoAbort::max_below_min;
      }
      return SdoAbort::none;
    case obj::interpolation_time_period:
      return (entry.sub == 1 && value == 0) ? SdoAbort::value_too_low : SdoAbort::none;
    case obj::sync_counter_overflow:
      // CiA 301: 0 (no counter) or 2..240, and written only while 0x1006 is 0 (no SYNC period
      // running), otherwise 0x08000022. Changing it under a running stream would refuse the
      // next SYNC, so it is set before the drive is enabled.
      if (node.power_.enabled() || node.objects_.comm.cycle_period_us != 0) {
        return SdoAbort::cannot_store_device_state;
      }
      return value == 1 ? SdoAbort::invalid_value : SdoAbort::none;
    default:
      return SdoAbort::none;
  }
}

SdoAbort DriveNode::check_pdo_write(const OdEntry& entry, std::int64_t value) noexcept {
  // Only reached for a writable mapping (the static one is read-only in the dictionary). The
  // CiA 301 procedure: disable the PDO (COB-ID bit 31), set mapping sub 0 to 0, write the
  // entries, set sub 0 to their number (which validates and binds them), enable the PDO.
  // Not under an enabled drive's master: remapping TPDO1 makes it read its own target as the
  // position, moving an RPDO's COB-ID takes its setpoints away. CiA 301 allows the procedure in
  // pre-operational (no PDO is exchanged there), and any time the power stage is off.
  if (driving() && nmt_.state() != NmtState::pre_operational) {
    return SdoAbort::cannot_store_device_state;
  }
  const std::uint16_t index = entry.index;
  const bool receive = index < obj::tpdo1_communication;
  const bool mapping = (index & 0x0200U) != 0;
  const std::size_t i = index & 0x00FFU;
  DriveCommObjects& c = objects_.comm;
  DriveCommObjects::PdoComm& comm = receive ? c.rpdo_comm[i] : c.tpdo_comm[i];
  DriveCommObjects::PdoMap& map = receive ? c.rpdo_map[i] : c.tpdo_map[i];
  PdoBinding& binding = receive ? rpdo_[i] : tpdo_[i];
  const PdoDirection direction = receive ? PdoDirection::receive : PdoDirection::transmit;
  const bool valid = (comm.cob_id & pdo_cob_invalid) == 0;
  if (!mapping) {
    if (entry.sub == 2) {
      return is_synchronous(value) ? SdoAbort::none : SdoAbort::invalid_value;
    }
    const auto cob = static_cast<std::uint32_t>(value);
    const bool enable = (cob & pdo_cob_invalid) == 0;
    const std::uint32_t id = cob & pdo_cob_id_mask;
    // 29-bit ids are not supported; the id of a valid PDO cannot change under it.
    if ((cob & pdo_cob_extended) != 0 || (cob & 0x1FFF'F800U) != 0 || id == 0 ||
        (valid && enable && id != (comm.cob_id & pdo_cob_id_mask))) {
      return SdoAbort::invalid_value;
    }
    if (enable && !valid) {
      // Enabling: only with a mapping that binds (sub 0 > 0, every entry valid).
      PdoMapping m = mapping_of(comm, map, map.count);
      m.cob_id = id;
      if (map.count == 0 || binding.bind(m, od_, direction) != SdoAbort::none) {
        return SdoAbort::invalid_value;
      }
    }
    return SdoAbort::none;
  }
  if (valid) {
    return SdoAbort::invalid_value;  // the mapping of a valid PDO cannot change
  }
  if (entry.sub != 0) {
    return map.count == 0 ? SdoAbort::none : SdoAbort::invalid_value;  // entries only while sub 0 is 0
  }
  if (value > static_cast<std::int64_t>(map.entries.size())) {
    return SdoAbort::value_too_high;
  }
  if (value == 0) {
    return SdoAbort::none;
  }
  return binding.bind(mapping_of(comm, map, static_cast<std::size_t>(value)), od_, direction);
}

void DriveNode::on_written(void* self, const OdEntry& entry) noexcept {
  auto& node = *static_cast<DriveNode*>(self);
  switch (entry.index) {
    case obj::controlword:
      // Acted on by the caller of the write, which knows the time and has a sink for EMCY.
      node.controlword_written_ = true;
      break;
    case obj::modes_of_operation:
      node.objects_.app.mode_display = node.objects_.app.mode;
      break;
    default:
      node.apply_configuration(entry.index);
      break;
  }
  node.update_statusword();
}

}  // namespace settle::hal::canopen
