// EDS/DCF reading: the file split into sections and keys (tokenize, below: lines of any length
// read whole), then CiA 306's meaning (object sections [IIII] and [IIIIsubS], the object lists, DeviceInfo, a DCF's
// ParameterValue and NodeID) and checks what a master relies on.
#include "settle/hal/eds_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
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
};

struct Raw {
  std::map<std::string, Section> sections;  // upper-case section name
  std::string error;
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
  const auto refuse = [&](std::string why) {
    raw.error = "line " + std::to_string(line) + ": " + std::move(why);
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
      if (close == std::string::npos) return refuse("a section header without ']'");
      const std::string after = trim(std::string_view{t}.substr(close + 1));
      if (!after.empty() && after[0] != ';' && after[0] != '#') return refuse("text after the section header");
      std::string name = trim(std::string_view{t}.substr(1, close - 1));
      if (name.empty()) return refuse("a section without a name");
      std::string upper = name;
      for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      const auto [it, fresh] = raw.sections.try_emplace(std::move(upper));
      if (!fresh) {
        return refuse("[" + name + "] is given twice (first on line " + std::to_string(it->second.line) + ")");
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
    if (current == nullptr) return refuse(key + " is given before any [section]");
    std::string_view value = std::string_view{t}.substr(eq + 1);
    for (std::size_t i = 1; i < value.size(); ++i) {
      if (value[i] == ';' && std::isspace(static_cast<unsigned char>(value[i - 1]))) {
        value = value.substr(0, i);
        break;
      }
    }
    const auto [it, fresh] = current->keys.try_emplace(lower(key));
    if (!fresh) {
      return refuse("[" + current->name + "] gives " + key + " twice (first on line " +
                    std::to_string(it->second.line) + ")");
    }
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

struct Builder {
  static LoadResult build(const Raw& raw);
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

std::optional<std::int64_t> parse_integer(std::string_view text, std::uint8_t node) {
  std::string t = trim(text);
  std::int64_t base = 0;
  const std::string l = lower(t);
  const std::string tag = "$nodeid";
  if (const auto at = l.find(tag); at != std::string::npos) {
    base = node;
    std::string rest = t.substr(0, at) + t.substr(at + tag.size());
    rest = trim(rest);
    // $NODEID+v or v+$NODEID: strip the one '+' that joined them.
    if (!rest.empty() && rest.front() == '+') {
      rest = trim(rest.substr(1));
    } else if (!rest.empty() && rest.back() == '+') {
      rest = trim(rest.substr(0, rest.size() - 1));
    } else if (!rest.empty()) {
      return std::nullopt;
    }
    if (rest.empty()) return base;
    t = rest;
  }
  bool negative = false;
  if (!t.empty() && (t[0] == '-' || t[0] == '+')) {
    negative = t[0] == '-';
    t.erase(0, 1);
  }
  const auto v = parse_unsigned(t);
  if (!v) return std::nullopt;
  // 64-bit objects aside, every value fits an int64 with room for the node id.
  if (*v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) - 0x80) return std::nullopt;
  const auto magnitude = static_cast<std::int64_t>(*v);
  return base + (negative ? -magnitude : magnitude);
}

std::optional<std::int64_t> Entry::value(std::uint8_t node) const {
  if (!data_type_is_integer(data_type)) return std::nullopt;
  const std::string& text = parameter_value.empty() ? default_value : parameter_value;
  if (text.empty()) return std::nullopt;
  return parse_integer(text, node);
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

LoadResult Builder::build(const Raw& raw) {
  LoadResult r{};
  Description d{};
  auto fail = [&](std::string message) {
    r.error = std::move(message);
    return r;
  };
  // Object sections, indexed once: each object's [IIII] and its [IIIIsubS] by sub-index (the
  // file's sections are visited once; every look-up after is by index).
  struct Sections {
    const Section* object{nullptr};  // [IIII], when the file has it
    std::vector<std::pair<std::uint8_t, const Section*>> subs;
  };
  std::map<std::uint16_t, Sections> objects;
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
  // A VAR at [IIII] is sub 0; an ARRAY or RECORD [IIII] has its subs in [IIIIsubS] and defines
  // no value itself.
  struct Item {
    std::uint16_t index;
    std::uint8_t sub;
    const Section* section;
  };
  std::vector<Item> items;
  for (auto& [index, o] : objects) {
    std::sort(o.subs.begin(), o.subs.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 1; i < o.subs.size(); ++i) {
      if (o.subs[i].first == o.subs[i - 1].first) {
        return fail("[" + o.subs[i].second->name + "] and [" + o.subs[i - 1].second->name +
                    "] describe the same sub-index " + object_name(index, o.subs[i].first));
      }
    }
    if (o.object == nullptr) {
      const std::string& sub_name = o.subs.front().second->name;
      return fail("[" + sub_name + "] has no object section [" + sub_name.substr(0, 4) + "]");
    }
    if (o.subs.empty()) {
      items.push_back(Item{index, 0, o.object});
      continue;
    }
    const Section& sec = *o.object;
    const std::string* ot = sec.get("objecttype");
    const auto type = ot ? parse_integer(*ot, 0) : std::nullopt;
    if (!type || (*type != 0x8 && *type != 0x9)) {
      return fail("[" + sec.name + "] has sub-index sections but is not an ARRAY or RECORD (ObjectType 0x8 or 0x9)");
    }
    const std::string* sn = sec.get("subnumber");
    const auto stated = sn ? parse_integer(*sn, 0) : std::nullopt;
    const auto described = static_cast<std::int64_t>(o.subs.size());
    if (!stated || *stated != described) {
      return fail("[" + sec.name + "] SubNumber " + (sn ? *sn : std::string{"(missing)"}) + " but " +
                  std::to_string(described) + " sub-index sections");
    }
    for (const auto& [sub, sub_section] : o.subs) items.push_back(Item{index, sub, sub_section});
  }
  d.entries_.reserve(items.size());
  for (const Item& item : items) {
    const Section& sec = *item.section;
    Entry e{};
    e.index = item.index;
    e.sub = item.sub;
    const std::string where = "[" + sec.name + "] (" + object_name(e.index, e.sub) + ")";
    if (const std::string* v = sec.get("parametername")) e.name = *v;
    const std::string* dt = sec.get("datatype");
    const auto type = dt ? parse_integer(*dt, 0) : std::nullopt;
    if (!type || *type <= 0 || *type > 0xFFFF) return fail(where + ": no valid DataType");
    e.data_type = static_cast<std::uint16_t>(*type);
    const std::string* acc = sec.get("accesstype");
    const auto access = acc ? parse_access(*acc) : std::nullopt;
    if (!access) return fail(where + ": AccessType must be ro, wo, rw, rwr, rww or const");
    e.access = *access;
    if (const std::string* m = sec.get("pdomapping")) {
      if (*m != "0" && *m != "1") return fail(where + ": PDOMapping must be 0 or 1");
      e.pdo_mappable = *m == "1";
    }
    if (const std::string* v = sec.get("defaultvalue")) e.default_value = *v;
    if (const std::string* v = sec.get("parametervalue")) e.parameter_value = *v;
    for (const auto& [key, v] : sec.keys) {
      if (key == "lowlimit" || key == "highlimit") {
        if (v.text.empty()) continue;
        const auto limit = parse_integer(v.text, 0);
        if (!limit) return fail(where + ": " + key + " is not a number");
        (key == "lowlimit" ? e.low_limit : e.high_limit) = *limit;
      }
    }
    if (data_type_is_integer(e.data_type)) {
      for (const std::string* text : {&e.default_value, &e.parameter_value}) {
        if (!text->empty() && !parse_integer(*text, 1)) {
          return fail(where + ": value '" + *text + "' is not an integer");
        }
      }
    }
    d.entries_.push_back(std::move(e));
  }
  std::sort(d.entries_.begin(), d.entries_.end(),
            [](const Entry& a, const Entry& b) { return a.index != b.index ? a.index < b.index : a.sub < b.sub; });

  // Every object the lists name is described.
  for (const char* list : {"MANDATORYOBJECTS", "OPTIONALOBJECTS", "MANUFACTUREROBJECTS"}) {
    const auto it = raw.sections.find(list);
    if (it == raw.sections.end()) continue;
    const std::string* count_text = it->second.get("supportedobjects");
    const auto count = count_text ? parse_integer(*count_text, 0) : std::nullopt;
    if (!count || *count < 0 || *count > static_cast<std::int64_t>(max_objects)) {
      return fail(std::string{"["} + list + "]: no valid SupportedObjects");
    }
    for (std::int64_t i = 1; i <= *count; ++i) {
      const std::string* item = it->second.get(std::to_string(i).c_str());
      const auto index = item ? parse_integer(*item, 0) : std::nullopt;
      if (!index || *index < 0 || *index > 0xFFFF) {
        return fail(std::string{"["} + list + "]: entry " + std::to_string(i) + " is missing or not an index");
      }
      if (*index >= 0x1000 && !d.has(static_cast<std::uint16_t>(*index))) {
        return fail(hex4(static_cast<std::uint16_t>(*index)) + " is listed in [" + list + "] but not described");
      }
      d.listed_.push_back(static_cast<std::uint16_t>(*index));
    }
  }
  if (!d.has(0x1000)) return fail("0x1000 (device type) is not described: not a CANopen device description");

  if (const auto it = raw.sections.find("DEVICEINFO"); it != raw.sections.end()) {
    const Section& s = it->second;
    auto number = [&](const char* key) -> std::uint32_t {
      const std::string* v = s.get(key);
      const auto n = v ? parse_integer(*v, 0) : std::nullopt;
      return n && *n >= 0 && *n <= 0xFFFFFFFF ? static_cast<std::uint32_t>(*n) : 0u;
    };
    if (const std::string* v = s.get("vendorname")) d.device_.vendor_name = *v;
    if (const std::string* v = s.get("productname")) d.device_.product_name = *v;
    d.device_.vendor_number = number("vendornumber");
    d.device_.product_number = number("productnumber");
    d.device_.revision_number = number("revisionnumber");
    d.device_.nr_rx_pdo = number("nrofrxpdo");
    d.device_.nr_tx_pdo = number("nroftxpdo");
    d.device_.granularity = number("granularity");
  }
  if (const auto it = raw.sections.find("DEVICECOMISSIONING"); it != raw.sections.end()) {
    if (const std::string* v = it->second.get("nodeid")) {
      const auto id = parse_integer(*v, 0);
      if (!id || *id < 1 || *id > 127) return fail("[DeviceComissioning] NodeID must be 1..127");
      d.dcf_node_id_ = static_cast<std::uint8_t>(*id);
    }
  }
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
      if (close == 5 && std::all_of(l.begin() + 1, l.begin() + 5, [](char c) {
            return std::isxdigit(static_cast<unsigned char>(c)) != 0;
          }) && l[1] != '0') {
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

}  // namespace

LoadResult parse(std::string_view text) {
  if (text.size() > max_file_bytes) {
    return LoadResult{std::nullopt, "larger than max_file_bytes (" + std::to_string(max_file_bytes) + " bytes)"};
  }
  if (std::string why = exceeded_bound(text); !why.empty()) return LoadResult{std::nullopt, std::move(why)};
  Raw raw{};
  if (!tokenize(text, raw)) return LoadResult{std::nullopt, raw.error};
  return Builder::build(raw);
}

LoadResult load(const std::string& path) {
  std::ifstream in{path, std::ios::binary};
  if (!in) return LoadResult{std::nullopt, path + ": cannot be opened"};
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) return LoadResult{std::nullopt, path + ": cannot be read"};
  if (static_cast<std::uint64_t>(size) > max_file_bytes) {
    return LoadResult{std::nullopt,
                      path + ": larger than max_file_bytes (" + std::to_string(max_file_bytes) + " bytes)"};
  }
  in.seekg(0);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), size)) return LoadResult{std::nullopt, path + ": cannot be read"};
  LoadResult r = parse(text);
  if (!r.error.empty()) r.error = path + ": " + r.error;
  return r;
}

}  // namespace settle::hal::eds
