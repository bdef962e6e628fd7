// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/eds_drive_config.hpp"

#include <array>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "settle/hal/canopen/process_data.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/canopen/standard_objects.hpp"

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

// "" or why the object cannot serve.
std::string check(const Description& d, const Required& r) {
  const Entry* e = d.find(r.index, r.sub);
  if (e == nullptr) return "the drive's EDS has no " + object(r);
  if (e->data_type != r.type) {
    std::array<char, 8> t{};
    std::snprintf(t.data(), t.size(), "0x%04X", static_cast<unsigned>(e->data_type));
    return "the drive's EDS gives " + object(r) + " the data type " + t.data() + ", not " +
           canopen::data_type_name(r.type, "another type");
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

// The layout a drive's default (or DCF-configured) mapping gives, as start-up will derive it: a
// PDO whose COB-ID says it does not exist (bit 31) is neither sent nor received, and places nothing.
ProcessDataLayout layout_of(const std::vector<Pdo>& rpdos, const std::vector<Pdo>& tpdos,
                            const ProcessDataLayout& objects, std::uint16_t& unfillable,
                            unsigned& unfillable_pdo) {
  ProcessDataLayout l = canopen::empty_layout(objects);
  unfillable = 0;
  unfillable_pdo = 0;
  for (const auto* list : {&rpdos, &tpdos}) {
    for (const Pdo& p : *list) {
      if (p.number < 1 || p.number > canopen::layout_pdo_count || (p.cob_id & canopen::pdo_cob_id_invalid) != 0) {
        continue;
      }
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

bool is_settle_drive(const Description& description) noexcept {
  return description.settle_drive();
}

namespace {

namespace obj = canopen::obj;

// "" or why the description lacks what streaming needs: a way to tell the drive the SYNC period
// (0x60C2 or 0x1006), and every object the master reads, writes or maps (the feedback asked for
// included) with its data type, access and mappability.
std::string required_objects_problem(const Description& description, const FeedbackRequest& feedback) {
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
  // The period reaches the drive through 0x60C2 or 0x1006 (each written when the drive has it).
  const bool has_ip = description.has(obj::interpolation_time_period);
  if (!has_ip && !description.has(obj::communication_cycle_period)) {
    return "the drive's EDS has neither 0x60C2 (interpolation time period) nor 0x1006 (communication cycle "
           "period): the drive cannot be told the SYNC period";
  }
  if (!has_ip) required.resize(required.size() - 2);  // the two 0x60C2 rows, last in the list
  if (feedback.velocity_actual) required.push_back({obj::velocity_actual, 0, "velocity actual value", data_type::i32, Need::tpdo});
  if (feedback.following_error) {
    required.push_back({obj::following_error_actual, 0, "following error actual value", data_type::i32, Need::tpdo});
  }
  if (feedback.load_position_index != 0) {
    required.push_back({feedback.load_position_index, feedback.load_position_sub, "load-side position", data_type::i32,
                        Need::tpdo});
  }
  for (const Required& r : required) {
    if (std::string why = check(description, r); !why.empty()) return why;
  }
  return {};
}

// CiA 301 asks 0x1006 only of the SYNC producer: written only to a drive that has it; so are
// the other objects the master uses when present. The identity expected is the description's.
void use_what_is_present(const Description& description, canopen::RemoteDriveConfig& config) {
  config.write_sync_period = description.has(obj::communication_cycle_period);
  config.write_interpolation_period = description.has(obj::interpolation_time_period);
  if (description.find(obj::producer_heartbeat_time, 0) == nullptr) config.heartbeat_period_ms = 0;
  if (description.find(obj::consumer_heartbeat_time, 1) == nullptr) config.master_node = 0;
  if (description.find(obj::following_error_window, 0) == nullptr ||
      description.find(obj::following_error_timeout, 0) == nullptr) {
    config.following_error_window = 0;
  }
  if (!is_settle_drive(description) || description.find(obj::communication_loss_periods, 0) == nullptr) {
    config.communication_loss_periods = 0;
  }
  const DeviceInfo& device = description.device();
  if (device.vendor_number != 0) config.expected_vendor_id = device.vendor_number;
  if (device.product_number != 0) config.expected_product_code = device.product_number;
}

// The layout the master would write: RPDO1 and TPDO1 as Settle's, the feedback asked for after;
// `tpdos_needed` how many TPDOs it uses.
ProcessDataLayout wanted_layout(const ProcessDataLayout& objects, const FeedbackRequest& feedback,
                                std::uint8_t& tpdos_needed) {
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
  tpdos_needed = at == 0 ? static_cast<std::uint8_t>(pdo - 1) : pdo;
  return wanted;
}

// "" or why the TPDOs a split feedback comes in (the statusword and the position actual in
// different TPDOs: feedback_tpdos) cannot give one period's values together: each must be sent on
// the same SYNCs as the others (one synchronous cyclic transmission type, 1..240).
std::string split_feedback_problem(const ProcessDataLayout& l, const std::vector<Pdo>& tpdos) {
  const std::uint8_t used = canopen::feedback_tpdos(l);
  const Pdo* first = nullptr;
  for (const Pdo& p : tpdos) {
    if (p.number < 1 || p.number > canopen::layout_pdo_count || (used & (1U << (p.number - 1U))) == 0) continue;
    const std::string name = "TPDO" + std::to_string(p.number);
    const std::string type = " (transmission type " + std::to_string(p.transmission_type) + ")";
    if (p.transmission_type < 1 || p.transmission_type > 240) {
      return name + type + " is not sent on SYNCs (synchronous cyclic: 1..240)";
    }
    if (first != nullptr && first->transmission_type != p.transmission_type) {
      return name + type + " and TPDO" + std::to_string(first->number) + " (transmission type " +
             std::to_string(first->transmission_type) + ") are not sent on the same SYNCs";
    }
    if (first == nullptr) first = &p;
  }
  return {};
}

// "" or why the description's own (static) mapping `l` cannot carry what is needed; `unfillable`
// the first object in PDO `unfillable_pdo` the master cannot fill (0: none).
std::string static_layout_problem(const ProcessDataLayout& l, std::uint16_t unfillable, unsigned unfillable_pdo,
                                  const FeedbackRequest& feedback, const std::vector<Pdo>& tpdos) {
  std::string what;
  if (!l.controlword.mapped() || !l.target_position.mapped() || l.controlword.pdo != l.target_position.pdo) {
    what = "no RPDO carries both 0x6040 (controlword) and 0x607A (target position)";
  } else if (unfillable != 0 && unfillable_pdo == l.controlword.pdo) {
    what = "its RPDO" + std::to_string(unfillable_pdo) + " also maps " + hex4(unfillable) +
           ", which the master cannot fill";
  } else if (!l.statusword.mapped()) {
    what = "no TPDO carries 0x6041 (statusword)";
  } else if (!l.position_actual.mapped()) {
    what = "no TPDO carries 0x6064 (position actual value)";
  } else if (feedback.velocity_actual && !l.velocity_actual.mapped()) {
    what = "no TPDO carries 0x606C (velocity actual value)";
  } else if (feedback.following_error && !l.following_error.mapped()) {
    what = "no TPDO carries 0x60F4 (following error actual value)";
  } else if (feedback.load_position_index != 0 && !l.load_position.mapped()) {
    what = "no TPDO carries " + hex4(feedback.load_position_index) + " (load-side position)";
  } else if (const canopen::LayoutError e = canopen::check_layout(l, false); e != canopen::LayoutError::none) {
    what = std::string{"its layout is not one the master can stream through ("} + canopen::to_string(e) + ")";
  } else if (canopen::feedback_split(l)) {
    if (std::string why = split_feedback_problem(l, tpdos); !why.empty()) {
      what = "the statusword (TPDO" + std::to_string(l.statusword.pdo) + ") and the position actual (TPDO" +
             std::to_string(l.position_actual.pdo) + ") come in different TPDOs, but " + why;
    }
  }
  return what.empty() ? std::string{} : "the drive's PDO mapping is static (not writable) and " + what;
}

// "" or why a PDO the static layout uses would go unheard: the master sends and listens on the
// predefined connection set's COB-IDs (CiA 301: 0x200/0x180 + 0x100 (n - 1) + node) and does not
// re-assign a static drive's, so a drive described with another one is refused, not streamed to
// into silence. Bits 0..29 are compared (29: a 29-bit identifier); bit 30 (no RTR) is free.
std::string cob_id_problem(const ProcessDataLayout& l, const std::vector<Pdo>& rpdos, const std::vector<Pdo>& tpdos,
                           std::uint8_t node) {
  const auto heard = [&](const PdoSlot& slot, bool receive) -> std::string {
    if (!slot.mapped()) return {};
    for (const Pdo& p : receive ? rpdos : tpdos) {
      if (p.number != slot.pdo) continue;
      const std::uint32_t predefined = canopen::pdo_cob_id(receive, slot.pdo, node);
      if ((p.cob_id & 0x3FFFFFFFU) == predefined) return {};
      std::array<char, 160> text{};
      std::snprintf(text.data(), text.size(), "%s%u's COB-ID (0x%04X:1) is 0x%X, not the predefined 0x%03X",
                    receive ? "RPDO" : "TPDO", static_cast<unsigned>(slot.pdo),
                    static_cast<unsigned>(canopen::pdo_communication_index(receive, slot.pdo)),
                    static_cast<unsigned>(p.cob_id & 0x3FFFFFFFU), static_cast<unsigned>(predefined));
      return std::string{text.data()} + (receive ? " the master sends on" : " the master listens on") +
             " (CiA 301's predefined connection set for node " + std::to_string(node) + ")";
    }
    return {};
  };
  for (const auto& [slot, receive] : {std::pair{l.controlword, true}, std::pair{l.statusword, false},
                                      std::pair{l.position_actual, false}, std::pair{l.load_position, false},
                                      std::pair{l.velocity_actual, false}, std::pair{l.following_error, false}}) {
    if (std::string why = heard(slot, receive); !why.empty()) {
      return "the drive's PDO mapping is static (not writable) and its " + why;
    }
  }
  return {};
}

}  // namespace

DriveConfigResult drive_config_from_eds(const Description& description, const canopen::RemoteDriveConfig& base,
                                        const FeedbackRequest& feedback) {
  DriveConfigResult result{};
  result.config = base;
  result.error = required_objects_problem(description, feedback);
  if (!result.error.empty()) return result;
  use_what_is_present(description, result.config);

  ProcessDataLayout objects{};
  if (feedback.load_position_index != 0) {
    objects.load_position_index = feedback.load_position_index;
    objects.load_position_sub = feedback.load_position_sub;
  }
  const std::vector<Pdo> rpdos = description.rpdos(base.node);
  const std::vector<Pdo> tpdos = description.tpdos(base.node);
  std::uint8_t tpdos_needed = 0;
  const ProcessDataLayout wanted = wanted_layout(objects, feedback, tpdos_needed);

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
  result.error = static_layout_problem(l, unfillable, unfillable_pdo, feedback, tpdos);
  if (result.error.empty()) result.error = cob_id_problem(l, rpdos, tpdos, base.node);
  if (!result.error.empty()) return result;
  result.config.pdo_setup = canopen::PdoSetup::read_static;
  result.config.layout = l;
  return result;
}

}  // namespace settle::hal::eds

namespace settle::hal::eds {
namespace {

struct Known {
  std::uint16_t index;
  std::uint8_t sub;
  const char* name;
  bool needed;
  const char* without;
};
constexpr Known kKnown[] = {
    {0x1006, 0, "communication cycle period", false, "the drive takes the period from 0x60C2 (CiA 301 asks 0x1006 only of the SYNC producer)"},
    {0x1016, 1, "consumer heartbeat time", false, "the drive does not watch the master's heartbeat"},
    {0x1017, 0, "producer heartbeat time", false, "the master does not set the drive's heartbeat period"},
    {0x1018, 1, "vendor id", false, "the vendor is not checked"},
    {0x1018, 2, "product code", false, "the product is not checked"},
    {0x1019, 0, "synchronous counter overflow", false, "the master sends SYNCs without a counter"},
    {0x2001, 0, "communication loss periods (Settle's drive)", false, "the drive keeps its own SYNC-loss reaction"},
    {0x6040, 0, "controlword", true, ""},
    {0x6041, 0, "statusword", true, ""},
    {0x6060, 0, "modes of operation", true, ""},
    {0x6061, 0, "modes of operation display", true, ""},
    {0x6064, 0, "position actual value", true, ""},
    {0x6065, 0, "following error window", false, "the drive keeps its own following error supervision"},
    {0x6066, 0, "following error time out", false, "the drive keeps its own following error supervision"},
    {0x606C, 0, "velocity actual value", false, "the drive's velocity is not reported"},
    {0x607A, 0, "target position", true, ""},
    {0x607D, 1, "min position limit", false, "the loop knows no software position limit"},
    {0x607D, 2, "max position limit", false, "the loop knows no software position limit"},
    {0x607F, 0, "max profile velocity", false, "the loop's step guard uses its own velocity bound alone"},
    {0x60C2, 1, "interpolation time period value", false, "the drive takes the period from 0x1006"},
    {0x60C2, 2, "interpolation time index", false, "the drive takes the period from 0x1006"},
    {0x60F4, 0, "following error actual value", false, "the following error is not reported"},
};

std::string slot_use(const canopen::ProcessDataLayout& l, std::uint16_t index, std::uint8_t sub) {
  namespace obj = canopen::obj;
  const struct {
    const PdoSlot* slot;
    std::uint16_t index;
    std::uint8_t sub;
    bool receive;
  } slots[] = {{&l.controlword, obj::controlword, 0, true},
               {&l.target_position, obj::target_position, 0, true},
               {&l.statusword, obj::statusword, 0, false},
               {&l.position_actual, obj::position_actual, 0, false},
               {&l.velocity_actual, obj::velocity_actual, 0, false},
               {&l.following_error, obj::following_error_actual, 0, false},
               {&l.load_position, l.load_position_index, l.load_position_sub, false}};
  for (const auto& s : slots) {
    if (s.index == index && s.sub == sub && s.slot->mapped()) {
      return std::string{s.receive ? "RPDO" : "TPDO"} + std::to_string(s.slot->pdo);
    }
  }
  return {};
}

}  // namespace

std::vector<Capability> capabilities(const Description& description, const DriveConfigResult& plan,
                                     const FeedbackRequest& feedback) {
  std::vector<Known> known{std::begin(kKnown), std::end(kKnown)};
  if (feedback.load_position_index != 0) {
    known.push_back({feedback.load_position_index, feedback.load_position_sub, "load position (the load feedback)",
                     false, ""});
  }
  std::array<canopen::StartupStep, canopen::remote_drive_max_steps> steps{};
  const std::size_t count = plan.ok() ? canopen::plan_start_up(plan.config, steps).value_or(0) : 0;
  std::vector<Capability> out;
  for (const Known& k : known) {
    Capability c{k.index, k.sub, k.name, k.needed, description.find(k.index, k.sub) != nullptr, {}, k.without};
    if (plan.ok()) c.use = slot_use(plan.config.layout, k.index, k.sub);
    for (std::size_t i = 0; i < count && c.use.empty(); ++i) {
      if (steps[i].index() != k.index || steps[i].sub() != k.sub) continue;
      switch (steps[i].action()) {
        case canopen::StartupAction::write: c.use = "written"; break;
        case canopen::StartupAction::check: c.use = "checked"; break;
        case canopen::StartupAction::read: c.use = "read"; break;
        case canopen::StartupAction::read_mapping: break;
      }
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace settle::hal::eds
