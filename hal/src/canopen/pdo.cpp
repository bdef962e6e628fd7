// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/pdo.hpp"

#include "settle/hal/canopen/byte_order.hpp"
#include "settle/hal/canopen/cob_id.hpp"

namespace settle::hal::canopen {

SdoAbort PdoBinding::bind(const PdoMapping& mapping, ObjectDictionary& od, PdoDirection direction) noexcept {
  od_ = nullptr;
  if (mapping.count > pdo_max_entries) {
    return SdoAbort::pdo_too_long;
  }
  if (mapping.bit_length() > 64) {
    return SdoAbort::pdo_too_long;
  }
  std::array<const OdEntry*, pdo_max_entries> resolved{};
  for (std::size_t i = 0; i < mapping.count; ++i) {
    const PdoMappingEntry& m = mapping.entries[i];
    const OdEntry* entry = od.find(m.index, m.sub);
    if (entry == nullptr) {
      return od.has_index(m.index) ? SdoAbort::no_sub_index : SdoAbort::no_object;
    }
    const bool readable = entry->access != OdAccess::wo;
    const bool writable = entry->access == OdAccess::wo || entry->access == OdAccess::rw;
    if (!entry->pdo_mappable || (direction == PdoDirection::receive && !writable) ||
        (direction == PdoDirection::transmit && !readable)) {
      return SdoAbort::not_mappable;
    }
    if (m.bits != 8U * od_type_size(entry->var.type())) {
      return SdoAbort::length_mismatch;
    }
    resolved[i] = entry;
  }
  resolved_ = resolved;
  cob_id_ = mapping.cob_id;
  count_ = mapping.count;
  bytes_ = static_cast<std::uint8_t>(mapping.byte_length());
  od_ = &od;
  return SdoAbort::none;
}

bool PdoBinding::carries(std::uint16_t index, std::uint8_t sub) const noexcept {
  for (std::size_t i = 0; i < count_ && od_ != nullptr; ++i) {
    if (resolved_[i]->index == index && resolved_[i]->sub == sub) {
      return true;
    }
  }
  return false;
}

PdoStatus PdoBinding::pack(CanFrame& out) const noexcept {
  if (od_ == nullptr) {
    return PdoStatus::unbound;
  }
  out = CanFrame{};
  out.id = cob_id_;
  std::size_t offset = 0;
  for (std::size_t i = 0; i < count_; ++i) {
    const std::size_t n = od_type_size(resolved_[i]->var.type());
    put_le(std::span<std::uint8_t>{out.data}.subspan(offset, n), resolved_[i]->var.raw(), n);
    offset += n;
  }
  out.len = static_cast<std::uint8_t>(offset);
  return PdoStatus::ok;
}

PdoStatus PdoBinding::unpack(const CanFrame& in) noexcept {
  if (od_ == nullptr) {
    return PdoStatus::unbound;
  }
  if (!is_canopen_data_frame(in) || in.id != cob_id_) {
    return PdoStatus::wrong_id;
  }
  const std::size_t expected = bytes_;
  if (in.len < expected) {
    return PdoStatus::too_short;
  }

  // Check every value before storing any: a PDO is applied whole or not at all.
  std::array<std::uint32_t, pdo_max_entries> raw{};
  std::size_t offset = 0;
  for (std::size_t i = 0; i < count_; ++i) {
    const std::size_t n = od_type_size(resolved_[i]->var.type());
    raw[i] = get_le(std::span<const std::uint8_t>{in.data}.subspan(offset, n), n);
    offset += n;
    if (od_->check_entry(*resolved_[i], raw[i]) != SdoAbort::none) {
      return PdoStatus::rejected;
    }
  }
  for (std::size_t i = 0; i < count_; ++i) {
    od_->store_entry(*resolved_[i], raw[i]);
  }
  return in.len > expected ? PdoStatus::applied_longer : PdoStatus::ok;
}

}  // namespace settle::hal::canopen
