// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/object_dictionary.hpp"

#include "settle/hal/canopen/byte_order.hpp"

namespace settle::hal::canopen {

std::uint32_t OdVar::raw() const noexcept {
  switch (type_) {
    case OdType::u8: return *p_.u8;
    case OdType::i8: return static_cast<std::uint8_t>(*p_.i8);
    case OdType::u16: return *p_.u16;
    case OdType::i16: return static_cast<std::uint16_t>(*p_.i16);
    case OdType::u32: return *p_.u32;
    case OdType::i32: return static_cast<std::uint32_t>(*p_.i32);
    case OdType::visible_string:
    case OdType::octet_string:
    case OdType::domain: return 0;
  }
  return 0;
}

std::int64_t OdVar::value() const noexcept {
  const std::uint32_t bits = raw();
  if (od_type_signed(type_)) {
    return sign_extend(bits, 8U * od_type_size(type_));
  }
  return bits;
}

void OdVar::set_raw(std::uint32_t raw) const noexcept {
  switch (type_) {
    case OdType::u8: *p_.u8 = static_cast<std::uint8_t>(raw); break;
    case OdType::i8: *p_.i8 = static_cast<std::int8_t>(static_cast<std::uint8_t>(raw)); break;
    case OdType::u16: *p_.u16 = static_cast<std::uint16_t>(raw); break;
    case OdType::i16: *p_.i16 = static_cast<std::int16_t>(static_cast<std::uint16_t>(raw)); break;
    case OdType::u32: *p_.u32 = raw; break;
    case OdType::i32: *p_.i32 = static_cast<std::int32_t>(raw); break;
    case OdType::visible_string:
    case OdType::octet_string:
    case OdType::domain: break;  // bytes are stored by ObjectDictionary::write_bytes
  }
}

namespace {
[[nodiscard]] constexpr std::uint32_t key(std::uint16_t index, std::uint8_t sub) noexcept {
  return (static_cast<std::uint32_t>(index) << 8U) | sub;
}
[[nodiscard]] constexpr std::uint32_t key(const OdEntry& e) noexcept { return key(e.index, e.sub); }

// First entry whose key is not less than k (the table is sorted).
[[nodiscard]] const OdEntry* lower_bound(std::span<const OdEntry> entries, std::uint32_t k) noexcept {
  std::size_t lo = 0;
  std::size_t hi = entries.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (key(entries[mid]) < k) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo < entries.size() ? &entries[lo] : nullptr;
}
}  // namespace

bool ObjectDictionary::is_well_formed() const noexcept {
  for (std::size_t i = 1; i < entries_.size(); ++i) {
    if (key(entries_[i - 1]) >= key(entries_[i])) {
      return false;
    }
  }
  for (const OdEntry& e : entries_) {
    if (e.min > e.max) {
      return false;
    }
  }
  return true;
}

const OdEntry* ObjectDictionary::find(std::uint16_t index, std::uint8_t sub) const noexcept {
  const OdEntry* e = lower_bound(entries_, key(index, sub));
  return (e != nullptr && e->index == index && e->sub == sub) ? e : nullptr;
}

bool ObjectDictionary::has_index(std::uint16_t index) const noexcept {
  const OdEntry* e = lower_bound(entries_, key(index, 0));
  return e != nullptr && e->index == index;
}

SdoAbort ObjectDictionary::locate(std::uint16_t index, std::uint8_t sub, const OdEntry*& entry) const noexcept {
  entry = find(index, sub);
  if (entry != nullptr) {
    return SdoAbort::none;
  }
  return has_index(index) ? SdoAbort::no_sub_index : SdoAbort::no_object;
}

SdoAbort ObjectDictionary::readable(std::uint16_t index, std::uint8_t sub, const OdEntry*& entry) const noexcept {
  if (const SdoAbort abort = locate(index, sub, entry); abort != SdoAbort::none) {
    return abort;
  }
  return entry->access == OdAccess::wo ? SdoAbort::write_only : SdoAbort::none;
}

SdoAbort ObjectDictionary::writable(std::uint16_t index, std::uint8_t sub, const OdEntry*& entry) const noexcept {
  if (const SdoAbort abort = locate(index, sub, entry); abort != SdoAbort::none) {
    return abort;
  }
  return entry->access == OdAccess::ro || entry->access == OdAccess::constant ? SdoAbort::read_only
                                                                                : SdoAbort::none;
}

SdoAbort ObjectDictionary::read(std::uint16_t index, std::uint8_t sub, std::uint32_t& raw,
                                std::uint8_t& size) const noexcept {
  const OdEntry* entry = nullptr;
  if (const SdoAbort abort = readable(index, sub, entry); abort != SdoAbort::none) {
    return abort;
  }
  if (entry->var.bytes() != nullptr) {
    return SdoAbort::unsupported_access;
  }
  raw = entry->var.raw();
  size = od_type_size(entry->var.type());
  return SdoAbort::none;
}

SdoAbort ObjectDictionary::write(std::uint16_t index, std::uint8_t sub, std::uint32_t raw,
                                 std::uint8_t size) noexcept {
  const OdEntry* entry = nullptr;
  if (const SdoAbort abort = writable(index, sub, entry); abort != SdoAbort::none) {
    return abort;
  }
  if (entry->var.bytes() != nullptr) {
    const std::uint8_t count = size == 0 || size > 4 ? 4 : size;
    std::uint8_t bytes[4]{};
    put_u32(bytes, raw);
    return write_bytes(*entry, std::span<const std::uint8_t>{bytes, count});
  }
  const std::uint8_t expected = od_type_size(entry->var.type());
  if (size != 0 && size > expected) {
    return SdoAbort::length_too_high;
  }
  if (size != 0 && size < expected) {
    return SdoAbort::length_too_low;
  }
  // An expedited download without a size indication carries four bytes; only the object's
  // own bytes count, so stray padding cannot turn into a range error.
  const std::uint32_t mask = expected == 4 ? 0xFFFF'FFFFU : ((1U << (8U * expected)) - 1U);
  return write_entry(*entry, raw & mask);
}

SdoAbort ObjectDictionary::write_bytes(const OdEntry& entry, std::span<const std::uint8_t> bytes) noexcept {
  OdBytes* target = entry.var.bytes();
  if (target == nullptr) {
    return SdoAbort::unsupported_access;
  }
  if (bytes.size() > target->capacity) {
    return SdoAbort::length_too_high;
  }
  const auto length = static_cast<std::int64_t>(bytes.size());
  if (length > entry.max) {
    return SdoAbort::length_too_high;
  }
  if (length < entry.min) {
    return SdoAbort::length_too_low;
  }
  if (check_ != nullptr) {
    if (const SdoAbort abort = check_(context_, entry, length); abort != SdoAbort::none) {
      return abort;
    }
  }
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    target->data[i] = bytes[i];
  }
  target->size = static_cast<std::uint32_t>(bytes.size());
  if (written_ != nullptr) {
    written_(context_, entry);
  }
  return SdoAbort::none;
}

SdoAbort ObjectDictionary::check_entry(const OdEntry& entry, std::uint32_t raw) const noexcept {
  const OdType type = entry.var.type();
  const std::int64_t value =
      od_type_signed(type) ? std::int64_t{sign_extend(raw, 8U * od_type_size(type))} : std::int64_t{raw};
  if (value > entry.max) {
    return SdoAbort::value_too_high;
  }
  if (value < entry.min) {
    return SdoAbort::value_too_low;
  }
  return check_ != nullptr ? check_(context_, entry, value) : SdoAbort::none;
}

void ObjectDictionary::store_entry(const OdEntry& entry, std::uint32_t raw) noexcept {
  entry.var.set_raw(raw);
  if (written_ != nullptr) {
    written_(context_, entry);
  }
}

SdoAbort ObjectDictionary::write_entry(const OdEntry& entry, std::uint32_t raw) noexcept {
  const SdoAbort abort = check_entry(entry, raw);
  if (abort == SdoAbort::none) {
    store_entry(entry, raw);
  }
  return abort;
}

}  // namespace settle::hal::canopen
