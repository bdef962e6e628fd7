// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/eds_drive_config.hpp"

#include <array>
#include <cstdio>
#include <vector>

#include "settle/hal/canopen/process_data.hpp"

namespace settle::hal::eds {
namespace {

using canopen::PdoSlot;
using canopen::ProcessDataLayout;

enum class Need : std::uint8_t { read, write, rpdo, tpdo };

struct Required {
  std::uint16_t index;
  std::uint8_t sub;
  const char* name;
  std::uint16_t type;
  Need need;
};

std::string hex4(std::uint16_t index) {
  std::array<char, 8> text{};
  std::snprintf(text.data(), text.size(), "0x%04X", static_cast<unsigned>(index));
  return text.data();
}

std::string object(const Required& r) {
  std::string s = hex4(r.index);
  if (r.sub != 0) s += ":" + std::to_string(r.sub);
  return s + " (" + r.name + ")";
}

const char* type_name(std::uint16_t type) {
  switch (type) {
    case data_type::i8: return "INTEGER8";
    case data_type::i16: return "INTEGER16";
    case data_type::i32: return "INTEGER32";
    case data_type::u8: return "UNSIGNED8";
    case data_type::u16: return "UNSIGNED16";
    case data_type::u32: return "UNSIGNED32";
    default: return "another type";
  }
}

// "" or why the object cannot serve.
std::string check(const Description& d, const Required& r) {
  const Entry* e = d.find(r.index, r.sub);
  if (e == nullptr) return "the drive's EDS has no " + object(r);
  if (e->data_type != r.type) {
    std::array<char, 8> t{};
    std::snprintf(t.data(), t.size(), "0x%04X", static_cast<unsigned>(e->data_type));
    return "the drive's EDS gives " + object(r) + " the data type " + t.data() + ", not " + type_name(r.type);
  }
  const bool writes = r.need == Need::write || r.need == Need::rpdo;
  if (writes && !e->writable()) {
    return "the drive's EDS makes " + object(r) + " " + to_string(e->access) + ": the master must write it";
  }
  if (!writes && !e->readable()) return "the drive's EDS makes " + object(r) + " write-only: the master must read it";
  if ((r.need == Need::rpdo || r.need == Need::tpdo) && !e->pdo_mappable) {
    return "the drive's EDS does not let " + object(r) + " be mapped to a PDO";
  }
  return {};
}

// The layout a drive's default (or DCF-configured) mapping gives, as start-up will derive it.
ProcessDataLayout layout_of(const std::vector<Pdo>& rpdos, const std::vector<Pdo>& tpdos,
                            const ProcessDataLayout& objects, std::uint16_t& unfillable,
                            unsigned& unfillable_pdo) {
  ProcessDataLayout l = canopen::empty_layout(objects);
  unfillable = 0;
  unfillable_pdo = 0;
  for (const auto* list : {&rpdos, &tpdos}) {
    for (const Pdo& p : *list) {
      if (p.number < 1 || p.number > canopen::layout_pdo_count) continue;
      unsigned at = 0;
      for (const MappedObject& m : p.mapping) {
        const std::uint32_t raw = (std::uint32_t{m.index} << 16U) | (std::uint32_t{m.sub} << 8U) | m.bits;
        if (!canopen::place_mapped_object(l, p.receive, static_cast<std::uint8_t>(p.number),
                                          static_cast<std::uint8_t>(at), raw) &&
            unfillable == 0) {
          unfillable = m.index;
          unfillable_pdo = p.number;
        }
        at += m.bits / 8U;
      }
    }
  }
  return l;
}

}  // namespace

DriveConfigResult drive_config_from_eds(const Description& description, const canopen::RemoteDriveConfig& base,
                                        const FeedbackRequest& feedback) {
  namespace obj = canopen::obj;
  DriveConfigResult result{};
  result.config = base;
  std::vector<Required> required{
      {obj::controlword, 0, "controlword", data_type::u16, Need::rpdo},
      {obj::statusword, 0, "statusword", data_type::u16, Need::tpdo},
      {obj::modes_of_operation, 0, "modes of operation", data_type::i8, Need::write},
      {obj::modes_of_operation_display, 0, "modes of operation display", data_type::i8, Need::read},
      {obj::target_position, 0, "target position", data_type::i32, Need::rpdo},
      {obj::position_actual, 0, "position actual value", data_type::i32, Need::tpdo},
      {obj::interpolation_time_period, 1, "interpolation time period value", data_type::u8, Need::write},
      {obj::interpolation_time_period, 2, "interpolation time index", data_type::i8, Need::write},
  };
  // 0x60C2 as a whole first, so that a drive without it is told so in those words.
  if (!description.has(obj::interpolation_time_period)) {
    result.error = "the drive's EDS has no 0x60C2 (interpolation time period)";
    return result;
  }
  if (feedback.velocity_actual) required.push_back({obj::velocity_actual, 0, "velocity actual value", data_type::i32, Need::tpdo});
  if (feedback.following_error) {
    required.push_back({obj::following_error_actual, 0, "following error actual value", data_type::i32, Need::tpdo});
  }
  if (feedback.load_position_index != 0) {
    required.push_back({feedback.load_position_index, feedback.load_position_sub, "load-side position", data_type::i32,
                        Need::tpdo});
  }
  for (const Required& r : required) {
    if (std::string why = check(description, r); !why.empty()) {
      result.error = std::move(why);
      return result;
    }
  }

  // CiA 301 asks 0x1006 only of the SYNC producer: written only to a drive that has it.
  result.config.write_sync_period = description.has(obj::communication_cycle_period);

  const DeviceInfo& device = description.device();
  if (device.vendor_number != 0) result.config.expected_vendor_id = device.vendor_number;
  if (device.product_number != 0) result.config.expected_product_code = device.product_number;

  ProcessDataLayout objects{};
  if (feedback.load_position_index != 0) {
    objects.load_position_index = feedback.load_position_index;
    objects.load_position_sub = feedback.load_position_sub;
  }
  const std::vector<Pdo> rpdos = description.rpdos(base.node);
  const std::vector<Pdo> tpdos = description.tpdos(base.node);

  // The layout the master would write: RPDO1 and TPDO1 as Settle's, the feedback asked for after.
  ProcessDataLayout wanted = canopen::empty_layout(objects);
  wanted.controlword = PdoSlot{1, 0, 2};
  wanted.target_position = PdoSlot{1, 2, 4};
  wanted.statusword = PdoSlot{1, 0, 2};
  wanted.position_actual = PdoSlot{1, 2, 4};
  std::uint8_t pdo = 2;
  std::uint8_t at = 0;
  const auto place = [&](PdoSlot& slot) {
    if (at + 4 > 8) {
      ++pdo;
      at = 0;
    }
    slot = PdoSlot{pdo, at, 4};
    at = static_cast<std::uint8_t>(at + 4);
  };
  if (feedback.load_position_index != 0) place(wanted.load_position);
  if (feedback.velocity_actual) place(wanted.velocity_actual);
  if (feedback.following_error) place(wanted.following_error);
  const std::uint8_t tpdos_needed = at == 0 ? static_cast<std::uint8_t>(pdo - 1) : pdo;

  // Dynamic when every PDO the layout uses is described with a writable mapping.
  const auto writable = [](const std::vector<Pdo>& list, std::uint8_t number) {
    for (const Pdo& p : list) {
      if (p.number == number) return p.mapping_writable;
    }
    return false;
  };
  bool dynamic = writable(rpdos, 1);
  for (std::uint8_t n = 1; n <= tpdos_needed; ++n) dynamic = dynamic && writable(tpdos, n);
  result.mapping_writable = dynamic;
  if (dynamic) {
    result.config.pdo_setup = canopen::PdoSetup::dynamic;
    result.config.layout = wanted;
    return result;
  }

  // Static: the description's own mapping must carry what is needed; start-up reads it from the
  // drive and checks it again.
  std::uint16_t unfillable = 0;
  unsigned unfillable_pdo = 0;
  const ProcessDataLayout l = layout_of(rpdos, tpdos, objects, unfillable, unfillable_pdo);
  const auto missing = [&](const char* what) {
    result.error = std::string{"the drive's PDO mapping is static (not writable) and "} + what;
  };
  if (!l.controlword.mapped() || !l.target_position.mapped() || l.controlword.pdo != l.target_position.pdo) {
    missing("no RPDO carries both 0x6040 (controlword) and 0x607A (target position)");
  } else if (unfillable != 0 && unfillable_pdo == l.controlword.pdo) {
    missing(("its RPDO" + std::to_string(unfillable_pdo) + " also maps " + hex4(unfillable) +
             ", which the master cannot fill").c_str());
  } else if (!l.statusword.mapped() || !l.position_actual.mapped() || l.statusword.pdo != l.position_actual.pdo) {
    missing("no TPDO carries both 0x6041 (statusword) and 0x6064 (position actual value)");
  } else if (feedback.velocity_actual && !l.velocity_actual.mapped()) {
    missing("no TPDO carries 0x606C (velocity actual value)");
  } else if (feedback.following_error && !l.following_error.mapped()) {
    missing("no TPDO carries 0x60F4 (following error actual value)");
  } else if (feedback.load_position_index != 0 && !l.load_position.mapped()) {
    missing(("no TPDO carries " + hex4(feedback.load_position_index) + " (load-side position)").c_str());
  } else if (const canopen::LayoutError e = canopen::check_layout(l, false); e != canopen::LayoutError::none) {
    missing((std::string{"its layout is not one the master can stream through ("} + canopen::to_string(e) + ")").c_str());
  }
  if (!result.error.empty()) return result;
  result.config.pdo_setup = canopen::PdoSetup::read_static;
  result.config.layout = l;
  return result;
}

}  // namespace settle::hal::eds
