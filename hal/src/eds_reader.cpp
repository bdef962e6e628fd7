// SPDX-License-Identifier: Apache-2.0
// EDS/DCF reading in three passes, each linear in the file: the lines counted against the
// bounds (exceeded_bound), the file split into sections and keys (tokenize: lines of any length
// read whole), then CiA 306's meaning (Builder: object sections [IIII] and [IIIIsubS] indexed by
// object once, the object lists, DeviceInfo, a DCF's ParameterValue and NodeID), tolerant of
// what tools write and strict about what a master configures the drive from.
#include "settle/hal/eds_reader.hpp"
#include "settle/hal/canopen/standard_objects.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <limits>
#include <map>

namespace settle::hal::eds {
namespace {

std::string lower(std::string_view s) {
  std::string out{s};
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string trim(std::string_view s) {
  std::size_t b = 0;
  std::size_t e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return std::string{s.substr(b, e - b)};
}

std::string hex4(std::uint16_t index) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", index);
  return buf;
}

std::string object_name(std::uint16_t index, std::uint8_t sub) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X:%u", index, sub);
  return buf;
}

std::optional<std::uint64_t> parse_unsigned(std::string_view text) {
  if (text.empty()) return std::nullopt;
  unsigned base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  } else if (text.size() > 1 && text[0] == '0') {
    base = 8;
    text.remove_prefix(1);
  }
  if (text.empty()) return std::nullopt;
  std::uint64_t v = 0;
  for (const char c : text) {
    unsigned d = 0;
    if (c >= '0' && c <= '9') {
      d = static_cast<unsigned>(c - '0');
    } else if (c >= 'a' && c <= 'f') {
      d = static_cast<unsigned>(c - 'a' + 10);
    } else if (c >= 'A' && c <= 'F') {
      d = static_cast<unsigned>(c - 'A' + 10);
    } else {
      return std::nullopt;
    }
    if (d >= base) return std::nullopt;
    if (v > (std::numeric_limits<std::uint64_t>::max() - d) / base) return std::nullopt;
    v = v * base + d;
  }
  return v;
}

// One section of the file: its keys in lower case (each with the spelling and line it was
// written with, for messages), and the line it started on.
struct Value {
  std::string key;  // as written
  std::string text;
  int line{0};
};
struct Section {
  std::string name;  // as written, without the brackets
  std::map<std::string, Value> keys;
  int line{0};
  [[nodiscard]] const std::string* get(const char* key) const {
    const auto it = keys.find(key);
    return it == keys.end() ? nullptr : &it->second.text;
  }
  // The key as CiA 306 spells it ("DataType"), found in any case.
  [[nodiscard]] const Value* find(std::string_view key) const {
    const auto it = keys.find(lower(key));
    return it == keys.end() ? nullptr : &it->second;
  }
};

struct Raw {
  std::map<std::string, Section> sections;  // upper-case section name
  Problem error;                            // message empty: none
};

// The INI layer, CiA 306's dialect: [section] headers, key=value lines (':' also separates, as
// in the INI readers tools use), comment lines starting with ';' or '#', a ';' after white space
// starting a comment at the end of a value, CRLF or LF line ends, an optional UTF-8 byte order
// mark, white space trimmed around names and values. Section and key names are
// case-insensitive. A line is read whole whatever its length (the file's size is bounded); a
// line that is none of these, a section given twice and a key given twice in one section are
// refused, naming the line.
bool tokenize(std::string_view text, Raw& raw) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  Section* current = nullptr;
  int line = 0;
  const auto refuse = [&](std::string why, std::string key = {}) {
    raw.error = Problem{current != nullptr ? current->name : std::string{}, std::move(key), std::move(why), line};
    return false;
  };
  while (!text.empty()) {
    ++line;
    const std::size_t eol = text.find('\n');
    std::string_view l = text.substr(0, eol);
    text.remove_prefix(eol == std::string_view::npos ? text.size() : eol + 1);
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    const std::string t = trim(l);
    if (t.empty() || t[0] == ';' || t[0] == '#') continue;
    if (t[0] == '[') {
      const std::size_t close = t.find(']');
      current = nullptr;
      if (close == std::string::npos) return refuse("a section header without ']'");
      const std::string after = trim(std::string_view{t}.substr(close + 1));
      if (!after.empty() && after[0] != ';' && after[0] != '#') return refuse("text after the section header");
      std::string name = trim(std::string_view{t}.substr(1, close - 1));
      if (name.empty()) return refuse("a section without a name");
      std::string upper = name;
      for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      const auto [it, fresh] = raw.sections.try_emplace(std::move(upper));
      if (!fresh) {
        raw.error = Problem{
            name, {}, "the section is given twice (first on line " + std::to_string(it->second.line) + ")", line};
        return false;
      }
      it->second.name = std::move(name);
      it->second.line = line;
      current = &it->second;
      continue;
    }
    const std::size_t eq = t.find_first_of("=:");
    if (eq == std::string::npos) return refuse("not an INI line (a [section], key=value or a comment)");
    std::string key = trim(std::string_view{t}.substr(0, eq));
    if (key.empty()) return refuse("a value without a key");
    if (current == nullptr) return refuse("a key before any [section]", key);
    std::string_view value = std::string_view{t}.substr(eq + 1);
    for (std::size_t i = 1; i < value.size(); ++i) {
      if (value[i] == ';' && std::isspace(static_cast<unsigned char>(value[i - 1]))) {
        value = value.substr(0, i);
        break;
      }
    }
    const auto [it, fresh] = current->keys.try_emplace(lower(key));
    if (!fresh)
      return refuse("given twice in the section (first on line " + std::to_string(it->second.line) + ")", key);
    it->second = Value{std::move(key), trim(value), line};
  }
  return true;
}

// "1018" or "1018SUB2" (upper case) -> (index, sub, has_sub); anything else -> nullopt.
struct ObjectSection {
  std::uint16_t index;
  std::uint8_t sub;
  bool has_sub;
};
std::optional<ObjectSection> object_section(const std::string& name) {
  if (name.size() < 4) return std::nullopt;
  const auto index = parse_unsigned("0x" + name.substr(0, 4));
  if (!index) return std::nullopt;
  if (name.size() == 4) return ObjectSection{static_cast<std::uint16_t>(*index), 0, false};
  if (name.size() < 8 || name.size() > 9 || name.compare(4, 3, "SUB") != 0) return std::nullopt;
  const auto sub = parse_unsigned("0x" + name.substr(7));
  if (!sub || *sub > 0xFF) return std::nullopt;
  return ObjectSection{static_cast<std::uint16_t>(*index), static_cast<std::uint8_t>(*sub), true};
}

std::optional<Access> parse_access(const std::string& text) {
  const std::string t = lower(text);
  if (t == "ro") return Access::ro;
  if (t == "wo") return Access::wo;
  if (t == "rw") return Access::rw;
  if (t == "rwr") return Access::rwr;
  if (t == "rww") return Access::rww;
  if (t == "const") return Access::constant;
  return std::nullopt;
}

}  // namespace

// CiA 306's meaning of a read file, in stages; each stage that can refuse the file returns false
// with the refusal in the result (warnings go there too).
struct Builder {
  // Object sections, indexed once: each object's [IIII] and its [IIIIsubS] by sub-index (the
  // file's sections are visited once; every look-up after is by index).
  struct Sections {
    const Section* object{nullptr};  // [IIII], when the file has it
    std::vector<std::pair<std::uint8_t, const Section*>> subs;
    [[nodiscard]] const Section* sub(std::uint8_t s) const {
      const auto it =
          std::lower_bound(subs.begin(), subs.end(), s, [](const auto& p, std::uint8_t v) { return p.first < v; });
      return it != subs.end() && it->first == s ? it->second : nullptr;
    }
  };
  using Objects = std::map<std::uint16_t, Sections>;
  // One entry to read: a VAR's [IIII] (sub 0), or one [IIIIsubS] of an ARRAY or RECORD.
  struct Item {
    std::uint16_t index;
    std::uint8_t sub;
    const Section* section;
  };

  static LoadResult build(const Raw& raw);
  static Objects index_objects(const Raw& raw);
  static bool list_items(const Raw& raw, Objects& objects, std::deque<Section>& synthesized, std::vector<Item>& items,
                         LoadResult& r);
  static bool read_entry(const Item& item, Entry& e, LoadResult& r);
  static bool read_limits(const Section& sec, Entry& e, LoadResult& r);
  static bool check_pdo_objects(const Objects& objects, const Description& d, LoadResult& r);
  static void read_object_lists(const Raw& raw, const Objects& objects, Description& d, LoadResult& r);
  static bool read_device_info(const Raw& raw, Description& d, LoadResult& r);
  static void reconcile_identity(const Raw& raw, Description& d, LoadResult& r);
  static bool read_settle_sections(const Raw& raw, Description& d, LoadResult& r);
};

const char* to_string(Access access) noexcept {
  switch (access) {
    case Access::ro: return "ro";
    case Access::wo: return "wo";
    case Access::rw: return "rw";
    case Access::rwr: return "rwr";
    case Access::rww: return "rww";
    case Access::constant: return "const";
  }
  return "?";
}

unsigned data_type_bits(std::uint16_t type) noexcept {
  switch (type) {
    case data_type::boolean:
    case data_type::i8:
    case data_type::u8: return 8;
    case data_type::i16:
    case data_type::u16: return 16;
    case data_type::i32:
    case data_type::u32:
    case data_type::real32: return 32;
    case data_type::real64:
    case data_type::i64:
    case data_type::u64: return 64;
    default: return 0;
  }
}

bool data_type_is_integer(std::uint16_t type) noexcept {
  return type == data_type::boolean || type == data_type::i8 || type == data_type::i16 || type == data_type::i32 ||
         type == data_type::u8 || type == data_type::u16 || type == data_type::u32 || type == data_type::i64 ||
         type == data_type::u64;
}

bool data_type_is_signed(std::uint16_t type) noexcept {
  return type == data_type::i8 || type == data_type::i16 || type == data_type::i32 || type == data_type::i64;
}

bool data_type_is_real(std::uint16_t type) noexcept { return type == data_type::real32 || type == data_type::real64; }

std::string to_string(const Problem& problem) {
  std::string s;
  if (problem.line > 0) s += "line " + std::to_string(problem.line) + ": ";
  if (!problem.section.empty()) s += "[" + problem.section + "] ";
  if (!problem.key.empty()) s += problem.key + ": ";
  return s + problem.message;
}

namespace {

// "$NODEID+v", "v+$NODEID", "$NODEID" or "v": whether the node id is added, and v's text.
struct NodeTerm {
  bool ok{true};
  bool node{false};
  std::string number;
};
NodeTerm split_node_id(std::string_view text) {
  NodeTerm t{true, false, trim(text)};
  const std::string l = lower(t.number);
  const std::string tag = "$nodeid";
  const auto at = l.find(tag);
  if (at == std::string::npos) return t;
  t.node = true;
  std::string rest = trim(t.number.substr(0, at) + t.number.substr(at + tag.size()));
  // $NODEID+v or v+$NODEID: strip the one '+' that joined them.
  if (!rest.empty() && rest.front() == '+') {
    rest = trim(rest.substr(1));
    t.ok = !rest.empty();
  } else if (!rest.empty() && rest.back() == '+') {
    rest = trim(rest.substr(0, rest.size() - 1));
    t.ok = !rest.empty();
  } else if (!rest.empty()) {
    t.ok = false;
  }
  t.number = rest;
  return t;
}

__extension__ using Wide = __int128;

// A value of integer type `type` from its text, $NODEID resolved for `node`, or why not.
// Decimal, 0x hex or leading-0 octal, with an optional sign; a hex value of a signed type whose
// top bit (of the type's width) is set is that type's two's complement, as tools write negative
// values in hex (0xFFFFFFFFFFFFFFFF: an INTEGER64's -1; 0xFF: an INTEGER8's -1).
struct Integer {
  std::optional<std::int64_t> value;  // UNSIGNED64 above 2^63 - 1: its bits
  std::string why;
};
Integer parse_typed(std::string_view text, std::uint16_t type, std::uint8_t node) {
  const std::string quoted = "'" + trim(text) + "'";
  const NodeTerm t = split_node_id(text);
  if (!t.ok) return {std::nullopt, quoted + " is not a number ($NODEID and a number are joined by one '+')"};
  std::string_view n = t.number;
  bool negative = false;
  if (!n.empty() && (n[0] == '-' || n[0] == '+')) {
    negative = n[0] == '-';
    n.remove_prefix(1);
  }
  const bool hex = n.size() > 2 && n[0] == '0' && (n[1] == 'x' || n[1] == 'X');
  std::uint64_t magnitude = 0;
  if (!(t.node && n.empty())) {
    const auto u = parse_unsigned(n);
    if (!u) return {std::nullopt, quoted + " is not an integer (decimal, 0x hex or 0 octal)"};
    magnitude = *u;
  }
  const unsigned bits = type == data_type::boolean ? 1 : data_type_bits(type);
  const bool is_signed = data_type_is_signed(type);
  Wide v = negative ? -Wide{magnitude} : Wide{magnitude};
  if (hex && !negative && is_signed && v >= (Wide{1} << (bits - 1)) && v < (Wide{1} << bits)) v -= Wide{1} << bits;
  if (t.node) v += node;
  const Wide low = is_signed ? -(Wide{1} << (bits - 1)) : 0;
  const Wide high = is_signed ? (Wide{1} << (bits - 1)) - 1 : (Wide{1} << bits) - 1;
  if (v < low || v > high) {
    return {std::nullopt, quoted + " is outside " + canopen::data_type_name(type, "this data type") + " (" +
                              std::to_string(static_cast<std::int64_t>(low)) + ".." +
                              std::to_string(static_cast<std::uint64_t>(high)) + ")"};
  }
  return {static_cast<std::int64_t>(static_cast<std::uint64_t>(v)), {}};
}

// A REAL32/REAL64 value from its text (decimal, such as 4.5, -0.25 or 1e-3), or why not.
struct Real {
  std::optional<double> value;
  std::string why;
};
Real parse_real(std::string_view text, std::uint16_t type) {
  const std::string t = trim(text);
  std::string_view v = t;
  if (!v.empty() && v[0] == '+') v.remove_prefix(1);
  const std::string_view digits = !v.empty() && v[0] == '-' ? v.substr(1) : v;
  if (digits.size() > 1 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    return {std::nullopt, "'" + t + "': a " + canopen::data_type_name(type, "this data type") +
                              " is written in decimal (such as 4.5), not hex"};
  }
  double d = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), d);
  if (v.empty() || ec != std::errc{} || end != v.data() + v.size() || !std::isfinite(d)) {
    return {std::nullopt, "'" + t + "' is not a decimal number"};
  }
  if (type == data_type::real32 && std::fabs(d) > static_cast<double>(std::numeric_limits<float>::max())) {
    return {std::nullopt, "'" + t + "' is outside REAL32"};
  }
  return {d, {}};
}

// a < b for two values of `type` (UNSIGNED64's come as bits).
bool less(std::int64_t a, std::int64_t b, std::uint16_t type) {
  return type == data_type::u64 ? static_cast<std::uint64_t>(a) < static_cast<std::uint64_t>(b) : a < b;
}

std::string integer_text(std::int64_t v, std::uint16_t type) {
  return type == data_type::u64 ? std::to_string(static_cast<std::uint64_t>(v)) : std::to_string(v);
}

}  // namespace

std::optional<std::int64_t> parse_integer(std::string_view text, std::uint8_t node) {
  const NodeTerm t = split_node_id(text);
  if (!t.ok) return std::nullopt;
  if (t.node && t.number.empty()) return std::int64_t{node};
  std::string_view n = t.number;
  bool negative = false;
  if (!n.empty() && (n[0] == '-' || n[0] == '+')) {
    negative = n[0] == '-';
    n.remove_prefix(1);
  }
  const auto v = parse_unsigned(n);
  if (!v) return std::nullopt;
  // 64-bit objects aside, every value fits an int64 with room for the node id.
  if (*v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) - 0x80) return std::nullopt;
  const auto magnitude = static_cast<std::int64_t>(*v);
  return (t.node ? node : 0) + (negative ? -magnitude : magnitude);
}

std::optional<std::int64_t> Entry::value(std::uint8_t node) const {
  if (!data_type_is_integer(data_type)) return std::nullopt;
  const std::string& text = parameter_value.empty() ? default_value : parameter_value;
  if (text.empty()) return std::nullopt;
  return parse_typed(text, data_type, node).value;
}

std::optional<double> Entry::real_value() const {
  if (!data_type_is_real(data_type)) return std::nullopt;
  const std::string& text = parameter_value.empty() ? default_value : parameter_value;
  if (text.empty()) return std::nullopt;
  return parse_real(text, data_type).value;
}

const Entry* Description::find(std::uint16_t index, std::uint8_t sub) const noexcept {
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), std::pair{index, sub},
                                   [](const Entry& e, const std::pair<std::uint16_t, std::uint8_t>& k) {
                                     return e.index != k.first ? e.index < k.first : e.sub < k.second;
                                   });
  return it != entries_.end() && it->index == index && it->sub == sub ? &*it : nullptr;
}

bool Description::has(std::uint16_t index) const noexcept {
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), index,
                                   [](const Entry& e, std::uint16_t i) { return e.index < i; });
  return it != entries_.end() && it->index == index;
}

namespace {

std::vector<Pdo> pdos(const Description& d, bool receive, std::uint8_t node) {
  std::vector<Pdo> out;
  for (unsigned n = 1; n <= 512; ++n) {
    Pdo p{};
    p.receive = receive;
    p.number = n;
    const Entry* cob = d.find(p.communication_index(), 1);
    const Entry* count = d.find(p.mapping_index(), 0);
    if (cob == nullptr || count == nullptr) continue;
    p.cob_id = static_cast<std::uint32_t>(cob->value(node).value_or(0x80000000));
    if (const Entry* type = d.find(p.communication_index(), 2)) {
      p.transmission_type = static_cast<std::uint8_t>(type->value(node).value_or(0));
    }
    p.mapping_writable = count->writable();
    const auto entries = count->value(node).value_or(0);
    for (std::int64_t i = 1; i <= entries && i <= 64; ++i) {
      const Entry* m = d.find(p.mapping_index(), static_cast<std::uint8_t>(i));
      if (m == nullptr) break;
      const auto raw = static_cast<std::uint32_t>(m->value(node).value_or(0));
      p.mapping.push_back(MappedObject{static_cast<std::uint16_t>(raw >> 16), static_cast<std::uint8_t>(raw >> 8),
                                       static_cast<std::uint8_t>(raw)});
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

std::vector<Pdo> Description::rpdos(std::uint8_t node) const { return pdos(*this, true, node); }
std::vector<Pdo> Description::tpdos(std::uint8_t node) const { return pdos(*this, false, node); }

namespace {

bool is_communication(std::uint16_t index) {
  return (index >= 0x1400 && index <= 0x15FF) || (index >= 0x1800 && index <= 0x19FF);
}
bool is_mapping(std::uint16_t index) {
  return (index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF);
}
bool is_string(std::uint16_t type) {
  return type == data_type::visible_string || type == data_type::octet_string || type == data_type::unicode_string ||
         type == data_type::domain;
}

// Where a key is, as a problem's place: the key's spelling and line when the section has it,
// else CiA 306's spelling and the section's line.
Problem at(const Section& section, std::string_view key, std::string message) {
  const Value* v = key.empty() ? nullptr : section.find(key);
  return Problem{section.name, v != nullptr ? v->key : std::string{key}, std::move(message),
                 v != nullptr ? v->line : section.line};
}

// CiA 306's CompactSubObj=N: an ARRAY whose sub 0 (UNSIGNED8, ro) holds N and whose subs 1..N
// share the object's DataType, AccessType, PDOMapping, limits and default; their names come from
// [IIIIName] (key i), their values from [IIIIValue] (key i, a DCF's configured value) when given.
// Each becomes a section of its own, read like a written [IIIIsubS] (placed at the object's line).
void expand_compact(const Raw& raw, const Section& object, unsigned n, std::deque<Section>& out,
                    std::vector<std::pair<std::uint8_t, const Section*>>& subs) {
  const std::string base = object.name.substr(0, 4);
  std::string upper = base;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const auto list = [&](const char* suffix) -> const Section* {
    const auto it = raw.sections.find(upper + suffix);
    return it == raw.sections.end() ? nullptr : &it->second;
  };
  const Section* names = list("NAME");
  const Section* values = list("VALUE");
  const auto set = [](Section& s, const char* key, std::string text, int line) {
    s.keys[lower(key)] = Value{key, std::move(text), line};
  };
  Section& zero = out.emplace_back();
  zero.name = object.name;
  zero.line = object.line;
  set(zero, "ParameterName", "Number of entries", object.line);
  set(zero, "DataType", "0x0005", object.line);
  set(zero, "AccessType", "ro", object.line);
  set(zero, "DefaultValue", std::to_string(n), object.line);
  subs.emplace_back(0, &zero);
  for (unsigned i = 1; i <= n; ++i) {
    Section& s = out.emplace_back();
    s.name = object.name;
    s.line = object.line;
    for (const char* key : {"DataType", "AccessType", "PDOMapping", "LowLimit", "HighLimit", "DefaultValue"}) {
      if (const Value* v = object.find(key)) set(s, key, v->text, v->line);
    }
    const std::string k = std::to_string(i);
    const Value* name = names != nullptr ? names->find(k) : nullptr;
    const Value* own = object.find("ParameterName");
    set(s, "ParameterName", name != nullptr ? name->text : (own != nullptr ? own->text : base) + " " + k,
        name != nullptr ? name->line : object.line);
    if (const Value* v = values != nullptr ? values->find(k) : nullptr) set(s, "ParameterValue", v->text, v->line);
    subs.emplace_back(static_cast<std::uint8_t>(i), &s);
  }
}

}  // namespace

namespace {

// The file refused: `why` in the result, as its error too. Always false (a stage's failure).
bool refuse(LoadResult& r, Problem why) {
  r.error = to_string(why);
  r.refusal = std::move(why);
  return false;
}

}  // namespace

Builder::Objects Builder::index_objects(const Raw& raw) {
  Objects objects;
  for (const auto& [name, sec] : raw.sections) {
    const auto obj = object_section(name);
    if (!obj || obj->index < 0x1000) continue;  // data type definitions (0x0001..0x025F)
    Sections& o = objects[obj->index];
    if (obj->has_sub) {
      o.subs.emplace_back(obj->sub, &sec);
    } else {
      o.object = &sec;
    }
  }
  return objects;
}

// A VAR at [IIII] is sub 0; an ARRAY or RECORD [IIII] has its subs in [IIIIsubS] (or CompactSubObj,
// expanded into `synthesized`) and defines no value itself (its DataType, if any, names a
// structure; the subs give theirs).
bool Builder::list_items(const Raw& raw, Objects& objects, std::deque<Section>& synthesized, std::vector<Item>& items,
                         LoadResult& r) {
  const auto fail = [&](Problem why) { return refuse(r, std::move(why)); };
  const auto warn = [&](Problem why) { r.warnings.push_back(std::move(why)); };
  std::size_t compact_subs = 0;
  for (auto& [index, o] : objects) {
    std::sort(o.subs.begin(), o.subs.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 1; i < o.subs.size(); ++i) {
      if (o.subs[i].first == o.subs[i - 1].first) {
        return fail(Problem{
            o.subs[i].second->name,
            {},
            "describes " + object_name(index, o.subs[i].first) + " as [" + o.subs[i - 1].second->name + "] does",
            o.subs[i].second->line});
      }
    }
    if (o.object == nullptr) {
      const Section& first = *o.subs.front().second;
      return fail(Problem{first.name, {}, "has no object section [" + first.name.substr(0, 4) + "]", first.line});
    }
    const Section& sec = *o.object;
    std::int64_t type = 0x7;  // CiA 306: a VAR when ObjectType is not given
    if (const Value* ot = sec.find("ObjectType"); ot != nullptr) {
      const auto t = parse_integer(ot->text, 0);
      if (!t) return fail(at(sec, "ObjectType", "'" + ot->text + "' is not a number (0x7 VAR, 0x8 ARRAY, 0x9 RECORD)"));
      type = *t;
    }
    const bool aggregate = type == 0x8 || type == 0x9;
    bool compact_object = false;
    if (const Value* compact = sec.find("CompactSubObj"); compact != nullptr && !compact->text.empty()) {
      const auto n = parse_integer(compact->text, 0);
      if (!n || *n < 0 || *n > 254) {
        return fail(at(sec, "CompactSubObj", hex4(index) + ": '" + compact->text + "' is not a number of sub-objects (0..254)"));
      }
      if (*n > 0) {
        if (!aggregate || !o.subs.empty()) {
          return fail(at(sec, "CompactSubObj",
                         hex4(index) + ": compact sub-objects belong to an ARRAY (ObjectType 0x8) without [" +
                             sec.name.substr(0, 4) + "subS] sections"));
        }
        if (compact_subs + static_cast<std::size_t>(*n) > max_sections) {
          return fail(at(sec, "CompactSubObj", "more than max_sections (" + std::to_string(max_sections) +
                                                   ") sub-objects, the compact ones included"));
        }
        compact_subs += static_cast<std::size_t>(*n) + 1;
        compact_object = true;
        expand_compact(raw, sec, static_cast<unsigned>(*n), synthesized, o.subs);
      }
    }
    if (!aggregate && !o.subs.empty()) {
      return fail(
          at(sec, "ObjectType", "has sub-index sections but is not an ARRAY or RECORD (ObjectType 0x8 or 0x9)"));
    }
    if (!aggregate) {
      items.push_back(Item{index, 0, o.object});
      continue;
    }
    if (o.subs.empty()) {
      warn(at(sec, "ObjectType",
              "an ARRAY or RECORD without [" + sec.name.substr(0, 4) + "subS] sections: " + hex4(index) +
                  " has no entries"));
      continue;
    }
    const std::string present = std::to_string(o.subs.size()) + " sub-index sections";
    if (compact_object) {
      // CompactSubObj states the number itself.
    } else if (const Value* sn = sec.find("SubNumber"); sn == nullptr) {
      warn(at(sec, "SubNumber", "missing: the " + present + " present are read"));
    } else if (const auto stated = parse_integer(sn->text, 0);
               !stated || *stated != static_cast<std::int64_t>(o.subs.size())) {
      warn(at(sec, "SubNumber", "SubNumber " + sn->text + " but " + present + ": the sections present are read"));
    }
    for (const auto& [sub, sub_section] : o.subs) items.push_back(Item{index, sub, sub_section});
  }
  return true;
}

bool Builder::read_entry(const Item& item, Entry& e, LoadResult& r) {
  const auto fail = [&](Problem why) { return refuse(r, std::move(why)); };
  const auto warn = [&](Problem why) { r.warnings.push_back(std::move(why)); };
  const Section& sec = *item.section;
  e.index = item.index;
  e.sub = item.sub;
  const std::string obj = object_name(e.index, e.sub);
  if (const std::string* v = sec.get("parametername")) e.name = *v;
  const Value* dt = sec.find("DataType");
  const auto type = dt ? parse_integer(dt->text, 0) : std::nullopt;
  if (!type || *type <= 0 || *type > 0xFFFF) {
    return fail(at(sec, "DataType", obj + " needs a DataType: a CiA 301 data type index such as 0x0007"));
  }
  e.data_type = static_cast<std::uint16_t>(*type);
  const std::string* acc = sec.get("accesstype");
  const auto access = acc ? parse_access(*acc) : std::nullopt;
  if (!access) return fail(at(sec, "AccessType", obj + ": AccessType must be ro, wo, rw, rwr, rww or const"));
  e.access = *access;
  if (const Value* m = sec.find("PDOMapping"); m != nullptr && !m->text.empty()) {
    const auto mappable = parse_integer(m->text, 0);
    if (!mappable || (*mappable != 0 && *mappable != 1)) {
      return fail(at(sec, "PDOMapping", obj + ": PDOMapping must be 0 or 1 (decimal or hex), not '" + m->text + "'"));
    }
    e.pdo_mappable = *mappable == 1;
  }
  if (const std::string* v = sec.get("defaultvalue")) e.default_value = *v;
  if (const std::string* v = sec.get("parametervalue")) e.parameter_value = *v;
  e.section = sec.name;
  e.line = sec.line;
  if (const Value* v = sec.find(e.parameter_value.empty() ? "DefaultValue" : "ParameterValue")) e.line = v->line;
  const bool integer = data_type_is_integer(e.data_type);
  const bool real = data_type_is_real(e.data_type);

  // The value: checked for every node a $NODEID may stand for.
  for (const char* key : {"DefaultValue", "ParameterValue"}) {
    const std::string& text = key[0] == 'D' ? e.default_value : e.parameter_value;
    if (text.empty()) continue;
    std::string why;
    if (integer) {
      for (const std::uint8_t node : {std::uint8_t{1}, std::uint8_t{127}}) {
        if (why.empty()) why = parse_typed(text, e.data_type, node).why;
      }
    } else if (real) {
      why = parse_real(text, e.data_type).why;
    }
    if (!why.empty()) return fail(at(sec, key, obj + ": " + why));
  }
  if (!read_limits(sec, e, r)) return false;
  // The values within the limits (strict as the limits are).
  const bool strict = e.writable();
  for (const char* key : {"DefaultValue", "ParameterValue"}) {
    const std::string& text = key[0] == 'D' ? e.default_value : e.parameter_value;
    if (text.empty()) continue;
    std::string why;
    if (integer && (e.low_limit || e.high_limit)) {
      for (const std::uint8_t node : {std::uint8_t{1}, std::uint8_t{127}}) {
        const std::int64_t v = *parse_typed(text, e.data_type, node).value;
        if ((e.low_limit && less(v, *e.low_limit, e.data_type)) ||
            (e.high_limit && less(*e.high_limit, v, e.data_type))) {
          why = integer_text(v, e.data_type) + " is outside LowLimit..HighLimit";
        }
      }
    } else if (real && (e.low_limit_real || e.high_limit_real)) {
      const double v = *parse_real(text, e.data_type).value;
      if ((e.low_limit_real && v < *e.low_limit_real) || (e.high_limit_real && v > *e.high_limit_real)) {
        why = "'" + text + "' is outside LowLimit..HighLimit";
      }
    }
    if (why.empty()) continue;
    if (strict) return fail(at(sec, key, obj + ": " + why));
    warn(at(sec, key, obj + ": " + why));
  }
  return true;
}

// Limits: strict for an object the master may write (a wrong limit would let it write what
// the drive does not accept, or refuse what it does); dropped with a warning otherwise.
bool Builder::read_limits(const Section& sec, Entry& e, LoadResult& r) {
  const auto fail = [&](Problem why) { return refuse(r, std::move(why)); };
  const auto warn = [&](Problem why) { r.warnings.push_back(std::move(why)); };
  const std::string obj = object_name(e.index, e.sub);
  const bool integer = data_type_is_integer(e.data_type);
  const bool real = data_type_is_real(e.data_type);
  const bool strict = e.writable();
  const std::string dropped = strict ? "" : " (ignored: the object is not writable)";
  const auto limit_problem = [&](const char* key, const std::string& why) -> bool {
    if (strict) return true;
    warn(at(sec, key, obj + ": " + why + dropped));
    return false;
  };
  for (const char* key : {"LowLimit", "HighLimit"}) {
    const Value* v = sec.find(key);
    if (v == nullptr || v->text.empty()) continue;
    const bool low = key[0] == 'L';
    if (integer) {
      const Integer p = parse_typed(v->text, e.data_type, 0);
      if (!p.value) {
        if (limit_problem(key, p.why)) return fail(at(sec, key, obj + ": " + p.why));
        continue;
      }
      (low ? e.low_limit : e.high_limit) = *p.value;
    } else if (real) {
      const Real p = parse_real(v->text, e.data_type);
      if (!p.value) {
        if (limit_problem(key, p.why)) return fail(at(sec, key, obj + ": " + p.why));
        continue;
      }
      (low ? e.low_limit_real : e.high_limit_real) = *p.value;
    } else if (is_string(e.data_type)) {
      warn(at(sec, key, obj + ": a limit on a string or domain means nothing and is not read"));
    } else if (const auto n = parse_integer(v->text, 0)) {
      (low ? e.low_limit : e.high_limit) = *n;  // a type this reader does not know: as written
    } else {
      warn(at(sec, key,
              obj + ": '" + v->text + "' is not read (" + hex4(e.data_type) + " is not a type this reader knows)"));
    }
  }
  const bool inverted = (e.low_limit && e.high_limit && less(*e.high_limit, *e.low_limit, e.data_type)) ||
                        (e.low_limit_real && e.high_limit_real && *e.high_limit_real < *e.low_limit_real);
  if (inverted) {
    const std::string why = "LowLimit is above HighLimit";
    if (limit_problem("LowLimit", why)) return fail(at(sec, "LowLimit", obj + ": " + why));
    e.low_limit.reset();
    e.high_limit.reset();
    e.low_limit_real.reset();
    e.high_limit_real.reset();
  }
  return true;
}

// The PDO objects, strictly: what the master configures the drive's process data from.
bool Builder::check_pdo_objects(const Objects& objects, const Description& d, LoadResult& r) {
  const auto fail = [&](Problem why) { return refuse(r, std::move(why)); };
  for (const auto& [index, o] : objects) {
    if ((!is_communication(index) && !is_mapping(index)) || !d.has(index)) continue;
    const Section& sec = *o.object;
    const std::uint8_t key_sub = is_communication(index) ? 1 : 0;
    const Entry* key_entry = d.find(index, key_sub);
    const Section* key_sec = o.sub(key_sub);
    if (key_entry == nullptr || key_sec == nullptr) {
      return fail(
          Problem{sec.name,
                  {},
                  hex4(index) + (key_sub == 1 ? " (PDO communication) has no sub-index 1, the COB-ID"
                                              : " (PDO mapping) has no sub-index 0, the number of mapped objects"),
                  sec.line});
    }
    const auto value_key = [](const Entry& e) { return e.parameter_value.empty() ? "DefaultValue" : "ParameterValue"; };
    if (key_sub == 1) {
      if (key_entry->data_type != data_type::u32) {
        return fail(at(*key_sec, "DataType", object_name(index, 1) + ": a COB-ID is UNSIGNED32 (0x0007)"));
      }
      if (!key_entry->value(1))
        return fail(at(*key_sec, "DefaultValue", object_name(index, 1) + ": the COB-ID has no value"));
      for (const std::uint8_t node : {std::uint8_t{1}, std::uint8_t{127}}) {
        const auto cob = static_cast<std::uint32_t>(*key_entry->value(node));
        if ((cob & (1U << 29)) == 0 && (cob & 0x1FFFF800U) != 0) {
          return fail(at(*key_sec, value_key(*key_entry),
                         object_name(index, 1) + ": an 11-bit COB-ID (bit 29 clear) with bits 11..28 set"));
        }
      }
      if (const Entry* tt = d.find(index, 2); tt != nullptr && tt->data_type != data_type::u8) {
        return fail(at(*o.sub(2), "DataType", object_name(index, 2) + ": the transmission type is UNSIGNED8 (0x0005)"));
      }
      continue;
    }
    if (key_entry->data_type != data_type::u8) {
      return fail(
          at(*key_sec, "DataType", object_name(index, 0) + ": the number of mapped objects is UNSIGNED8 (0x0005)"));
    }
    const auto count = key_entry->value(1);
    if (!count)
      return fail(at(*key_sec, "DefaultValue", object_name(index, 0) + ": the number of mapped objects has no value"));
    if (*count > 64) {
      return fail(at(*key_sec, value_key(*key_entry), object_name(index, 0) + ": more than 64 mapped objects"));
    }
    for (std::int64_t i = 1; i <= *count; ++i) {
      const auto sub = static_cast<std::uint8_t>(i);
      const Entry* m = d.find(index, sub);
      const Section* msec = o.sub(sub);
      if (m == nullptr || msec == nullptr) {
        return fail(at(*key_sec, value_key(*key_entry),
                       object_name(index, 0) + " maps " + std::to_string(*count) + " objects but " +
                           object_name(index, sub) + " is not described"));
      }
      const std::string name = object_name(index, sub);
      if (m->data_type != data_type::u32)
        return fail(at(*msec, "DataType", name + ": a mapping entry is UNSIGNED32 (0x0007)"));
      const auto raw1 = m->value(1);
      if (!raw1) return fail(at(*msec, "DefaultValue", name + ": the mapping entry has no value"));
      if (m->value(127) != raw1)
        return fail(at(*msec, value_key(*m), name + ": a mapping entry cannot depend on $NODEID"));
      const auto entry = static_cast<std::uint32_t>(*raw1);
      const unsigned bits = entry & 0xFFU;
      const auto mapped_index = static_cast<std::uint16_t>(entry >> 16U);
      const auto mapped_sub = static_cast<std::uint8_t>(entry >> 8U);
      if (bits == 0 || bits > 64) {
        return fail(
            at(*msec, value_key(*m), name + ": maps " + std::to_string(bits) + " bits (a mapped object has 1..64)"));
      }
      if (const Entry* mapped = d.find(mapped_index, mapped_sub); mapped != nullptr) {
        if (const unsigned size = data_type_bits(mapped->data_type); size != 0 && size != bits) {
          return fail(at(*msec, value_key(*m),
                         name + ": maps " + object_name(mapped_index, mapped_sub) + " with " + std::to_string(bits) +
                             " bits, but it is described with " + std::to_string(size)));
        }
      }
    }
  }
  return true;
}

// The object lists: each entry i=index read as present (in the order of i); a SupportedObjects
// that disagrees with the entries present, an entry that is not an index, and an object listed
// without a section of its own are warnings (nothing is configured from the lists).
void Builder::read_object_lists(const Raw& raw, const Objects& objects, Description& d, LoadResult& r) {
  const auto warn = [&](Problem why) { r.warnings.push_back(std::move(why)); };
  for (const char* list : {"MANDATORYOBJECTS", "OPTIONALOBJECTS", "MANUFACTUREROBJECTS"}) {
    const auto it = raw.sections.find(list);
    if (it == raw.sections.end()) continue;
    const Section& sec = it->second;
    std::vector<std::pair<std::uint64_t, const Value*>> numbered;
    for (const auto& [key, value] : sec.keys) {
      if (const auto n = parse_unsigned(key); n && *n >= 1 && key[0] != '0') numbered.emplace_back(*n, &value);
    }
    std::sort(numbered.begin(), numbered.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    const Value* count_value = sec.find("SupportedObjects");
    const auto count = count_value != nullptr ? parse_integer(count_value->text, 0) : std::nullopt;
    if (!count || *count != static_cast<std::int64_t>(numbered.size())) {
      warn(at(sec, "SupportedObjects",
              (count_value != nullptr ? "SupportedObjects=" + count_value->text : std::string{"missing"}) + " but " +
                  std::to_string(numbered.size()) + " entries: the entries present are read"));
    }
    for (const auto& [n, value] : numbered) {
      const auto index = parse_integer(value->text, 0);
      if (!index || *index < 0 || *index > 0xFFFF) {
        warn(Problem{sec.name, value->key, "'" + value->text + "' is not an object index: the entry is not read",
                     value->line});
        continue;
      }
      const auto i = static_cast<std::uint16_t>(*index);
      if (i >= 0x1000 && !d.has(i) && objects.find(i) == objects.end()) {
        warn(Problem{sec.name, value->key,
                     hex4(i) + " is listed in [" + sec.name + "] but has no section [" + hex4(i).substr(2) +
                         "]: it is not read",
                     value->line});
        continue;
      }
      d.listed_.push_back(i);
    }
  }
}

bool Builder::read_device_info(const Raw& raw, Description& d, LoadResult& r) {
  const auto fail = [&](Problem why) { return refuse(r, std::move(why)); };
  const auto warn = [&](Problem why) { r.warnings.push_back(std::move(why)); };
  if (const auto it = raw.sections.find("DEVICEINFO"); it != raw.sections.end()) {
    const Section& s = it->second;
    // The identity the master checks at start-up is read strictly; the PDO counts and the
    // granularity, which nothing configures from, are taken as 0 with a warning when malformed.
    bool bad = false;
    auto number = [&](const char* key, bool strict) -> std::uint32_t {
      const Value* v = s.find(key);
      if (v == nullptr || v->text.empty()) return 0;
      const auto n = parse_integer(v->text, 0);
      if (n && *n >= 0 && *n <= 0xFFFFFFFF) return static_cast<std::uint32_t>(*n);
      Problem p = at(s, key, "'" + v->text + "' is not an UNSIGNED32");
      if (strict && !bad) {
        bad = true;
        fail(std::move(p));
      } else if (!strict) {
        p.message += ": read as 0";
        warn(std::move(p));
      }
      return 0;
    };
    if (const std::string* v = s.get("vendorname")) d.device_.vendor_name = *v;
    if (const std::string* v = s.get("productname")) d.device_.product_name = *v;
    d.device_.vendor_number = number("VendorNumber", true);
    d.device_.product_number = number("ProductNumber", true);
    d.device_.revision_number = number("RevisionNumber", true);
    d.device_.nr_rx_pdo = number("NrOfRXPDO", false);
    d.device_.nr_tx_pdo = number("NrOfTXPDO", false);
    d.device_.granularity = number("Granularity", false);
    if (bad) return false;
    // The PDO counts against the PDOs described (communication and mapping object both present).
    for (const bool receive : {true, false}) {
      const char* key = receive ? "NrOfRXPDO" : "NrOfTXPDO";
      const Value* v = s.find(key);
      const std::size_t described = (receive ? d.rpdos(1) : d.tpdos(1)).size();
      if (v != nullptr && (receive ? d.device_.nr_rx_pdo : d.device_.nr_tx_pdo) != described) {
        warn(at(s, key, v->text + " but " + std::to_string(described) + (receive ? " RPDOs" : " TPDOs") +
                            " are described: the PDOs described are read"));
      }
    }
  }
  return true;
}

// One identity for the master (which checks it at start-up) and the simulated drive (which
// serves it): 0x1018's value, which is what a drive answers, unless it is absent or 0 (a
// placeholder many files carry), then [DeviceInfo]'s. Where the two contradict, a warning says
// which is used.
void Builder::reconcile_identity(const Raw& raw, Description& d, LoadResult& r) {
  const auto warn = [&](Problem why) { r.warnings.push_back(std::move(why)); };
  {
    const auto info = raw.sections.find("DEVICEINFO");
    const struct {
      const char* key;
      std::uint8_t sub;
      std::uint32_t* field;
    } ids[] = {{"VendorNumber", 1, &d.device_.vendor_number},
               {"ProductNumber", 2, &d.device_.product_number},
               {"RevisionNumber", 3, &d.device_.revision_number}};
    for (const auto& id : ids) {
      const Entry* e = d.find(0x1018, id.sub);
      if (e == nullptr) continue;
      const std::int64_t served = e->value(1).value_or(-1);
      if (served < 0) continue;
      const Value* stated = info != raw.sections.end() ? info->second.find(id.key) : nullptr;
      const bool has_stated = stated != nullptr && !stated->text.empty();
      const auto value = static_cast<std::uint32_t>(served);
      if (has_stated && value != *id.field) {
        char text[160];
        const std::uint32_t used = value != 0 ? value : *id.field;
        std::snprintf(text, sizeof text, "0x%08X but 0x1018:%u gives 0x%08X: 0x%08X (%s) is the identity both the "
                      "master and the simulated drive use",
                      static_cast<unsigned>(*id.field), static_cast<unsigned>(id.sub), static_cast<unsigned>(value),
                      static_cast<unsigned>(used), value != 0 ? "0x1018's" : "[DeviceInfo]'s");
        warn(at(info->second, id.key, text));
      }
      if (value != 0) *id.field = value;
    }
  }
}

// Settle's own section ([SettleDrive] LoadPosition) and a DCF's node id ([DeviceComissioning]).
bool Builder::read_settle_sections(const Raw& raw, Description& d, LoadResult& r) {
  const auto fail = [&](Problem why) { return refuse(r, std::move(why)); };
  if (const auto it = raw.sections.find("SETTLEDRIVE"); it != raw.sections.end()) {
    d.settle_drive_ = true;
    if (const Value* v = it->second.find("LoadPosition"); v != nullptr) {
      const std::size_t colon = v->text.find(':');
      const auto index = colon == std::string::npos ? std::nullopt : parse_integer(v->text.substr(0, colon), 0);
      const auto sub = colon == std::string::npos ? std::nullopt : parse_integer(v->text.substr(colon + 1), 0);
      if (!index || !sub || *index < 0x1000 || *index > 0xFFFF || *sub < 0 || *sub > 0xFF) {
        return fail(at(it->second, "LoadPosition", "'" + v->text + "' is not INDEX:SUB (such as 0x2000:0)"));
      }
      const auto i = static_cast<std::uint16_t>(*index);
      const auto s = static_cast<std::uint8_t>(*sub);
      const Entry* e = d.find(i, s);
      if (e == nullptr || e->data_type != data_type::i32 || !e->readable() || !e->pdo_mappable) {
        return fail(at(it->second, "LoadPosition",
                       object_name(i, s) + " must be described as a readable, mappable INTEGER32"));
      }
      d.load_position_ = MappedObject{i, s, 32};
    }
  }
  if (const auto it = raw.sections.find("DEVICECOMISSIONING"); it != raw.sections.end()) {
    if (const std::string* v = it->second.get("nodeid")) {
      const auto id = parse_integer(*v, 0);
      if (!id || *id < 1 || *id > 127) return fail(at(it->second, "NodeID", "NodeID must be 1..127"));
      d.dcf_node_id_ = static_cast<std::uint8_t>(*id);
    }
  }
  return true;
}

LoadResult Builder::build(const Raw& raw) {
  LoadResult r{};
  Description d{};
  Objects objects = index_objects(raw);
  std::deque<Section> synthesized;  // the sub-objects of CompactSubObj arrays (stable addresses)
  std::vector<Item> items;
  if (!list_items(raw, objects, synthesized, items, r)) return r;
  d.entries_.reserve(items.size());
  for (const Item& item : items) {
    Entry e{};
    if (!read_entry(item, e, r)) return r;
    d.entries_.push_back(std::move(e));
  }
  std::sort(d.entries_.begin(), d.entries_.end(),
            [](const Entry& a, const Entry& b) { return a.index != b.index ? a.index < b.index : a.sub < b.sub; });
  if (!check_pdo_objects(objects, d, r)) return r;
  read_object_lists(raw, objects, d, r);
  if (!d.has(0x1000)) {
    refuse(r, Problem{{}, {}, "0x1000 (device type) is not described: not a CANopen device description", 0});
    return r;
  }
  if (!read_device_info(raw, d, r)) return r;
  reconcile_identity(raw, d, r);
  if (!read_settle_sections(raw, d, r)) return r;
  r.description = std::move(d);
  return r;
}

namespace {

// The first pass: the lines of each kind counted against the bounds, nothing stored. "" or the
// bound the text exceeds.
std::string exceeded_bound(std::string_view text) {
  std::size_t sections = 0;
  std::size_t objects = 0;
  std::size_t keys = 0;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    std::string_view l = text.substr(0, eol);
    text.remove_prefix(eol == std::string_view::npos ? text.size() : eol + 1);
    while (!l.empty() && std::isspace(static_cast<unsigned char>(l.front()))) l.remove_prefix(1);
    if (l.empty() || l.front() == ';' || l.front() == '#') continue;
    if (l.front() == '[') {
      ++sections;
      const std::size_t close = l.find(']');
      if (close == 5 &&
          std::all_of(l.begin() + 1, l.begin() + 5,
                      [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }) &&
          l[1] != '0') {
        ++objects;  // [IIII] with IIII >= 0x1000
      }
    } else if (l.find_first_of("=:") != std::string_view::npos) {
      ++keys;
    }
  }
  const auto over = [](const char* bound, std::size_t value, const char* what) {
    return "more than " + std::string{bound} + " (" + std::to_string(value) + ") " + what;
  };
  if (sections > max_sections) return over("max_sections", max_sections, "sections");
  if (objects > max_objects) return over("max_objects", max_objects, "object sections [IIII]");
  if (keys > max_keys) return over("max_keys", max_keys, "key=value lines");
  return {};
}

LoadResult refused(Problem why) {
  LoadResult r{};
  r.error = to_string(why);
  r.refusal = std::move(why);
  return r;
}

}  // namespace

LoadResult parse(std::string_view text) {
  if (text.size() > max_file_bytes) {
    return refused(Problem{{}, {}, "larger than max_file_bytes (" + std::to_string(max_file_bytes) + " bytes)", 0});
  }
  if (std::string why = exceeded_bound(text); !why.empty()) return refused(Problem{{}, {}, std::move(why), 0});
  Raw raw{};
  if (!tokenize(text, raw)) return refused(std::move(raw.error));
  return Builder::build(raw);
}

LoadResult load(const std::string& path) {
  const auto fail = [&](const std::string& why) { return refused(Problem{{}, {}, path + ": " + why, 0}); };
  std::ifstream in{path, std::ios::binary};
  if (!in) return fail("cannot be opened");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) return fail("cannot be read");
  if (static_cast<std::uint64_t>(size) > max_file_bytes) {
    return fail("larger than max_file_bytes (" + std::to_string(max_file_bytes) + " bytes)");
  }
  in.seekg(0);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), size)) return fail("cannot be read");
  LoadResult r = parse(text);
  if (!r.error.empty()) r.error = path + ": " + r.error;
  return r;
}

}  // namespace settle::hal::eds
