// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/remote_drive.hpp"

#include <bit>

#include "settle/hal/canopen/nmt.hpp"

namespace settle::hal::canopen {

std::uint16_t EnableSequence::next(std::uint16_t statusword) noexcept {
  std::uint16_t cw = controlword::disable_voltage;
  switch (state_from_statusword(statusword)) {
    case Cia402State::fault:
      // Bit 7 must rise: after a 0x80 that did not clear the fault, drop it for one tick.
      cw = (last_ & controlword::fault_reset) != 0 ? controlword::disable_voltage : controlword::fault_reset;
      break;
    case Cia402State::switch_on_disabled: cw = controlword::shutdown; break;
    case Cia402State::ready_to_switch_on: cw = controlword::switch_on; break;
    case Cia402State::switched_on:
    case Cia402State::operation_enabled: cw = controlword::enable_operation; break;
    case Cia402State::quick_stop_active:  // disable voltage ends the quick stop (transition 12)
    case Cia402State::not_ready_to_switch_on:
    case Cia402State::fault_reaction_active: cw = controlword::disable_voltage; break;
  }
  last_ = cw;
  return cw;
}

std::optional<InterpolationPeriod> interpolation_period_from_us(std::uint32_t period_us) noexcept {
  std::uint32_t unit_us = 1'000'000;
  for (int index = 0; index >= -6; --index, unit_us /= 10U) {
    if (period_us != 0 && period_us % unit_us == 0 && period_us / unit_us <= 255U) {
      return InterpolationPeriod{static_cast<std::uint8_t>(period_us / unit_us), static_cast<std::int8_t>(index)};
    }
  }
  return std::nullopt;
}

namespace {
constexpr const char* kStateCodes[] = {SETTLE_HAL_REMOTE_DRIVE_STATES(SETTLE_ENUM_CODE)};
constexpr const char* kStateTexts[] = {SETTLE_HAL_REMOTE_DRIVE_STATES(SETTLE_ENUM_TEXT)};
constexpr const char* kStartupErrorCodes[] = {SETTLE_HAL_STARTUP_ERRORS(SETTLE_ENUM_CODE)};
constexpr const char* kStartupErrorTexts[] = {SETTLE_HAL_STARTUP_ERRORS(SETTLE_ENUM_TEXT)};
}  // namespace

const char* to_string(RemoteDriveState state) noexcept { return enum_text(kStateCodes, state, "?"); }
const char* describe(RemoteDriveState state) noexcept { return enum_text(kStateTexts, state, "?"); }

const char* to_string(StartupError error) noexcept { return enum_text(kStartupErrorCodes, error, "?"); }
const char* describe(StartupError error) noexcept { return enum_text(kStartupErrorTexts, error, "?"); }

std::optional<std::size_t> plan_start_up(const RemoteDriveConfig& config, std::span<StartupStep> out) noexcept {
  std::size_t n = 0;
  bool fits = true;
  const auto add = [&](const StartupStep& s) {
    if (n < out.size()) {
      out[n++] = s;
    } else {
      fits = false;
    }
  };
  using S = StartupStep;
  const auto mode = static_cast<std::uint8_t>(config.mode);
  // A CiA 402 device at all (profile number in the low 16 bits of 0x1000)?
  add(S::check(obj::device_type, 0, cia402_device_type, 2));
  // The drive the user expects, when they said which.
  const std::array<std::uint32_t, 4> identity{config.expected_vendor_id, config.expected_product_code,
                                              config.expected_revision, config.expected_serial};
  for (std::size_t i = 0; i < identity.size(); ++i) {
    if (identity[i] != 0) add(S::check(obj::identity, static_cast<std::uint8_t>(i + 1), identity[i], 4));
  }
  add(S::write(obj::modes_of_operation, 0, mode, 1));
  if (const auto ip = interpolation_period_from_us(config.sync_period_us); ip && config.write_interpolation_period) {
    add(S::write(obj::interpolation_time_period, 1, ip->value, 1));
    add(S::write(obj::interpolation_time_period, 2, static_cast<std::uint8_t>(ip->index), 1));
  }
  if (config.write_sync_period) add(S::write(obj::communication_cycle_period, 0, config.sync_period_us, 4));
  if (config.communication_loss_periods != 0) {
    add(S::write(obj::communication_loss_periods, 0, config.communication_loss_periods, 1));
  }
  if (config.master_node != 0) {
    const std::uint32_t hb = (std::uint32_t{config.master_node} << 16U) | config.master_heartbeat_timeout_ms;
    add(S::write(obj::consumer_heartbeat_time, 1, hb, 4));
  }
  if (config.heartbeat_period_ms != 0) add(S::write(obj::producer_heartbeat_time, 0, config.heartbeat_period_ms, 2));
  if (config.following_error_window != 0) {
    add(S::write(obj::following_error_window, 0, config.following_error_window, 4));
    add(S::write(obj::following_error_timeout, 0, config.following_error_timeout_ms, 2));
  }
  switch (config.pdo_setup) {
    case PdoSetup::assume: break;
    case PdoSetup::dynamic:
      // CiA 301: a PDO is changed while it does not exist (COB-ID bit 31), its mapping while sub 0
      // is 0; then it is given its entries, their number, synchronous transmission, and enabled.
      for (const bool receive : {true, false}) {
        for (std::uint8_t pdo = 1; pdo <= layout_pdo_count; ++pdo) {
          const PdoMapping m = layout_mapping(config.layout, receive, pdo, config.node);
          const std::uint16_t comm = pdo_communication_index(receive, pdo);
          const std::uint16_t map = pdo_mapping_index(receive, pdo);
          if (m.count == 0) {
            add(S::write_cob_id(comm, m.cob_id | pdo_cob_id_invalid, true));  // not used (if it exists): disabled
            continue;
          }
          add(S::write_cob_id(comm, m.cob_id | pdo_cob_id_invalid));
          add(S::write(map, 0, 0, 1));
          for (std::uint8_t i = 0; i < m.count; ++i) {
            add(S::write(map, static_cast<std::uint8_t>(i + 1), m.entries[i].raw(), 4));
          }
          add(S::write(map, 0, m.count, 1));
          add(S::write(comm, 2, m.transmission_type, 1));
          add(S::write_cob_id(comm, m.cob_id));
        }
      }
      break;
    case PdoSetup::read_static:
      for (const bool receive : {true, false}) {
        for (std::uint8_t pdo = 1; pdo <= layout_pdo_count; ++pdo) add(S::read_mapping(pdo_mapping_index(receive, pdo)));
      }
      break;
  }
  // The limits the loop enforces at submit; a drive without them limits nothing.
  add(S::read(obj::software_position_limit, 1, StartupField::position_min, true));
  add(S::read(obj::software_position_limit, 2, StartupField::position_max, true));
  add(S::read(obj::max_profile_velocity, 0, StartupField::max_profile_velocity, true));
  // The drive may accept a mode write and still run another one: trust the display.
  add(S::check(obj::modes_of_operation_display, 0, mode, 1));
  if (!fits) return std::nullopt;
  return n;
}

RemoteDrive::RemoteDrive(const RemoteDriveConfig& config) noexcept
    : config_{config},
      heartbeat_id_{is_valid_node(config.node) ? cob_id(cob::heartbeat, config.node) : ~std::uint32_t{0}},
      sdo_{config.node, config.sdo_timeout_us},
      heartbeat_{config.node, config.heartbeat_timeout_ms},
      emcy_{config.node} {
  static_assert(remote_drive_max_steps <= 255, "step_count_ is a byte");
  // The steps depend on the configuration alone, which is fixed from here on: planned once, so
  // the tick that takes a drive's boot-up (start()) does no division and builds no table.
  if (const auto n = plan_start_up(config_, steps_)) {
    step_count_ = static_cast<std::uint8_t>(*n);
  } else {
    plan_too_long_ = true;
  }
  layout_unusable_ = config_.pdo_setup != PdoSetup::read_static &&
                     check_layout(config_.layout, config_.pdo_setup == PdoSetup::dynamic) != LayoutError::none;
  apply_layout();
}

void RemoteDrive::apply_layout() noexcept {
  const ProcessDataLayout& l = config_.layout;
  default_layout_ = is_default_layout(l);
  status_pdo_ = l.statusword.pdo;
  second_pdo_ = 0;
  period_tpdos_ = 0;
  // A period's TPDOs are those carrying a value the master reads (feedback_tpdos); one a static
  // mapping fills with other objects only (a manufacturer object in TPDO3) is no part of it.
  for (std::uint8_t n = 1; n <= layout_pdo_count; ++n) {
    const std::uint8_t read = layout_pdo_length(l, false, n);
    if (config_.pdo_setup != PdoSetup::read_static) tpdo_len_[n - 1U] = read;
    if (read == 0) continue;
    period_tpdos_ = static_cast<std::uint8_t>(period_tpdos_ | (1U << (n - 1U)));
    if (n != status_pdo_ && second_pdo_ == 0) second_pdo_ = n;
  }
#if SETTLE_HAL_SPLIT_FEEDBACK
  split_ = feedback_split(l);
#endif
  const bool valid = is_valid_node(config_.node);
  const auto id = [&](std::uint8_t n) {
    return valid && n != 0 && n <= layout_pdo_count ? pdo_cob_id(false, n, config_.node) : ~std::uint32_t{0};
  };
  tpdo1_id_ = id(status_pdo_);
  tpdo2_id_ = id(second_pdo_);
  tpdo1_len_ = status_pdo_ != 0 && status_pdo_ <= layout_pdo_count ? tpdo_len_[status_pdo_ - 1U] : 0;
  tpdo2_len_ = second_pdo_ != 0 ? tpdo_len_[second_pdo_ - 1U] : 0;
  held_tpdos_ = 0;
}

inline void RemoteDrive::take_extra_feedback(const CanFrame& frame, std::uint8_t number) noexcept {
  const ProcessDataLayout& l = config_.layout;
  const auto i32 = [&frame](const PdoSlot& s) { return static_cast<std::int32_t>(slot_value(s, frame)); };
  if (slot_carried(l.load_position, number, frame)) feedback_.load_position = i32(l.load_position);
  if (slot_carried(l.velocity_actual, number, frame)) feedback_.velocity_actual = i32(l.velocity_actual);
  if (slot_carried(l.following_error, number, frame)) feedback_.following_error = i32(l.following_error);
}

#if SETTLE_HAL_SPLIT_FEEDBACK
RemoteFrame RemoteDrive::take_period_tpdo(const CanFrame& frame, std::uint8_t number, std::uint64_t now_us) noexcept {
  // A period's TPDOs come in PDO order. One out of that order means the period held lacks its
  // later TPDOs (this one begins the next period), or this one's period lacks its first.
  const unsigned bit = 1U << (number - 1U);
  const unsigned pending = period_tpdos_ & ~unsigned{held_tpdos_};
  if (bit != (pending & (0U - pending))) {
    feedback_.tpdos_dropped += static_cast<std::uint32_t>(std::popcount(held_tpdos_));
    held_tpdos_ = 0;
    if (bit != (period_tpdos_ & (0U - unsigned{period_tpdos_}))) {
      ++feedback_.tpdos_dropped;
      return RemoteFrame::dropped;
    }
  }
  held_tpdos_ = static_cast<std::uint8_t>(held_tpdos_ | bit);
  // The load position, velocity and following error as they come: the loop logs a period's sample
  // when its last TPDO is in, by which time each holds that period's value (a period dropped logs
  // none). The statusword and the position actual wait for their period, and are taken together.
  take_extra_feedback(frame, number);
  const ProcessDataLayout& l = config_.layout;
  if (slot_carried(l.position_actual, number, frame)) held_position_ = static_cast<std::int32_t>(slot_value(l.position_actual, frame));
  if (slot_carried(l.statusword, number, frame)) held_statusword_ = static_cast<std::uint16_t>(slot_value(l.statusword, frame));
  if (held_tpdos_ != period_tpdos_) return RemoteFrame::held;
  held_tpdos_ = 0;
  ++feedback_.periods_complete;
  take_tpdo1(Tpdo1{held_statusword_, held_position_}, now_us);
  return RemoteFrame::tpdo2;
}
#endif

RemoteFrame RemoteDrive::take_layout_tpdo(const CanFrame& frame, std::uint8_t number, std::uint64_t now_us) noexcept {
#if SETTLE_HAL_SPLIT_FEEDBACK
  if (split_) return take_period_tpdo(frame, number, now_us);
#endif
  take_extra_feedback(frame, number);
  const ProcessDataLayout& l = config_.layout;
  if (slot_carried(l.statusword, number, frame)) {
    // The layout keeps the position actual in the statusword's TPDO.
    take_tpdo1(Tpdo1{static_cast<std::uint16_t>(slot_value(l.statusword, frame)),
                     static_cast<std::int32_t>(slot_value(l.position_actual, frame))},
               now_us);
  }
  // The period's last TPDO in PDO order (none of its TPDOs after it; the statusword's itself when
  // it is the only one: a drive without 0x606C and no load position) completes it: the loop logs
  // its sample then, once a period.
  if ((period_tpdos_ >> number) != 0) return RemoteFrame::tpdo1;
  ++feedback_.periods_complete;
  return RemoteFrame::tpdo2;
}

bool RemoteDrive::take_mapping_entry(const StartupStep& s, std::uint32_t value) noexcept {
  if (map_sub_ == map_sub_cob_id) {
    // The PDO's COB-ID first: one that does not exist (bit 31) is neither sent nor received, so
    // nothing its mapping names is placed.
    if ((value & pdo_cob_id_invalid) != 0) return true;
    map_sub_ = 0;
    return false;  // its mapping next
  }
  const bool receive = s.index() < 0x1A00U;
  const auto number = static_cast<std::uint8_t>((s.index() & 0xFFU) + 1U);
  if (map_sub_ == 0) {
    map_count_ = static_cast<std::uint8_t>(value > pdo_max_entries ? pdo_max_entries : value);
    map_bytes_ = 0;
  } else {
    if (!place_mapped_object(config_.layout, receive, number, map_bytes_, value) && unfillable_index_ == 0) {
      unfillable_index_ = static_cast<std::uint16_t>(value >> 16U);
      unfillable_pdo_ = number;
    }
    map_bytes_ = static_cast<std::uint8_t>(map_bytes_ + (value & 0xFFU) / 8U);
  }
  if (map_sub_ < map_count_) {
    ++map_sub_;
    return false;  // the next entry
  }
  if (!receive) tpdo_len_[number - 1U] = map_bytes_;
  map_sub_ = map_sub_cob_id;
  return true;
}

bool RemoteDrive::check_derived_layout(std::uint64_t now_us) noexcept {
  const ProcessDataLayout& l = config_.layout;
  std::uint16_t missing = unfillable_pdo_ == l.controlword.pdo ? unfillable_index_ : 0;
  if (missing == 0 && check_layout(l, false) != LayoutError::none) {
    // Name the first value streaming needs that is not where it must be.
    if (!l.controlword.mapped()) {
      missing = obj::controlword;
    } else if (l.target_position.pdo != l.controlword.pdo) {
      missing = obj::target_position;
    } else if (!l.statusword.mapped()) {
      missing = obj::statusword;
    } else {
      missing = obj::position_actual;
    }
  }
  if (missing != 0) {
    failure_ = RemoteDriveFailure{};
    failure_.index = missing;
    failure_.error = StartupError::mapping_unsuitable;
    fail(now_us);
    return false;
  }
  apply_layout();
  return true;
}

void RemoteDrive::start(std::uint64_t now_us, FrameSink& out) noexcept {
  state_ = RemoteDriveState::configuring;
  failure_ = RemoteDriveFailure{};
  sdo_.cancel();
  enable_timer_.disarm();
  step_ = 0;
  step_sent_ = false;
  answered_ = false;
  verifying_ = false;
  retried_ = false;
  operational_seen_ = false;
  limits_ = RemoteDriveLimits{};
  map_sub_ = map_sub_cob_id;
  held_tpdos_ = 0;  // a period begun before start-up is not completed after it
  if (plan_too_long_ || layout_unusable_) {
    failure_.error = plan_too_long_ ? StartupError::plan_too_long : StartupError::bad_layout;
    fail(now_us);
    return;
  }
  if (config_.pdo_setup == PdoSetup::read_static) {
    config_.layout = empty_layout(config_.layout);  // derived afresh from what the drive says
    tpdo_len_ = {};
    unfillable_index_ = 0;
    unfillable_pdo_ = 0;
  }
  // SDO configuration belongs in pre-operational, where no process data flows.
  (void)out.put(encode_nmt(NmtCommand::enter_pre_operational, config_.node));
  next_step(now_us, out);
}

void RemoteDrive::next_step(std::uint64_t now_us, FrameSink& out) noexcept {
  if (step_ >= step_count_) {
    if (out.put(encode_nmt(NmtCommand::start, config_.node))) {
      begin_enabling(now_us);
    }
    return;
  }
  const StartupStep& s = steps_[step_];
  // read_mapping: the communication object's COB-ID (0x1400/0x1800 + n - 1, sub 1), then the mapping.
  const bool cob_id = map_sub_ == map_sub_cob_id;
  step_sent_ = s.action() == StartupAction::read_mapping
                   ? sdo_.upload(cob_id ? pdo_communication_of_mapping(s.index()) : s.index(), cob_id ? 1 : map_sub_,
                                 now_us, out)
               : s.action() != StartupAction::write || verifying_
                   ? sdo_.upload(s.index(), s.sub(), now_us, out)
                   : sdo_.download(s.index(), s.sub(), s.value() & s.mask(), s.size(), now_us, out);
}

void RemoteDrive::fail_step(const SdoResult& r, StartupError error, std::uint64_t now_us) noexcept {
  failure_ = RemoteDriveFailure{r.index, r.sub, r.status, r.abort, false, false, error, 0, 0};
  fail(now_us);
}

bool RemoteDrive::take_step_result(const StartupStep& s, const SdoResult& r, std::uint64_t now_us) noexcept {
  switch (s.action()) {
    case StartupAction::write:  // the read-back
    case StartupAction::check: break;
    case StartupAction::read_mapping: return true;
    case StartupAction::read:
      switch (s.field()) {
        case StartupField::position_min: limits_.position_min = static_cast<std::int32_t>(r.value); break;
        case StartupField::position_max: limits_.position_max = static_cast<std::int32_t>(r.value); break;
        case StartupField::max_profile_velocity: limits_.max_profile_velocity = r.value; break;
        case StartupField::none: break;
      }
      return true;
  }
  if ((r.value & s.mask()) != (s.value() & s.mask())) {
    StartupError error = StartupError::wrong_value;
    if (s.action() == StartupAction::check) {
      if (s.index() == obj::device_type) error = StartupError::not_cia402;
      if (s.index() == obj::identity) error = StartupError::wrong_identity;
      if (s.index() == obj::modes_of_operation_display) error = StartupError::mode_not_applied;
    }
    failure_ = RemoteDriveFailure{r.index, r.sub, r.status, SdoAbort::none, true, false, error,
                                  s.value() & s.mask(), r.value & s.mask()};
    fail(now_us);
    return false;
  }
  return true;
}

void RemoteDrive::begin_enabling(std::uint64_t now_us) noexcept {
  state_ = RemoteDriveState::enabling;
  operational_seen_ = false;  // NMT start has just been sent: what came before is stale
  enable_.reset();
  enable_timer_.arm(config_.enable_timeout_us, now_us);
}

void RemoteDrive::recover(std::uint64_t now_us) noexcept {
  if (state_ == RemoteDriveState::stopped || state_ == RemoteDriveState::released ||
      (state_ == RemoteDriveState::failed && failure_.enable_timeout)) {
    failure_ = RemoteDriveFailure{};
    begin_enabling(now_us);
  }
}

void RemoteDrive::release() noexcept {
  if (state_ == RemoteDriveState::ready) state_ = RemoteDriveState::releasing;
}

void RemoteDrive::fail(std::uint64_t /*now_us*/) noexcept {
  state_ = RemoteDriveState::failed;
  enable_timer_.disarm();
  events_ |= remote_event::failed;
}

void RemoteDrive::enabled_changed(bool enabled) noexcept {
  if (state_ == RemoteDriveState::enabling && enabled) {
    state_ = RemoteDriveState::ready;
    enable_timer_.disarm();
    events_ |= remote_event::became_ready;
  } else if (state_ == RemoteDriveState::ready && !enabled) {
    state_ = RemoteDriveState::stopped;
    events_ |= remote_event::left_enabled;
  }
}

RemoteFrame RemoteDrive::on_heartbeat(std::uint8_t state_byte, std::uint64_t now_us, FrameSink& out) noexcept {
  const auto state = nmt_state_from_byte(state_byte);
  if (!state) {
    return RemoteFrame::ignored;  // not a heartbeat (node guarding's toggle bit, say)
  }
  const bool was_lost = state_ == RemoteDriveState::lost;
  switch (heartbeat_.on_state(*state, now_us)) {
    case HeartbeatEvent::boot_up:
      events_ |= remote_event::boot_up;
      // Whatever was configured on the drive is gone; configure it again before streaming.
      if (state_ != RemoteDriveState::idle) {
        start(now_us, out);
      }
      break;
    case HeartbeatEvent::alive:
      if (was_lost) {
        events_ |= remote_event::heartbeat_back;
        start(now_us, out);
      }
      break;
    case HeartbeatEvent::none:
    case HeartbeatEvent::state_changed:
    case HeartbeatEvent::lost:
      break;
  }
  // Process data needs NMT operational. Once the drive has been operational after our start, a
  // heartbeat saying pre-operational or stopped means someone else commanded it: whatever the
  // master streams is no longer applied, and nothing about the drive can be assumed.
  if (*state == NmtState::operational) {
    if (streaming_state()) operational_seen_ = true;
  } else if ((*state == NmtState::pre_operational || *state == NmtState::stopped) && streaming_state() &&
             operational_seen_) {
    leave_operational();
  }
  return RemoteFrame::heartbeat;
}

bool RemoteDrive::streaming_state() const noexcept {
  return state_ == RemoteDriveState::enabling || state_ == RemoteDriveState::ready ||
         state_ == RemoteDriveState::stopped || state_ == RemoteDriveState::releasing ||
         state_ == RemoteDriveState::released;
}

void RemoteDrive::leave_operational() noexcept {
  state_ = RemoteDriveState::not_operational;
  enable_timer_.disarm();
  events_ |= remote_event::left_operational;
}

RemoteFrame RemoteDrive::on_nmt_command(const CanFrame& frame) noexcept {
  const std::optional<NmtMessage> m = decode_nmt(frame);
  if (!m || m->command == NmtCommand::start || (m->node != 0 && m->node != config_.node) || !streaming_state() ||
      !operational_seen_) {
    return RemoteFrame::ignored;
  }
  leave_operational();
  return RemoteFrame::nmt;
}

RemoteFrame RemoteDrive::on_other_frame(const CanFrame& frame, std::uint64_t now_us, FrameSink& out) noexcept {
  // A layout other than the default: its two TPDOs by exact identifier and length, as
  // on_process_frame takes the default layout's.
  if (frame.flags == 0 && !default_layout_) {
    if (frame.id == tpdo1_id_ && frame.len == tpdo1_len_) return take_layout_tpdo(frame, status_pdo_, now_us);
    if (frame.id == tpdo2_id_ && frame.len == tpdo2_len_) return take_layout_tpdo(frame, second_pdo_, now_us);
  }
  if (frame.id == cob::nmt) return on_nmt_command(frame);
  // Every service the master consumes is node-specific: function code + this drive's node id.
  if (!is_canopen_data_frame(frame) || (frame.id & 0x7FU) != config_.node) {
    return RemoteFrame::ignored;
  }
  switch (frame.id & 0x780U) {
    case cob::emcy:
      if (!emcy_.on_frame(frame)) {
        return RemoteFrame::ignored;
      }
      events_ |= remote_event::emcy;
      return RemoteFrame::emcy;
    case cob::heartbeat:
      // A valid one took on_process_frame's path: this one has the wrong length.
      return RemoteFrame::ignored;
    case cob::tpdo1:
    case cob::tpdo2:
    case cob::tpdo3:
    case cob::tpdo4: {
      // The layout's first two TPDOs were taken above or by on_process_frame when valid; a third or fourth
      // comes here.
      const auto n = static_cast<std::uint8_t>(((frame.id & 0x780U) - cob::tpdo1) / 0x100U + 1U);
      // (The two taken inline, and every TPDO of the default layout, are here only with another
      // length than theirs: refused by the length.)
      if (((period_tpdos_ >> (n - 1U)) & 1U) != 0 && frame.len == tpdo_len_[n - 1U]) {
        return take_layout_tpdo(frame, n, now_us);
      }
      return RemoteFrame::ignored;
    }
    case cob::sdo_tx:
      break;
    default:
      return RemoteFrame::ignored;
  }
  if (state_ != RemoteDriveState::configuring || !sdo_.on_frame(frame, now_us, out)) {
    return RemoteFrame::ignored;
  }
  const SdoResult& r = sdo_.result();
  const StartupStep& s = steps_[step_];
  const std::uint8_t was = step_;
  const bool absent = r.abort == SdoAbort::no_object || r.abort == SdoAbort::no_sub_index;
  if (r.status == SdoClientStatus::aborted && s.optional() && absent) {
    ++step_;  // an optional object the drive does not have: the default stays
    map_sub_ = map_sub_cob_id;
  } else if (r.status != SdoClientStatus::done) {
    fail_step(r, StartupError::sdo_aborted, now_us);
    return RemoteFrame::sdo;
  } else if (s.action() == StartupAction::write && !verifying_) {
    verifying_ = true;  // written: now read it back
  } else if (s.action() == StartupAction::read_mapping) {
    if (take_mapping_entry(s, r.value)) ++step_;
  } else if (take_step_result(s, r, now_us)) {
    ++step_;
    verifying_ = false;
  } else {
    return RemoteFrame::sdo;
  }
  // read_static: after the last mapping object, the layout derived must be one streaming can use.
  if (s.action() == StartupAction::read_mapping && step_ != was &&
      (step_ >= step_count_ || steps_[step_].action() != StartupAction::read_mapping) && !check_derived_layout(now_us)) {
    return RemoteFrame::sdo;
  }
  retried_ = false;
  step_sent_ = false;
  answered_ = true;  // the next request: from poll(), in a later tick
  answered_us_ = now_us;
  return RemoteFrame::sdo;
}

void RemoteDrive::poll(std::uint64_t now_us, FrameSink& out) noexcept {
  if (heartbeat_.poll(now_us) == HeartbeatEvent::lost) {
    events_ |= remote_event::heartbeat_lost;
    if (state_ != RemoteDriveState::idle) {
      state_ = RemoteDriveState::lost;
      sdo_.cancel();
      enable_timer_.disarm();
    }
  }
  switch (state_) {
    case RemoteDriveState::configuring:
      sdo_.poll(now_us, out);
      if (sdo_.status() == SdoClientStatus::timed_out) {
        if (!retried_) {
          // One lost frame on a busy bus is not a broken drive: the same request once more.
          retried_ = true;
          step_sent_ = false;
          next_step(now_us, out);
        } else {
          fail_step(sdo_.result(), StartupError::sdo_timed_out, now_us);
        }
      } else if (!step_sent_ && !sdo_.busy() && !(answered_ && now_us == answered_us_)) {
        answered_ = false;
        next_step(now_us, out);  // the step after an answer, or a request that did not fit last time
      }
      break;
    case RemoteDriveState::enabling:
      if (enable_timer_.check(now_us)) {
        failure_ = RemoteDriveFailure{};
        failure_.enable_timeout = true;
        failure_.error = StartupError::enable_timeout;
        fail(now_us);
      }
      break;
    case RemoteDriveState::releasing:
      // The statusword of the latest TPDO1: still enabled until the drive has taken the Shutdown.
      switch (drive_state()) {
        case Cia402State::operation_enabled: break;
        case Cia402State::ready_to_switch_on:
        case Cia402State::switched_on: state_ = RemoteDriveState::released; break;
        default:  // a fault or a quick stop instead of the release asked for
          state_ = RemoteDriveState::stopped;
          events_ |= remote_event::left_enabled;
          break;
      }
      break;
    case RemoteDriveState::idle:
    case RemoteDriveState::ready:
    case RemoteDriveState::stopped:
    case RemoteDriveState::lost:
    case RemoteDriveState::not_operational:
    case RemoteDriveState::failed:
    case RemoteDriveState::released:
      break;
  }
}

bool RemoteDrive::enabling_rpdo(std::int32_t target_counts, CanFrame& out) noexcept {
  if (state_ == RemoteDriveState::enabling) {
    encode_rpdo(enable_.next(feedback_.statusword), feedback_.position_actual, out);
    return true;
  }
  if (state_ == RemoteDriveState::releasing) {
    encode_rpdo(controlword::shutdown, target_counts, out);
    return true;
  }
  return false;  // idle, configuring, stopped, lost, not_operational, failed, released: no process data
}

}  // namespace settle::hal::canopen
