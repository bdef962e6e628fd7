// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/process_data.hpp"

#include <type_traits>

#include "settle/hal/canopen/byte_order.hpp"

namespace settle::hal::canopen {
namespace {

// Every value a layout places: its slot, direction, object and size (Layout: const or not).
template <typename Slot>
struct Placed {
  Slot* slot;
  bool receive;
  std::uint16_t index;
  std::uint8_t sub;
  std::uint8_t size;
};

template <typename Layout>
auto placed(Layout& l) noexcept {
  using Slot = std::conditional_t<std::is_const_v<Layout>, const PdoSlot, PdoSlot>;
  return std::array<Placed<Slot>, 7>{{{&l.controlword, true, obj::controlword, 0, 2},
                                      {&l.target_position, true, obj::target_position, 0, 4},
                                      {&l.statusword, false, obj::statusword, 0, 2},
                                      {&l.position_actual, false, obj::position_actual, 0, 4},
                                      {&l.load_position, false, l.load_position_index, l.load_position_sub, 4},
                                      {&l.velocity_actual, false, obj::velocity_actual, 0, 4},
                                      {&l.following_error, false, obj::following_error_actual, 0, 4}}};
}

constexpr const char* kLayoutErrorCodes[] = {SETTLE_HAL_LAYOUT_ERRORS(SETTLE_ENUM_CODE)};
constexpr const char* kLayoutErrorTexts[] = {SETTLE_HAL_LAYOUT_ERRORS(SETTLE_ENUM_TEXT)};

}  // namespace

const char* to_string(LayoutError error) noexcept { return enum_text(kLayoutErrorCodes, error, "?"); }
const char* describe(LayoutError error) noexcept { return enum_text(kLayoutErrorTexts, error, "?"); }

LayoutError check_layout(const ProcessDataLayout& layout, bool dynamic) noexcept {
  const auto all = placed(layout);
  for (std::size_t i = 0; i < 4; ++i) {
    if (!all[i].slot->mapped()) return LayoutError::missing;
  }
  for (const auto& p : all) {
    if (!p.slot->mapped()) continue;
    if (p.slot->pdo > layout_pdo_count || p.slot->size != p.size) return LayoutError::bad_slot;
    if (p.slot->offset + p.slot->size > 8) return LayoutError::too_long;
  }
  // The master sends one RPDO a period; it may read a period's feedback from several TPDOs.
  if (layout.controlword.pdo != layout.target_position.pdo ||
      (!split_feedback_supported && layout.statusword.pdo != layout.position_actual.pdo)) {
    return LayoutError::split;
  }
  for (std::size_t i = 0; i < all.size(); ++i) {
    for (std::size_t j = i + 1; j < all.size(); ++j) {
      const PdoSlot& a = *all[i].slot;
      const PdoSlot& b = *all[j].slot;
      if (a.mapped() && b.mapped() && all[i].receive == all[j].receive && a.pdo == b.pdo &&
          a.offset < b.offset + b.size && b.offset < a.offset + a.size) {
        return LayoutError::overlap;
      }
    }
  }
  if (dynamic) {
    // Without overlaps, values back to back from byte 0 fill exactly the PDO's length.
    for (const bool receive : {true, false}) {
      for (std::uint8_t n = 1; n <= layout_pdo_count; ++n) {
        unsigned bytes = 0;
        for (const auto& p : all) {
          if (p.receive == receive && p.slot->pdo == n) bytes += p.slot->size;
        }
        if (bytes != layout_pdo_length(layout, receive, n)) return LayoutError::gap;
      }
    }
  }
  return LayoutError::none;
}

std::uint8_t layout_pdo_length(const ProcessDataLayout& layout, bool receive, std::uint8_t number) noexcept {
  unsigned end = 0;
  for (const auto& p : placed(layout)) {
    if (p.receive == receive && p.slot->mapped() && p.slot->pdo == number && p.slot->offset + p.slot->size > end) {
      end = p.slot->offset + p.slot->size;
    }
  }
  return static_cast<std::uint8_t>(end);
}

std::uint8_t feedback_tpdos(const ProcessDataLayout& layout) noexcept {
  unsigned mask = 0;
  for (std::uint8_t n = 1; n <= layout_pdo_count; ++n) {
    if (layout_pdo_length(layout, false, n) != 0) mask |= 1U << (n - 1U);
  }
  return static_cast<std::uint8_t>(mask);
}

PdoMapping layout_mapping(const ProcessDataLayout& layout, bool receive, std::uint8_t number, NodeId node) noexcept {
  PdoMapping m{pdo_cob_id(receive, number, node), pdo_transmission::synchronous, 0, {}};
  // In byte order: the next value is the one starting where the previous ended.
  for (std::uint8_t at = 0; at < 8 && m.count < pdo_max_entries;) {
    bool found = false;
    for (const auto& p : placed(layout)) {
      if (p.receive == receive && p.slot->mapped() && p.slot->pdo == number && p.slot->offset == at) {
        m.entries[m.count++] = PdoMappingEntry{p.index, p.sub, static_cast<std::uint8_t>(8U * p.size)};
        at = static_cast<std::uint8_t>(at + p.slot->size);
        found = true;
        break;
      }
    }
    if (!found) break;
  }
  return m;
}

bool place_mapped_object(ProcessDataLayout& layout, bool receive, std::uint8_t number, std::uint8_t offset_bytes,
                         std::uint32_t raw_entry) noexcept {
  const auto index = static_cast<std::uint16_t>(raw_entry >> 16U);
  const auto sub = static_cast<std::uint8_t>(raw_entry >> 8U);
  const auto bits = static_cast<std::uint8_t>(raw_entry);
  // A dummy entry (a data type index) is bytes a drive ignores: fine in a TPDO; in an RPDO the
  // master would have to send them, which its layouts do not.
  if (index != 0 && index < 0x0008) return !receive;
  const PdoSlot slot{number, offset_bytes, static_cast<std::uint8_t>(bits / 8U)};
  // The controlword and the statusword go where their partner is: a later PDO takes them over
  // unless the partner already sits with them (RPDO1 = controlword alone, RPDO2 = controlword +
  // target position: RPDO2).
  PdoSlot& first = receive ? layout.controlword : layout.statusword;
  const PdoSlot& partner = receive ? layout.target_position : layout.position_actual;
  if (index == (receive ? obj::controlword : obj::statusword) && sub == 0) {
    if (!first.mapped() || first.pdo != partner.pdo) first = slot;
    return true;
  }
  for (const auto& p : placed(layout)) {
    if (p.receive == receive && p.index == index && p.sub == sub) {
      if (!p.slot->mapped()) *p.slot = slot;
      return true;
    }
  }
  return !receive;  // a TPDO may carry more than the master reads; an RPDO may not
}

std::uint32_t slot_value(const PdoSlot& slot, const CanFrame& frame) noexcept {
  return get_le(std::span<const std::uint8_t>{&frame.data[slot.offset], slot.size}, slot.size);
}

void encode_layout_rpdo(const ProcessDataLayout& layout, NodeId node, std::uint16_t controlword,
                        std::int32_t target_position, CanFrame& out) noexcept {
  out.id = pdo_cob_id(true, layout.controlword.pdo, node);
  out.flags = 0;
  out.len = layout_pdo_length(layout, true, layout.controlword.pdo);
  for (std::size_t i = 0; i < 8; ++i) out.data[i] = 0;
  put_le(std::span<std::uint8_t>{&out.data[layout.controlword.offset], 2}, controlword, 2);
  put_le(std::span<std::uint8_t>{&out.data[layout.target_position.offset], 4},
         static_cast<std::uint32_t>(target_position), 4);
}

}  // namespace settle::hal::canopen
