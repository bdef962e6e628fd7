// SPDX-License-Identifier: Apache-2.0
#include "settle/testbed/drive_from_eds.hpp"

#include <cstdio>
#include <limits>
#include <memory>
#include <string_view>
#include <vector>

namespace settle::testbed {

namespace {

namespace co = hal::canopen;
namespace eds = hal::eds;

std::string object_name(std::uint16_t index, std::uint8_t sub) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%04X:%u", static_cast<unsigned>(index), static_cast<unsigned>(sub));
  return text;
}

eds::Access eds_access(co::OdAccess a) {
  switch (a) {
    case co::OdAccess::ro: return eds::Access::ro;
    case co::OdAccess::wo: return eds::Access::wo;
    case co::OdAccess::rw: return eds::Access::rw;
    case co::OdAccess::constant: return eds::Access::constant;
  }
  return eds::Access::ro;
}

// Reads one integer default into a configuration field of type T; false (with the error) when
// the object has none or it does not fit.
class Defaults {
 public:
  Defaults(const eds::Description& d, co::NodeId node, std::string& error) : d_{d}, node_{node}, error_{error} {}

  template <typename T>
  bool take(std::uint16_t index, std::uint8_t sub, T& field) {
    const eds::Entry* e = d_.find(index, sub);
    if (e == nullptr) {
      return true;  // checked with the object set
    }
    const std::optional<std::int64_t> v = e->value(node_);
    if (!v) {
      return true;  // no default: the drive's own
    }
    if (*v < std::numeric_limits<T>::min() || *v > std::numeric_limits<T>::max()) {
      error_ = object_name(index, sub) + " " + e->name + ": default " + std::to_string(*v) + " out of range";
      return false;
    }
    field = static_cast<T>(*v);
    return true;
  }

 private:
  const eds::Description& d_;
  co::NodeId node_;
  std::string& error_;
};

// The PDOs of one direction into the configuration: numbered 1..n without gaps, at most the
// drive's capacity, at most its entries each.
template <std::size_t N>
bool take_pdos(const eds::Description& d, bool receive, co::NodeId node, std::array<co::PdoMapping, N>& out,
               std::array<std::uint8_t, N>& rows, std::uint8_t& count, std::optional<bool>& writable,
               std::string& error) {
  const std::vector<eds::Pdo> pdos = receive ? d.rpdos(node) : d.tpdos(node);
  const char* kind = receive ? "RPDO" : "TPDO";
  out = {};
  for (co::PdoMapping& m : out) {
    m.cob_id = co::pdo_cob_invalid;
  }
  count = 0;
  for (const eds::Pdo& p : pdos) {
    const std::string name = std::string{kind} + std::to_string(p.number);
    if (p.number != count + 1U) {
      error = name + ": PDOs must be numbered from 1 without gaps";
      return false;
    }
    if (p.number > N) {
      error = name + ": the simulated drive has at most " + std::to_string(N) + " " + kind + "s";
      return false;
    }
    if (p.mapping.size() > co::drive_pdo_entry_capacity) {
      error = name + ": " + std::to_string(p.mapping.size()) + " mapped objects, at most " +
              std::to_string(co::drive_pdo_entry_capacity);
      return false;
    }
    if (writable && *writable != p.mapping_writable) {
      error = name + ": mapping writable in some PDOs and not in others (the simulated drive has one setting)";
      return false;
    }
    writable = p.mapping_writable;
    co::PdoMapping& m = out[p.number - 1U];
    // The predefined id of this node is stored as 0 (DriveNodeConfig's convention).
    const std::uint32_t predefined = co::drive_pdo_cob_id(0, receive, p.number, node);
    m.cob_id = (p.cob_id & co::pdo_cob_id_mask) == predefined ? (p.cob_id & ~co::pdo_cob_id_mask) : p.cob_id;
    m.transmission_type = p.transmission_type;
    m.count = static_cast<std::uint8_t>(p.mapping.size());
    for (std::size_t i = 0; i < p.mapping.size(); ++i) {
      m.entries[i] = co::PdoMappingEntry{p.mapping[i].index, p.mapping[i].sub, p.mapping[i].bits};
    }
    // A mapping may list entries past its count (a static TPDO2 that maps nothing, its sub 1
    // still described): unused, served as described (a static one only those it lists).
    if (d.find(p.mapping_index(), static_cast<std::uint8_t>(co::drive_pdo_entry_capacity + 1U)) != nullptr) {
      error = name + ": mapping entries past sub-index " + std::to_string(co::drive_pdo_entry_capacity) +
              " (the simulated drive has " + std::to_string(co::drive_pdo_entry_capacity) + ")";
      return false;
    }
    for (std::size_t i = p.mapping.size(); i < co::drive_pdo_entry_capacity; ++i) {
      const eds::Entry* e = d.find(p.mapping_index(), static_cast<std::uint8_t>(i + 1));
      if (e == nullptr) break;
      const auto raw = static_cast<std::uint32_t>(e->value(node).value_or(0));
      m.entries[i] = co::PdoMappingEntry{static_cast<std::uint16_t>(raw >> 16U), static_cast<std::uint8_t>(raw >> 8U),
                                         static_cast<std::uint8_t>(raw)};
      rows[p.number - 1U] = static_cast<std::uint8_t>(i + 1);
    }
    ++count;
  }
  return true;
}

// Which PDO and which of its entries the drive cannot bind: ": TPDO2 maps 0x2100:0, ...", or "".
std::string unbindable_entry(co::DriveNode& drive, const co::DriveNodeConfig& c) {
  for (const bool receive : {true, false}) {
    const std::size_t count = receive ? c.rpdo_count : c.tpdo_count;
    for (std::size_t i = 0; i < count; ++i) {
      const co::PdoMapping& m = receive ? c.rpdos[i] : c.tpdos[i];
      for (std::size_t k = 0; k < m.count; ++k) {
        const co::PdoMappingEntry& e = m.entries[k];
        const std::string pdo = std::string{receive ? ": RPDO" : ": TPDO"} + std::to_string(i + 1) + " maps " +
                                object_name(e.index, e.sub);
        const co::OdEntry* o = drive.dictionary().find(e.index, e.sub);
        if (o == nullptr) return pdo + ", which the simulated drive does not have";
        if (!o->pdo_mappable) return pdo + ", which is not mappable";
        const bool can = receive ? (o->access == co::OdAccess::rw || o->access == co::OdAccess::wo)
                                 : o->access != co::OdAccess::wo;
        if (!can) return pdo + (receive ? ", which is read-only (an RPDO writes it)" : ", which is write-only");
      }
    }
  }
  return {};
}

// Where the simulated drive serves its load position: Settle's own drive at 0x2000; another
// vendor's only at the object the user names (a readable, mappable INTEGER32 manufacturer object
// the EDS describes), else none. Empty, or why the named object cannot be it.
std::string place_load_position(const eds::Description& d, bool own, std::optional<eds::MappedObject> load_at,
                                co::DriveNodeConfig& c) {
  c.has_load_position = own && d.has(co::obj::load_position_actual);
  if (own || !load_at) return {};
  const eds::Entry* e = d.find(load_at->index, load_at->sub);
  const bool placeable = load_at->index == co::obj::load_position_actual ||
                         (load_at->index > co::obj::communication_loss_periods &&
                          load_at->index <= co::obj::manufacturer_index_last);
  if (e == nullptr || !placeable || e->data_type != eds::data_type::i32 || !e->pdo_mappable ||
      e->access == eds::Access::wo) {
    return object_name(load_at->index, load_at->sub) +
           ": the simulated drive serves its load position only in a manufacturer object (0x2000 or "
           "0x2002..0x5FFF) the EDS describes as a readable, mappable INTEGER32";
  }
  c.has_load_position = true;
  c.load_position_index = load_at->index;
  c.load_position_sub = load_at->sub;
  return {};
}

// The drive the configuration built against the EDS, object for object both ways (a vendor's
// manufacturer objects aside: `vendors`). Empty, or the first difference.
template <typename Vendors>
std::string differs_from_eds(const eds::Description& d, co::DriveNode& drive, co::NodeId node,
                             const Vendors& vendors) {
  for (const eds::Entry& x : d.entries()) {
    if (vendors(x.index)) continue;
    const co::OdEntry* e = drive.dictionary().find(x.index, x.sub);
    const std::string name = object_name(x.index, x.sub) + " " + x.name;
    if (e == nullptr) return name + ": an object the simulated drive does not implement";
    if (x.data_type != static_cast<std::uint16_t>(e->var.type())) {
      return name + ": data type differs from the simulated drive's";
    }
    if (x.access != eds_access(e->access)) {
      return name + ": AccessType " + eds::to_string(x.access) + ", the simulated drive's is " +
             eds::to_string(eds_access(e->access));
    }
    if (x.pdo_mappable != e->pdo_mappable) return name + ": PDOMapping differs from the simulated drive's";
    if (const hal::canopen::OdBytes* bytes = e->var.bytes(); bytes != nullptr) {
      const auto text = bytes->view();
      if (x.default_value != std::string(text.begin(), text.end())) {
        return name + ": default \"" + x.default_value + "\", the simulated drive serves \"" +
               std::string(text.begin(), text.end()) + "\"";
      }
    } else if (!(x.index == co::obj::identity && x.sub >= 1 && x.sub <= 3)) {  // the identity: the caller's
      if (const auto v = x.value(node); v && *v != e->var.value()) {
        return name + ": default " + std::to_string(*v) + ", the simulated drive starts with " +
               std::to_string(e->var.value());
      }
    }
  }
  for (const co::OdEntry& e : drive.dictionary().entries()) {
    if (d.find(e.index, e.sub) == nullptr && !vendors(e.index)) {
      return object_name(e.index, e.sub) + ": the simulated drive always has it, the EDS does not";
    }
  }
  return {};
}

}  // namespace

DriveFromEds simulated_drive_from_eds(const eds::Description& d, co::NodeId node,
                                      std::optional<eds::MappedObject> load_at) {
  DriveFromEds r;
  co::DriveNodeConfig c{};
  c.node = node;
  c.has_interpolation_period = d.has(co::obj::interpolation_time_period);
  c.has_following_error_actual = d.has(co::obj::following_error_actual);
  c.has_velocity_actual = d.has(co::obj::velocity_actual);
  // Settle's own dictionary ([SettleDrive]) is simulated object for object; another vendor's
  // manufacturer objects (0x2000..0x5FFF) are theirs: described, not simulated (the master never
  // uses them), and the simulated drive's own 0x2000/0x2001 stay out of the comparison.
  const bool own = d.settle_drive();
  const auto vendors = [own](std::uint16_t index) { return !own && index >= 0x2000 && index <= 0x5FFF; };
  r.error = place_load_position(d, own, load_at, c);
  if (!r.error.empty()) return r;
  c.has_communication_cycle_period = d.has(co::obj::communication_cycle_period);
  // CiA 301 asks 0x1006 only of the SYNC producer: a drive without it measures SYNCs against 0x60C2.
  if (!c.has_communication_cycle_period) c.sync_period_us = 0;

  Defaults take{d, node, r.error};
  // The identity the master expects too: the reader settles 0x1018 against [DeviceInfo] once.
  if (d.find(co::obj::identity, 1) != nullptr) c.vendor_id = d.device().vendor_number;
  if (d.find(co::obj::identity, 2) != nullptr) c.product_code = d.device().product_number;
  if (d.find(co::obj::identity, 3) != nullptr) c.revision = d.device().revision_number;
  if (!(take.take(co::obj::device_type, 0, c.device_type) && take.take(co::obj::identity, 4, c.serial) && take.take(co::obj::producer_heartbeat_time, 0, c.heartbeat_period_ms) &&
        take.take(co::obj::communication_cycle_period, 0, c.sync_period_us) &&
        take.take(co::obj::sync_counter_overflow, 0, c.sync_counter_overflow) &&
        take.take(co::obj::communication_loss_periods, 0, c.communication_loss_periods) &&
        take.take(co::obj::quick_stop_option, 0, c.quick_stop_option) &&
        take.take(co::obj::abort_connection_option, 0, c.abort_connection_option) &&
        take.take(co::obj::following_error_window, 0, c.following_error_window) &&
        take.take(co::obj::following_error_timeout, 0, c.following_error_timeout_ms) &&
        take.take(co::obj::max_profile_velocity, 0, c.max_profile_velocity) &&
        take.take(co::obj::software_position_limit, 1, c.position_limit_min) &&
        take.take(co::obj::software_position_limit, 2, c.position_limit_max))) {
    return r;
  }

  std::optional<bool> writable;
  if (!take_pdos(d, true, node, c.rpdos, c.rpdo_mapping_rows, c.rpdo_count, writable, r.error) ||
      !take_pdos(d, false, node, c.tpdos, c.tpdo_mapping_rows, c.tpdo_count, writable, r.error)) {
    return r;
  }
  // TPDO1 alone is a drive: one whose whole feedback (statusword and position actual) it carries.
  if (c.rpdo_count == 0 || c.tpdo_count == 0) {
    r.error = "the simulated drive needs RPDO1 and TPDO1 (the EDS describes " + std::to_string(c.rpdo_count) +
              " RPDOs and " + std::to_string(c.tpdo_count) + " TPDOs)";
    return r;
  }
  c.pdo_mapping_writable = writable.value_or(false);
  // The strings, served as the EDS gives them (an absent one is reported below: the drive has it).
  auto texts = std::make_unique<DriveTexts>();
  const auto text_of = [&d](std::uint16_t index) {
    const eds::Entry* e = d.find(index, 0);
    return e != nullptr ? e->default_value : std::string{};
  };
  texts->device_name = text_of(co::obj::device_name);
  texts->hardware_version = text_of(co::obj::hardware_version);
  texts->software_version = text_of(co::obj::software_version);
  c.device_name = texts->device_name.c_str();
  c.hardware_version = texts->hardware_version.c_str();
  c.software_version = texts->software_version.c_str();

  // The drive this configuration builds must be the one the EDS describes, object for object.
  const auto drive = std::make_unique<co::DriveNode>(c);
  if (const co::SdoAbort abort = drive->default_mapping_error(); abort != co::SdoAbort::none) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%08X", static_cast<unsigned>(abort));
    r.error = std::string{"a default PDO mapping cannot be bound (SDO abort "} + code + ")" +
              unbindable_entry(*drive, c);
    return r;
  }
  r.error = differs_from_eds(d, *drive, node, vendors);
  if (!r.error.empty()) return r;
  r.config = c;
  r.texts = std::move(texts);
  return r;
}

DriveFromEds load_drive_config(const std::string& path, co::NodeId node) {
  const eds::LoadResult loaded = eds::load(path);
  if (!loaded.description) {
    return DriveFromEds{std::nullopt, nullptr, loaded.error};  // the reader names the file and line
  }
  DriveFromEds r = simulated_drive_from_eds(*loaded.description, node);
  if (!r.config) {
    r.error = path + ": " + r.error;
  }
  return r;
}

}  // namespace settle::testbed
