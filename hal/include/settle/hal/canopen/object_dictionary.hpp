// SPDX-License-Identifier: Apache-2.0
// A static object dictionary: a sorted table of (index, sub-index) entries, each bound to a
// variable its owner declares. The SDO server and the PDO mappings read and write through it
// with CiA 301 access rules, sizes and value ranges; the owner reads its variables directly.
//
// Two kinds of entry: integers (8/16/32-bit, the only kind a PDO maps; their path is a switch on
// the type and a copy, nothing more) and byte strings (VISIBLE_STRING, OCTET_STRING, DOMAIN),
// each backed by a fixed buffer its owner declares (OdByteString<N>): a current size and a
// capacity, read by SDO upload and, where the access allows, written by SDO download.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>

#include "settle/hal/canopen/sdo_abort.hpp"

namespace settle::hal::canopen {

// Values are the CiA 301 data type indices, so an EDS DataType reads the same.
enum class OdType : std::uint16_t {
  i8 = 0x0002,
  i16 = 0x0003,
  i32 = 0x0004,
  u8 = 0x0005,
  u16 = 0x0006,
  u32 = 0x0007,
  visible_string = 0x0009,
  octet_string = 0x000A,
  domain = 0x000F,
};

[[nodiscard]] constexpr bool od_type_is_bytes(OdType type) noexcept {
  return type == OdType::visible_string || type == OdType::octet_string || type == OdType::domain;
}

[[nodiscard]] constexpr std::uint8_t od_type_size(OdType type) noexcept {
  switch (type) {
    case OdType::i8:
    case OdType::u8: return 1;
    case OdType::i16:
    case OdType::u16: return 2;
    case OdType::i32:
    case OdType::u32: return 4;
    case OdType::visible_string:
    case OdType::octet_string:
    case OdType::domain: return 0;  // variable length: see OdBytes
  }
  return 0;
}

[[nodiscard]] constexpr bool od_type_signed(OdType type) noexcept {
  return type == OdType::i8 || type == OdType::i16 || type == OdType::i32;
}

enum class OdAccess : std::uint8_t { ro, wo, rw, constant };

// The value of a byte-string entry: `size` bytes in use out of `capacity` at `data`. Both the
// bytes and this descriptor belong to the entry's owner (see OdByteString); the dictionary only
// changes them through ObjectDictionary::write_bytes.
struct OdBytes {
  std::uint8_t* data{nullptr};
  std::uint32_t capacity{0};
  std::uint32_t size{0};

  [[nodiscard]] std::span<const std::uint8_t> view() const noexcept { return {data, size}; }
};

// Fixed storage for one byte-string object. Not copyable: the descriptor points into the
// object itself, and a copy would point into the original.
template <std::uint32_t N>
class OdByteString {
 public:
  OdByteString() noexcept = default;
  OdByteString(const OdByteString&) = delete;
  OdByteString& operator=(const OdByteString&) = delete;

  // A string literal's characters, without its terminating NUL (CiA 301 strings carry none).
  template <std::size_t M>
  void assign(const char (&text)[M]) noexcept {
    static_assert(M >= 1 && M - 1 <= N, "the text does not fit the object");
    for (std::size_t i = 0; i + 1 < M; ++i) {
      storage_[i] = static_cast<std::uint8_t>(text[i]);
    }
    bytes_.size = static_cast<std::uint32_t>(M - 1);
  }

  [[nodiscard]] OdBytes& bytes() noexcept { return bytes_; }
  [[nodiscard]] std::span<const std::uint8_t> view() const noexcept { return bytes_.view(); }

 private:
  std::uint8_t storage_[N]{};
  OdBytes bytes_{storage_, N, 0};
};

// A typed reference to the variable behind an entry. The tag says which pointer is live.
class OdVar {
 public:
  explicit constexpr OdVar(std::uint8_t& v) noexcept : type_{OdType::u8} { p_.u8 = &v; }
  explicit constexpr OdVar(std::int8_t& v) noexcept : type_{OdType::i8} { p_.i8 = &v; }
  explicit constexpr OdVar(std::uint16_t& v) noexcept : type_{OdType::u16} { p_.u16 = &v; }
  explicit constexpr OdVar(std::int16_t& v) noexcept : type_{OdType::i16} { p_.i16 = &v; }
  explicit constexpr OdVar(std::uint32_t& v) noexcept : type_{OdType::u32} { p_.u32 = &v; }
  explicit constexpr OdVar(std::int32_t& v) noexcept : type_{OdType::i32} { p_.i32 = &v; }
  // type is one of the byte-string types (od_type_is_bytes).
  constexpr OdVar(OdBytes& b, OdType type) noexcept : type_{type} { p_.bytes = &b; }
  // Refers to nothing: the spare rows of a table sized for its largest configuration, which no
  // dictionary's span includes.
  constexpr OdVar() noexcept : type_{OdType::u8} {}

  [[nodiscard]] constexpr OdType type() const noexcept { return type_; }
  // The byte string behind a byte-string entry; nullptr for an integer.
  [[nodiscard]] OdBytes* bytes() const noexcept { return od_type_is_bytes(type_) ? p_.bytes : nullptr; }
  // The value as its wire bits, zero-extended to 32 bits (0 for a byte string).
  [[nodiscard]] std::uint32_t raw() const noexcept;
  // The value as a number (signed types sign-extended), for range checks.
  [[nodiscard]] std::int64_t value() const noexcept;
  // Stores the low bytes of raw into the variable (the reference itself does not change);
  // the caller has checked size and range.
  void set_raw(std::uint32_t raw) const noexcept;

 private:
  union Ptr {
    std::uint8_t* u8;
    std::int8_t* i8;
    std::uint16_t* u16;
    std::int16_t* i16;
    std::uint32_t* u32;
    std::int32_t* i32;
    OdBytes* bytes;
  };
  Ptr p_{};
  OdType type_;
};

struct OdEntry {
  std::uint16_t index;
  std::uint8_t sub;
  OdAccess access;
  bool pdo_mappable;
  OdVar var;
  std::int64_t min;  // inclusive limits enforced on writes from the bus (byte strings: on the length)
  std::int64_t max;
};

// Builds an entry whose limits default to the full range of the variable's type.
template <typename T>
[[nodiscard]] constexpr OdEntry od_entry(std::uint16_t index, std::uint8_t sub, T& var, OdAccess access,
                                         bool pdo_mappable = false,
                                         std::int64_t min = std::numeric_limits<T>::min(),
                                         std::int64_t max = std::numeric_limits<T>::max()) noexcept {
  static_assert(std::is_integral_v<T> && sizeof(T) <= 4, "object dictionary variables are 8/16/32-bit integers");
  return OdEntry{index, sub, access, pdo_mappable, OdVar{var}, min, max};
}

// A byte-string entry: never PDO-mappable; a write from the bus may set any length up to the
// buffer's capacity.
[[nodiscard]] constexpr OdEntry od_bytes_entry(std::uint16_t index, std::uint8_t sub, OdBytes& bytes, OdType type,
                                               OdAccess access) noexcept {
  return OdEntry{index, sub, access, false, OdVar{bytes, type}, 0, bytes.capacity};
}

class ObjectDictionary;

// Called before a write from the bus is stored, after access, size and range checks: the
// owner vetoes values its application cannot take (an unsupported mode, say) with an abort
// code, and learns about the ones it accepts (for a byte string, value is the new length and
// the bytes are not stored yet). A plain function pointer keeps it heap-free.
using OdWriteHook = SdoAbort (*)(void* context, const OdEntry& entry, std::int64_t value);
// Called after a write has been stored, so the owner can react (controlword, periods).
using OdWrittenHook = void (*)(void* context, const OdEntry& entry);

class ObjectDictionary {
 public:
  ObjectDictionary() = default;
  explicit ObjectDictionary(std::span<const OdEntry> entries) noexcept : entries_{entries} {}

  void set_hooks(OdWriteHook check, OdWrittenHook written, void* context) noexcept {
    check_ = check;
    written_ = written;
    context_ = context;
  }

  // Entries must be sorted by (index, sub) without duplicates; owners test this once.
  [[nodiscard]] bool is_well_formed() const noexcept;
  [[nodiscard]] const OdEntry* find(std::uint16_t index, std::uint8_t sub) const noexcept;
  [[nodiscard]] bool has_index(std::uint16_t index) const noexcept;
  [[nodiscard]] std::span<const OdEntry> entries() const noexcept { return entries_; }

  // The entry an SDO upload (readable) or download (writable) may access: no object, no
  // sub-index, write-only or read-only abort with their codes.
  [[nodiscard]] SdoAbort readable(std::uint16_t index, std::uint8_t sub, const OdEntry*& entry) const noexcept;
  [[nodiscard]] SdoAbort writable(std::uint16_t index, std::uint8_t sub, const OdEntry*& entry) const noexcept;

  // Reads for the bus: honours access rights (write-only objects abort). Integers only: a
  // byte string aborts 0x06010000 (its bytes are read through OdVar::bytes()).
  [[nodiscard]] SdoAbort read(std::uint16_t index, std::uint8_t sub, std::uint32_t& raw,
                              std::uint8_t& size) const noexcept;
  // Writes from the bus: access, size (0 = not indicated), range, then the owner's hook.
  // On any abort the variable is left untouched. A byte string takes the low `size` bytes of
  // raw (four when not indicated), as an expedited download carries them.
  [[nodiscard]] SdoAbort write(std::uint16_t index, std::uint8_t sub, std::uint32_t raw,
                               std::uint8_t size) noexcept;
  // Replaces a byte string's value: longer than its capacity aborts 0x06070012, then the
  // length limits and the owner's hook; on any abort the bytes and size are left untouched.
  [[nodiscard]] SdoAbort write_bytes(const OdEntry& entry, std::span<const std::uint8_t> bytes) noexcept;
  // Range and owner's veto for an entry already found (the PDO path resolves entries once
  // and checks every mapped value before storing any), then the store itself.
  [[nodiscard]] SdoAbort check_entry(const OdEntry& entry, std::uint32_t raw) const noexcept;
  void store_entry(const OdEntry& entry, std::uint32_t raw) noexcept;
  [[nodiscard]] SdoAbort write_entry(const OdEntry& entry, std::uint32_t raw) noexcept;

 private:
  [[nodiscard]] SdoAbort locate(std::uint16_t index, std::uint8_t sub, const OdEntry*& entry) const noexcept;

  std::span<const OdEntry> entries_{};
  OdWriteHook check_{nullptr};
  OdWrittenHook written_{nullptr};
  void* context_{nullptr};
};

}  // namespace settle::hal::canopen
