// SPDX-License-Identifier: Apache-2.0
// settle drive info|read|write|scan: a CANopen drive's dictionary over SDO (hal's SdoClient,
// expedited and segmented), on a SocketCAN interface or on the simulated drive in this process
// (--bus loopback, drive_link.hpp). settle drive nmt start|stop|preop|reset|reset-comm: one CiA
// 301 NMT command to one node (hal's encode_nmt), confirmed by the node's heartbeat or boot-up.
// `settle drive config` (configure and verify what streaming needs) is the master's start-up and
// is not part of this build. --eds FILE (on a bus) gives read and write their --type and names
// the mapped objects in info; with --bus loopback the simulated drive is the one it describes
// (testbed::build_simulated_drive).
//
// Exit status (commands.hpp): 0 done; 2 a bad request, before anything is sent; 1 the bus cannot
// be opened, the drive does not answer within --timeout-ms, or it aborts a transfer (the CiA 301
// code and its meaning are printed), or a written value reads back different, or (nmt) the node's
// heartbeats carry another state than the command leads to (none at all: exit 0, not confirmed).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "commands.hpp"
#include "drive_link.hpp"
#include "drive_nmt.hpp"
#include "eds_option.hpp"
#include "io/json.hpp"
#include "options.hpp"
#include "progress.hpp"
#include "settle/hal/canopen/sdo_abort.hpp"
#include "settle/hal/canopen/standard_objects.hpp"
#include "settle/hal/eds_reader.hpp"
#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/hal/eds_drive_config.hpp"
#include "settle/testbed/simulated_drive.hpp"
#include "settle/testbed/stream.hpp"

namespace settle::app {

namespace {

using hal::canopen::SdoAbort;
using hal::canopen::SdoClient;
using hal::canopen::SdoClientStatus;
using hal::canopen::SdoResult;

constexpr std::string_view kSubcommands[] = {"info", "read", "write", "config", "scan", "nmt"};
// Scan: nodes asked at once, each batch waiting at most --timeout-ms (documented in options.cpp).
constexpr hal::canopen::NodeId kScanBatch = 16;
// The longest object read: a string (segmented upload) longer than this is aborted 0x06070012.
constexpr std::size_t kMaxObjectBytes = 4096;
// CiA 301: a PDO mapping object has at most 64 entries (sub 0 = 0x40).
constexpr unsigned kMaxMappingEntries = 64;

struct ValueType {
  std::string_view name;
  unsigned bytes;  // 0: a string, any length
  bool is_signed;
};
constexpr ValueType kTypes[] = {{"u8", 1, false},  {"u16", 2, false}, {"u32", 4, false}, {"i8", 1, true},
                                {"i16", 2, true},  {"i32", 4, true},  {"string", 0, false}};

const ValueType& value_type(const std::string& name) {
  for (const ValueType& t : kTypes) {
    if (t.name == name) return t;
  }
  return kTypes[std::size(kTypes) - 1];  // unreachable: --type is a choice of these names
}

std::string hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, static_cast<unsigned>(v));
  return buf;
}

std::string object_name(std::uint16_t index, std::uint8_t sub) { return hex(index, 4) + ":" + std::to_string(sub); }

// One object's upload: its bytes, or why not.
struct Read {
  SdoResult result{};
  std::vector<std::uint8_t> bytes;

  [[nodiscard]] bool ok() const { return result.status == SdoClientStatus::done; }
  [[nodiscard]] bool timed_out() const { return result.status == SdoClientStatus::timed_out; }
  // Objects the drive does not have are absent, not errors.
  [[nodiscard]] bool absent() const {
    return result.status == SdoClientStatus::aborted &&
           (result.abort_raw == static_cast<std::uint32_t>(SdoAbort::no_object) ||
            result.abort_raw == static_cast<std::uint32_t>(SdoAbort::no_sub_index));
  }
  // The bytes as a little-endian unsigned integer (at most the first four).
  [[nodiscard]] std::uint32_t unsigned_value() const {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < bytes.size() && i < 4; ++i) v |= std::uint32_t{bytes[i]} << (8 * i);
    return v;
  }
  [[nodiscard]] std::string text() const { return {bytes.begin(), bytes.end()}; }
};

std::string abort_text(const SdoResult& r) {
  if (r.status == SdoClientStatus::timed_out) return "no answer (SDO timeout)";
  return "SDO abort " + hex(r.abort_raw, 8) + " (" + hal::canopen::abort_meaning(r.abort_raw) + ")";
}

// A string as text prints it: bytes outside printable ASCII as \xNN.
std::string printable(const std::string& s) {
  std::string out;
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7F && c != '\\') {
      out += c;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", u);
      out += buf;
    }
  }
  return out;
}

// Whether the bytes are UTF-8 text (JSON holds only text).
bool valid_utf8(const std::vector<std::uint8_t>& b) {
  for (std::size_t i = 0; i < b.size();) {
    const std::uint8_t c = b[i];
    const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (n == 0 || i + n > b.size()) return false;
    std::uint32_t cp = n == 1 ? c : c & (0x7FU >> n);
    for (std::size_t k = 1; k < n; ++k) {
      if ((b[i + k] & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (b[i + k] & 0x3FU);
    }
    // Overlong forms, surrogates and code points beyond U+10FFFF are not UTF-8.
    const std::uint32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < least[n] || (cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF) return false;
    i += n;
  }
  return true;
}

std::string hex_bytes(const std::vector<std::uint8_t>& b) {
  std::string out;
  for (const std::uint8_t c : b) {
    char two[3];
    std::snprintf(two, sizeof two, "%02X", static_cast<unsigned>(c));
    out += two;
  }
  return out;
}

// The link, the client and the output of one subcommand.
class Session {
 public:
  Session(const ParsedArgs& args, std::string command, const hal::eds::Description* eds)
      : command_{std::move(command)},
        eds_{eds},
        bus_name_{args.text_or_default("--bus")},
        node_{static_cast<hal::canopen::NodeId>(args.has("--node") ? args.integer("--node") : 1)},  // 1..127; scan has no --node
        timeout_us_{static_cast<std::uint32_t>(args.integer("--timeout-ms")) * 1000U},  // 1..60000 ms
        json_{args.json()},
        client_{node_, timeout_us_} {}

  // Exit status when the bus cannot be opened, or -1.
  int open(const hal::CanFilter& accept = kSdoAnswers) {
    std::string error;
    link_ = open_drive_link(bus_name_, node_, eds_, socketcan_, error, accept);
    if (!link_) return failed("bus", error);
    return -1;
  }

  [[nodiscard]] Read read(std::uint16_t index, std::uint8_t sub) {
    Read r;
    r.bytes.resize(kMaxObjectBytes);
    r.result = transfer(*link_, client_, [&](std::uint64_t now, hal::FrameSink& out) {
      return client_.upload_bytes(index, sub, r.bytes, now, out);
    });
    r.bytes.resize(r.ok() ? std::min<std::size_t>(r.result.length, kMaxObjectBytes) : 0);
    return r;
  }

  [[nodiscard]] SdoResult write_integer(std::uint16_t index, std::uint8_t sub, std::uint32_t raw, unsigned bytes) {
    return transfer(*link_, client_, [&](std::uint64_t now, hal::FrameSink& out) {
      return client_.download(index, sub, raw, static_cast<std::uint8_t>(bytes), now, out);
    });
  }
  [[nodiscard]] SdoResult write_bytes(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data) {
    return transfer(*link_, client_, [&](std::uint64_t now, hal::FrameSink& out) {
      return client_.download_bytes(index, sub, data, now, out);
    });
  }

  // A runtime failure: one line on stderr, or with --json the error object on stdout. Exit 1.
  int failed(const std::string& code, const std::string& message, const Json& detail = Json::object()) const {
    return drive_failure(command_, code, message, detail, json_, stdout, stderr);
  }
  // A transfer on object index:sub that did not end in done.
  int transfer_failed(const SdoResult& r) const {
    const std::string where = "node " + std::to_string(node_) + ", " + object_name(r.index, r.sub) + ": ";
    if (r.status == SdoClientStatus::timed_out) {
      return failed("sdo_timeout", where + "no answer within " + std::to_string(timeout_us_ / 1000) +
                                       " ms (SDO timeout; is the drive on " + bus_name_ + " as node " +
                                       std::to_string(node_) + "?)");
    }
    return failed("sdo_abort", where + abort_text(r),
                  {{"abort_code", hex(r.abort_raw, 8)}, {"meaning", hal::canopen::abort_meaning(r.abort_raw)}});
  }

  [[nodiscard]] testbed::ClockedBus& link() { return *link_; }
  [[nodiscard]] bool json() const { return json_; }
  [[nodiscard]] hal::canopen::NodeId node() const { return node_; }
  [[nodiscard]] std::uint32_t timeout_us() const { return timeout_us_; }
  [[nodiscard]] const std::string& bus_name() const { return bus_name_; }

 private:
  std::string command_;
  const hal::eds::Description* eds_;
  std::string bus_name_;
  hal::canopen::NodeId node_;
  std::uint32_t timeout_us_;
  bool json_;
  hal::SocketCanBus socketcan_;  // the interface --bus names (outlives link_)
  std::unique_ptr<testbed::ClockedBus> link_;
  SdoClient client_;
};

// `settle drive --help`: the subcommands, from the option table.
std::string drive_help() {
  std::string h = "usage: settle drive info|read|write|config|scan|nmt [options]\n\nsubcommands:\n";
  for (const CommandSpec& c : commands()) {
    if (c.name.rfind("drive ", 0) != 0) continue;
    char line[256];
    std::snprintf(line, sizeof line, "  %-6s %s\n", c.name.substr(6).c_str(), c.summary.c_str());
    h += line;
  }
  h += "\nrun 'settle drive <subcommand> --help' for its options.\n";
  return h;
}

// --eds FILE: the drive's description, read before anything is sent (eds_option.hpp), for the
// node the subcommand talks to (scan: any). Exit status or -1.
int load_description(const std::string& sub, const ParsedArgs& args, EdsOption& out) {
  std::vector<std::uint8_t> nodes;
  if (sub != "scan") nodes.push_back(static_cast<std::uint8_t>(args.integer("--node")));  // 1..127
  if (const int rc = load_eds_option(args, "drive " + sub, nodes, out); rc >= 0) return rc;
  if (out.description && args.text_or_default("--bus") == "loopback") {
    // The simulated drive is built from it: one it cannot be is a bad request too.
    testbed::SimulatedDriveSpec spec{};
    spec.eds = out.description.get();
    const testbed::DriveFromEds d = testbed::simulated_drive_config(spec);
    if (!d.config) return report_bad_request({"bad_eds", "--eds", "--eds: " + d.error}, args.json());
  }
  return -1;
}

// The warnings about the description, as JSON (drive info and config report them).
Json warnings_json(const std::vector<hal::eds::Problem>& warnings) {
  Json list = Json::array();
  for (const hal::eds::Problem& w : warnings) {
    list.push_back({{"section", w.section}, {"key", w.key}, {"line", w.line}, {"message", w.message},
                    {"text", hal::eds::to_string(w)}});
  }
  return list;
}

// What --type an object's EDS data type reads as; "" for a type settle drive does not read.
std::string type_name_of(std::uint16_t data_type) {
  namespace t = hal::eds::data_type;
  switch (data_type) {
    case t::u8: return "u8";
    case t::u16: return "u16";
    case t::u32: return "u32";
    case t::i8: return "i8";
    case t::i16: return "i16";
    case t::i32: return "i32";
    case t::visible_string:
    case t::octet_string:
    case t::domain: return "string";
    default: return "";
  }
}

// ---- info ----------------------------------------------------------------------------------

// An integer field of info: its value, null when the drive does not have the object, and the
// reason in `errors` when the drive refused for another reason.
struct Field {
  std::optional<std::uint32_t> value;
  std::string problem;  // "" ok or absent
};

class InfoReader {
 public:
  explicit InfoReader(Session& s) : s_{s} {}

  // nullopt, and the exit status in `failed_status`, when the drive stopped answering.
  std::optional<Read> get(std::uint16_t index, std::uint8_t sub) {
    Read r = s_.read(index, sub);
    if (r.timed_out()) {
      failed_status = s_.transfer_failed(r.result);
      return std::nullopt;
    }
    if (!r.ok() && !r.absent()) {
      errors.push_back({{"object", object_name(index, sub)},
                        {"abort_code", hex(r.result.abort_raw, 8)},
                        {"meaning", hal::canopen::abort_meaning(r.result.abort_raw)}});
    }
    return r;
  }

  int failed_status{-1};
  Json errors = Json::array();

 private:
  Session& s_;
};

Json field_json(const Read& r) { return r.ok() ? Json(r.unsigned_value()) : Json(nullptr); }
// A string object in JSON: its text, or {"hex": ...} when its bytes are not UTF-8.
Json bytes_json(const std::vector<std::uint8_t>& b) {
  return valid_utf8(b) ? Json(std::string(b.begin(), b.end())) : Json{{"hex", hex_bytes(b)}};
}
Json string_json(const Read& r) { return r.ok() ? bytes_json(r.bytes) : Json(nullptr); }
std::string field_text(const Read& r) {
  if (r.ok()) return hex(r.unsigned_value(), 8);
  return r.absent() ? "absent" : abort_text(r.result);
}
std::string string_text(const Read& r) {
  if (r.ok()) return "\"" + printable(r.text()) + "\"";
  return r.absent() ? "absent" : abort_text(r.result);
}

// One PDO's communication and mapping objects; nullopt when the drive stopped answering.
// With a description, each mapped object is named as the EDS names it.
std::optional<Json> read_pdo(InfoReader& reader, const hal::eds::Description* eds, bool receive, unsigned number,
                             std::string& text) {
  const auto comm = static_cast<std::uint16_t>((receive ? 0x1400 : 0x1800) + number - 1);
  const auto map = static_cast<std::uint16_t>((receive ? 0x1600 : 0x1A00) + number - 1);
  const std::string label = std::string{receive ? "RPDO" : "TPDO"} + std::to_string(number);
  Json j{{"number", number}, {"communication_index", comm}, {"mapping_index", map}};
  const auto cob = reader.get(comm, 1);
  if (!cob) return std::nullopt;
  if (cob->absent()) {
    j["present"] = false;
    text += label + "  absent (" + hex(comm, 4) + ")\n";
    return j;
  }
  j["present"] = true;
  const auto type = reader.get(comm, 2);
  if (!type) return std::nullopt;
  j["cob_id"] = field_json(*cob);
  j["enabled"] = cob->ok() ? Json((cob->unsigned_value() & 0x8000'0000U) == 0) : Json(nullptr);
  j["transmission_type"] = field_json(*type);
  text += label + "  COB-ID " + field_text(*cob);
  if (cob->ok()) text += (cob->unsigned_value() & 0x8000'0000U) != 0 ? " (disabled)" : " (enabled)";
  text += ", transmission type " + (type->ok() ? std::to_string(type->unsigned_value()) : field_text(*type));
  const auto count = reader.get(map, 0);
  if (!count) return std::nullopt;
  if (!count->ok()) {
    j["mapping"] = nullptr;
    text += ", mapping " + field_text(*count) + "\n";
    return j;
  }
  Json entries = Json::array();
  text += ", mapping:";
  const unsigned n = std::min(count->unsigned_value(), kMaxMappingEntries);
  for (unsigned sub = 1; sub <= n; ++sub) {
    const auto e = reader.get(map, static_cast<std::uint8_t>(sub));
    if (!e) return std::nullopt;
    if (!e->ok()) {
      entries.push_back(nullptr);
      text += " " + field_text(*e);
      continue;
    }
    const std::uint32_t raw = e->unsigned_value();
    const auto index = static_cast<std::uint16_t>(raw >> 16);
    const auto osub = static_cast<std::uint8_t>((raw >> 8) & 0xFF);
    const auto bits = static_cast<unsigned>(raw & 0xFF);
    Json entry{{"index", index}, {"sub", osub}, {"bits", bits}};
    text += " " + object_name(index, osub) + "/" + std::to_string(bits);
    if (const hal::eds::Entry* described = eds != nullptr ? eds->find(index, osub) : nullptr) {
      entry["name"] = described->name;
      text += " (" + described->name + ")";
    }
    entries.push_back(entry);
  }
  if (n == 0) text += " none";
  j["mapping"] = entries;
  text += "\n";
  return j;
}

int drive_info(const ParsedArgs& args, const hal::eds::Description* eds,
               const std::vector<hal::eds::Problem>& eds_warnings) {
  Session s{args, "info", eds};
  if (const int rc = s.open(); rc >= 0) return rc;
  InfoReader reader{s};
  // 0x1000 first: a drive that does not answer it is not there.
  const Read device_type = s.read(0x1000, 0);
  if (!device_type.ok()) return s.transfer_failed(device_type.result);
  struct Named {
    const char* key;
    const char* label;
    std::uint16_t index;
    std::uint8_t sub;
    bool is_string;
  };
  constexpr Named kIdentity[] = {
      {"vendor_id", "vendor id", 0x1018, 1, false},         {"product_code", "product code", 0x1018, 2, false},
      {"revision", "revision", 0x1018, 3, false},           {"serial", "serial number", 0x1018, 4, false},
      {"device_name", "device name", 0x1008, 0, true},      {"hardware_version", "hardware version", 0x1009, 0, true},
      {"software_version", "software version", 0x100A, 0, true},
  };
  const std::uint32_t dt = device_type.unsigned_value();
  Json j{{"status", "ok"}, {"bus", s.bus_name()}, {"node", s.node()}, {"device_type", dt},
         {"profile", dt & 0xFFFFU}};
  std::string text = "node " + std::to_string(s.node()) + " on " + s.bus_name() + "\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-18s %s (profile %u, additional information 0x%04X)\n", "device type",
                hex(dt, 8).c_str(), static_cast<unsigned>(dt & 0xFFFFU), static_cast<unsigned>(dt >> 16));
  text += line;
  Json identity = Json::object();
  for (const Named& n : kIdentity) {
    const auto r = reader.get(n.index, n.sub);
    if (!r) return reader.failed_status;
    const std::string shown = n.is_string ? string_text(*r) : field_text(*r);
    std::snprintf(line, sizeof line, "%-18s ", n.label);
    text += line + shown + "\n";
    if (n.is_string) {
      j[n.key] = string_json(*r);
    } else {
      identity[n.key] = field_json(*r);
    }
  }
  j["identity"] = identity;
  for (const bool receive : {true, false}) {
    Json pdos = Json::array();
    for (unsigned number = 1; number <= 4; ++number) {
      const auto pdo = read_pdo(reader, eds, receive, number, text);
      if (!pdo) return reader.failed_status;
      pdos.push_back(*pdo);
    }
    j[receive ? "rpdos" : "tpdos"] = pdos;
  }
  j["errors"] = reader.errors;
  if (eds != nullptr) j["eds_warnings"] = warnings_json(eds_warnings);
  if (eds != nullptr) text += std::to_string(eds_warnings.size()) + " EDS warning(s) (on stderr)\n";
  if (s.json()) {
    print_json(j);
  } else {
    std::fputs(text.c_str(), stdout);
  }
  return kExitOk;
}

// ---- read, write ---------------------------------------------------------------------------

struct Object {
  std::uint16_t index{0};
  std::uint8_t sub{0};
  const ValueType* type{nullptr};
};

// --index, --sub and --type, the type from the EDS when --type is not given. Exit status or -1.
int object_of(const ParsedArgs& args, const hal::eds::Description* eds, Object& o) {
  if (!args.has("--index")) return report_bad_request({"missing_option", "--index", "--index: required"}, args.json());
  o.index = static_cast<std::uint16_t>(args.integer("--index", 0));  // 1..0xFFFF
  o.sub = static_cast<std::uint8_t>(args.integer("--sub"));  // 0..255
  std::string type = args.text("--type", "");
  // The type the object has, where the EDS or the standard says: SDO carries bytes only, so a
  // --type of another size or kind would be written (a 4-character string fits an UNSIGNED32).
  std::string known;
  std::string source;
  if (const hal::eds::Entry* e = eds != nullptr ? eds->find(o.index, o.sub) : nullptr) {
    known = type_name_of(e->data_type);
    source = "the EDS gives it the data type " + hex(e->data_type, 4);
  } else if (const auto* std_object = hal::canopen::find_standard_object(o.index, o.sub)) {
    known = type_name_of(static_cast<std::uint16_t>(std_object->type));
    source = std::string{std_object->profile} + " makes it " + hal::canopen::data_type_name(static_cast<std::uint16_t>(std_object->type), "") + " (" +
             std_object->name + ")";
  }
  if (!type.empty() && !known.empty() && type != known) {
    return report_bad_request({"type_mismatch", "--type",
                               "--type: " + type + " is not the type of " + object_name(o.index, o.sub) + ": " +
                                   source + "; give --type " + known + " (or leave --type out)"},
                              args.json());
  }
  if (type.empty()) type = known;
  if (type.empty()) {
    const std::string why = eds != nullptr ? " (the EDS gives no type settle drive reads for " +
                                                 object_name(o.index, o.sub) + ")"
                                           : "";
    return report_bad_request({"missing_option", "--type", "--type: required" + why}, args.json());
  }
  o.type = &value_type(type);
  return -1;
}

// The value an integer object's bytes hold, as its type reads them.
long long integer_value(const Read& r, const ValueType& t) {
  const std::uint32_t u = r.unsigned_value();
  if (!t.is_signed) return u;
  const unsigned bits = 8 * t.bytes;
  const std::uint32_t sign = 1U << (bits - 1);
  const std::uint32_t mask = bits == 32 ? 0xFFFF'FFFFU : (1U << bits) - 1;
  const std::uint32_t v = u & mask;
  return (v & sign) != 0 ? static_cast<long long>(v) - (1LL << bits) : static_cast<long long>(v);
}

// The object's value as read, checked against --type. Exit status or -1 with `value` set.
int typed_value(Session& s, const Object& o, const Read& r, Json& value, std::string& shown) {
  if (o.type->bytes == 0) {
    // JSON holds text only: bytes that are not UTF-8 (a domain, an octet string) go as hex.
    value = bytes_json(r.bytes);
    shown = "\"" + printable(r.text()) + "\"";
    return -1;
  }
  if (r.bytes.size() != o.type->bytes) {
    return s.failed("type_mismatch", "node " + std::to_string(s.node()) + ", " + object_name(o.index, o.sub) +
                                         " holds " + std::to_string(r.bytes.size()) + " bytes; --type " +
                                         std::string{o.type->name} + " reads " + std::to_string(o.type->bytes));
  }
  const long long v = integer_value(r, *o.type);
  value = v;
  shown = std::to_string(v) + " (" + hex(r.unsigned_value(), static_cast<int>(2 * o.type->bytes)) + ")";
  return -1;
}

void print_value(const Session& s, const Object& o, const Json& value, const std::string& shown, const char* key) {
  if (s.json()) {
    print_json({{"status", "ok"}, {"node", s.node()}, {"index", o.index}, {"sub", o.sub},
                {"type", std::string{o.type->name}}, {key, value}});
  } else {
    std::printf("%s = %s\n", object_name(o.index, o.sub).c_str(), shown.c_str());
  }
}

int drive_read(const ParsedArgs& args, const hal::eds::Description* eds) {
  Object o{};
  if (const int rc = object_of(args, eds, o); rc >= 0) return rc;
  Session s{args, "read", eds};
  if (const int rc = s.open(); rc >= 0) return rc;
  const Read r = s.read(o.index, o.sub);
  if (!r.ok()) return s.transfer_failed(r.result);
  Json value;
  std::string shown;
  if (const int rc = typed_value(s, o, r, value, shown); rc >= 0) return rc;
  print_value(s, o, value, shown, "value");
  return kExitOk;
}

int drive_write(const ParsedArgs& args, const hal::eds::Description* eds) {
  Object o{};
  if (const int rc = object_of(args, eds, o); rc >= 0) return rc;
  if (!args.has("--value")) return report_bad_request({"missing_option", "--value", "--value: required"}, args.json());
  const std::string text = args.text("--value", "");
  // The value against its type, before anything is sent.
  std::uint32_t raw = 0;
  if (o.type->bytes != 0) {
    const unsigned bits = 8 * o.type->bytes;
    const Range r = o.type->is_signed ? Range{-std::ldexp(1.0, static_cast<int>(bits) - 1),
                                              std::ldexp(1.0, static_cast<int>(bits) - 1) - 1}
                                      : Range{0.0, std::ldexp(1.0, static_cast<int>(bits)) - 1};
    OptionSpec spec{.name = "--value", .kind = Kind::integer, .unit = "", .def = "",
                    .help = "", .range = r};
    spec.hex = true;
    double v = 0.0;
    RequestError err;
    if (!check_value(spec, text, v, err)) {
      err.message += " for --type " + std::string{o.type->name};
      return report_bad_request(err, args.json());
    }
    raw = static_cast<std::uint32_t>(static_cast<std::int64_t>(v));
  } else if (text.size() > kMaxObjectBytes) {
    return report_bad_request({"out_of_range", "--value",
                               "--value: " + std::to_string(text.size()) + " bytes; at most " +
                                   std::to_string(kMaxObjectBytes)},
                              args.json());
  }
  Session s{args, "write", eds};
  if (const int rc = s.open(); rc >= 0) return rc;
  const std::vector<std::uint8_t> bytes(text.begin(), text.end());
  const SdoResult w = o.type->bytes != 0 ? s.write_integer(o.index, o.sub, raw, o.type->bytes)
                                         : s.write_bytes(o.index, o.sub, bytes);
  if (w.status != SdoClientStatus::done) return s.transfer_failed(w);
  // Read back: a drive that takes a write and keeps another value is caught here.
  const Read back = s.read(o.index, o.sub);
  if (back.result.status == SdoClientStatus::aborted &&
      back.result.abort_raw == static_cast<std::uint32_t>(SdoAbort::write_only)) {
    print_value(s, o, nullptr, "written (write-only: not read back)", "read_back");
    return kExitOk;
  }
  if (!back.ok()) return s.transfer_failed(back.result);
  Json value;
  std::string shown;
  if (const int rc = typed_value(s, o, back, value, shown); rc >= 0) return rc;
  const bool same = o.type->bytes == 0 ? back.bytes == bytes : back.unsigned_value() == raw;
  if (!same) {
    return s.failed("read_back_differs", "node " + std::to_string(s.node()) + ", " + object_name(o.index, o.sub) +
                                             ": wrote " + (o.type->bytes == 0 ? "\"" + printable(text) + "\"" : text) +
                                             ", read back " + shown);
  }
  print_value(s, o, value, shown + " (written and read back)", "read_back");
  return kExitOk;
}

// ---- scan ----------------------------------------------------------------------------------

int drive_scan(const ParsedArgs& args, const hal::eds::Description* eds) {
  Session s{args, "scan", eds};
  if (const int rc = s.open(); rc >= 0) return rc;
  Json nodes = Json::array();
  std::string text;
  std::vector<SdoClient> batch;
  batch.reserve(kScanBatch);
  const Progress progress;
  for (unsigned first = 1; first <= 127; first += kScanBatch) {
    progress.say("settle drive scan: nodes %u..%u of 127 on %s, %zu answered so far", first,
                 std::min(first + kScanBatch - 1U, 127U), s.bus_name().c_str(), nodes.size());
    batch.clear();
    for (unsigned node = first; node < first + kScanBatch && node <= 127; ++node) {
      batch.emplace_back(static_cast<hal::canopen::NodeId>(node), s.timeout_us());
      SdoClient& c = batch.back();
      const std::span<SdoClient> running{batch.data(), batch.size() - 1};
      if (!start_transfer(s.link(), running, [&](std::uint64_t now, hal::FrameSink& out) {
            return c.upload(0x1000, 0, now, out);
          })) {
        return s.failed("bus", "cannot send on " + s.bus_name() + " (the transmit queue stays full)");
      }
    }
    finish_transfers(s.link(), batch);
    for (const SdoClient& c : batch) {
      const SdoResult& r = c.result();
      if (r.status == SdoClientStatus::timed_out) continue;
      // An abort is an answer too: the node is there, without a readable 0x1000.
      Json n{{"node", c.server()}, {"device_type", r.status == SdoClientStatus::done ? Json(r.value) : Json(nullptr)}};
      char line[160];
      if (r.status == SdoClientStatus::done) {
        std::snprintf(line, sizeof line, "node %3u  device type %s (profile %u)\n", static_cast<unsigned>(c.server()),
                      hex(r.value, 8).c_str(), static_cast<unsigned>(r.value & 0xFFFFU));
      } else {
        n["abort_code"] = hex(r.abort_raw, 8);
        n["meaning"] = hal::canopen::abort_meaning(r.abort_raw);
        std::snprintf(line, sizeof line, "node %3u  device type: %s\n", static_cast<unsigned>(c.server()),
                      abort_text(r).c_str());
      }
      text += line;
      nodes.push_back(n);
    }
  }
  progress.done();
  if (s.json()) {
    print_json({{"status", "ok"}, {"bus", s.bus_name()}, {"nodes", nodes}});
  } else {
    std::printf("%zu node(s) answered on %s\n%s", nodes.size(), s.bus_name().c_str(), text.c_str());
  }
  return kExitOk;
}

// What start-up writes to an object: what it held before (absent: the drive lacks it; start-up
// decides whether that matters) and the last value start-up writes to it.
struct ConfigChange {
  std::uint16_t index;
  std::uint8_t sub;
  std::optional<std::uint32_t> before;
  std::uint32_t after;
};

// Every object the start-up steps write, read before they run. Exit status or -1.
int read_before_writes(Session& s, const hal::canopen::StartupStep* steps, std::size_t count,
                       std::vector<ConfigChange>& changes) {
  for (std::size_t i = 0; i < count; ++i) {
    const hal::canopen::StartupStep& st = steps[i];
    if (st.action() != hal::canopen::StartupAction::write) continue;
    const auto known = std::find_if(changes.begin(), changes.end(),
                                    [&](const ConfigChange& c) { return c.index == st.index() && c.sub == st.sub(); });
    if (known != changes.end()) {
      known->after = st.value();
      continue;
    }
    const Read r = s.read(st.index(), st.sub());
    if (r.timed_out()) return s.transfer_failed(r.result);
    changes.push_back({st.index(), st.sub(), r.ok() ? std::optional<std::uint32_t>{r.unsigned_value()} : std::nullopt,
                       st.value()});
  }
  return -1;
}

// RemoteDrive's start-up of `config` (`count` steps) run to the end of its configuration, the drive
// then left pre-operational; `took_ms` how long it took. Exit status or -1.
int run_configuration(Session& s, const hal::canopen::RemoteDriveConfig& config, std::size_t count, double& took_ms) {
  using hal::canopen::RemoteDriveState;
  testbed::ClockedBus& link = s.link();
  hal::canopen::RemoteDrive drive{config};
  const std::uint64_t started_us = link.now_us();
  drive.start(started_us, link.link());
  // Bounded: every step may wait two SDO timeouts (one retry), and NMT takes a moment.
  const std::uint64_t deadline_us = started_us + (count + 2) * 2ULL * s.timeout_us() + 1'000'000ULL;
  while (drive.state() == RemoteDriveState::configuring && link.now_us() < deadline_us) {
    hal::CanFrame f{};
    if (link.receive(f, 10'000)) (void)drive.on_frame(f, link.now_us(), link.link());
    drive.poll(link.now_us(), link.link());
  }
  took_ms = static_cast<double>(link.now_us() - started_us) / 1000.0;
  // Start-up ends with NMT start; a configured drive is left pre-operational, not running.
  (void)link.link().send(hal::canopen::encode_nmt(hal::canopen::NmtCommand::enter_pre_operational, s.node()));
  if (drive.state() == RemoteDriveState::configuring) {
    return s.failed("timeout", "node " + std::to_string(s.node()) + ": configuration did not finish in time");
  }
  if (drive.state() == RemoteDriveState::failed) {
    const hal::canopen::RemoteDriveFailure& f = drive.failure();
    return s.failed("start_up_failed", "node " + std::to_string(s.node()) + ": " + testbed::start_up_failure_text(f),
                    {{"index", hex(f.index, 4)}, {"sub", f.sub}, {"reason", hal::canopen::to_string(f.error)}});
  }
  return -1;
}

// What drive config did, as text or JSON: the objects written and changed, what was not written
// and why, and how the master uses each object the EDS offers.
struct ConfigReport {
  std::size_t steps{0};
  std::vector<ConfigChange> changes;
  double took_ms{0.0};
  std::vector<hal::eds::Capability> caps;
};

int print_configuration(const Session& s, const hal::canopen::RemoteDriveConfig& config, const ConfigReport& r,
                        const std::vector<hal::eds::Problem>& eds_warnings) {
  const char* setup = config.pdo_setup == hal::canopen::PdoSetup::dynamic       ? "dynamic"
                      : config.pdo_setup == hal::canopen::PdoSetup::read_static ? "static (read and checked)"
                                                                                : "assumed";
  std::size_t changed = 0;
  for (const ConfigChange& c : r.changes) changed += c.before != c.after ? 1U : 0U;
  // What the master did not write, and why (CiA 301 asks 0x1006 only of the SYNC producer).
  std::vector<std::string> skipped;
  if (!config.write_sync_period) {
    skipped.emplace_back(object_name(hal::canopen::obj::communication_cycle_period, 0) +
                         " not written: the drive's EDS has no 0x1006 (communication cycle period; CiA 301 asks it "
                         "only of the SYNC producer)");
  }
  // A drive whose description needed tolerating is configured, but not called verified.
  const bool verified = eds_warnings.empty();
  if (s.json()) {
    Json objects = Json::array();
    for (const hal::eds::Capability& c : r.caps) {
      objects.push_back({{"object", object_name(c.index, c.sub)},
                         {"name", c.name},
                         {"needed", c.needed},
                         {"found", c.found},
                         {"use", c.use.empty() ? Json(nullptr) : Json(c.use)},
                         {"without", c.use.empty() ? Json(c.without) : Json(nullptr)}});
    }
    Json list = Json::array();
    for (const ConfigChange& c : r.changes) {
      list.push_back({{"object", object_name(c.index, c.sub)},
                      {"before", c.before ? Json(*c.before) : Json(nullptr)},
                      {"after", c.after},
                      {"changed", c.before != c.after}});
    }
    print_json({{"status", "ok"},
                {"node", s.node()},
                {"pdo_mapping", setup},
                {"steps", r.steps},
                {"objects_written", r.changes.size()},
                {"objects_changed", changed},
                {"configured_ms", r.took_ms},
                {"writes", list},
                {"skipped", skipped},
                {"objects", objects},
                {"verified", verified},
                {"eds_warnings", warnings_json(eds_warnings)}});
    return kExitOk;
  }
  std::printf("node %u configured%s in %.1f ms: %zu steps, PDO mapping %s; %zu objects written, %zu "
              "changed (each read back)\n",
              static_cast<unsigned>(s.node()), verified ? " and verified" : "", r.took_ms, r.steps, setup,
              r.changes.size(), changed);
  if (!verified) {
    std::printf("  not verified: its EDS needed %zu deviation(s) tolerated (the warnings on stderr)\n",
                eds_warnings.size());
  }
  for (const ConfigChange& c : r.changes) {
    std::printf("  %s  %-12s -> %-12s %s\n", object_name(c.index, c.sub).c_str(),
                c.before ? hex(*c.before, 8).c_str() : "absent", hex(c.after, 8).c_str(),
                c.before != c.after ? "changed" : "unchanged");
  }
  for (const std::string& why : skipped) std::printf("  %s\n", why.c_str());
  std::printf("objects (found in the EDS: how the master uses each, or does without):\n");
  for (const hal::eds::Capability& c : r.caps) {
    const std::string use = !c.use.empty() ? c.use
                            : c.found      ? "found, not used: " + c.without
                                           : "absent: " + c.without;
    std::printf("  %-8s %-44s %s%s\n", object_name(c.index, c.sub).c_str(), c.name.c_str(), use.c_str(),
                c.needed ? " (needed)" : "");
  }
  return kExitOk;
}

// settle drive config: the master's start-up (hal's RemoteDrive, configured from the EDS as
// `settle stream --eds` configures it) run to the end of its configuration. Every object it
// writes is read first, so the output says what changed; RemoteDrive reads each write back.
int drive_config(const ParsedArgs& args, const hal::eds::Description* eds,
                 const std::vector<hal::eds::Problem>& eds_warnings) {
  if (eds == nullptr) {
    return report_bad_request({"missing_option", "--eds", "--eds: required (drive config applies what the drive's EDS/DCF describes)"}, args.json());
  }
  Session s{args, "config", eds};
  hal::canopen::RemoteDriveConfig base{};
  base.node = s.node();
  base.sdo_timeout_us = s.timeout_us();
  const hal::eds::FeedbackRequest feedback = testbed::streaming_feedback(*eds);
  const hal::eds::DriveConfigResult plan = hal::eds::drive_config_from_eds(*eds, base, feedback);
  if (!plan.ok()) return s.failed("cannot_stream", "node " + std::to_string(s.node()) + ": " + plan.error);
  std::array<hal::canopen::StartupStep, hal::canopen::remote_drive_max_steps> steps{};
  const std::optional<std::size_t> count = hal::canopen::plan_start_up(plan.config, steps);
  if (!count) return s.failed("plan_too_long", "the configuration needs more start-up steps than the master holds");
  if (const int rc = s.open(); rc >= 0) return rc;
  ConfigReport report{};
  report.steps = *count;
  if (const int rc = read_before_writes(s, steps.data(), *count, report.changes); rc >= 0) return rc;
  if (const int rc = run_configuration(s, plan.config, *count, report.took_ms); rc >= 0) return rc;
  // What the drive offers the master, and what the master does with it.
  report.caps = hal::eds::capabilities(*eds, plan, feedback);
  return print_configuration(s, plan.config, report, eds_warnings);
}

// ---- nmt ------------------------------------------------------------------------------------

// settle drive nmt: the link lets the node's heartbeat through; the rest is run_drive_nmt's.
int drive_nmt(const ParsedArgs& args, const hal::eds::Description* eds) {
  Session s{args, "nmt", eds};
  if (const int rc = s.open(nmt_heartbeat_filter(s.node())); rc >= 0) return rc;
  return run_drive_nmt(s.link(), {s.node(), args.positional(), s.timeout_us(), s.json(), s.bus_name()}, stdout, stderr);
}

}  // namespace

int cmd_drive(int argc, char** argv) {
  const std::string sub = argc > 0 ? argv[0] : "";
  if (sub == "--help" || sub == "-h") {
    std::fputs(drive_help().c_str(), stdout);
    return kExitOk;
  }
  if (std::find(std::begin(kSubcommands), std::end(kSubcommands), sub) == std::end(kSubcommands)) {
    const bool json = std::any_of(argv, argv + argc, [](const char* a) { return std::strcmp(a, "--json") == 0; });
    return report_bad_request({"bad_command", "drive",
                               "drive: " + (sub.empty() ? std::string{"needs a subcommand"}
                                                        : "unknown subcommand '" + sub + "'") +
                                   " (info, read, write, config, scan, nmt; settle drive --help)"},
                              json);
  }
  const std::string name = "drive " + sub;
  ParsedArgs args;
  if (const int rc = parse_or_exit(name, argc - 1, argv + 1, args); rc >= 0) return rc;
  EdsOption loaded;
  if (const int rc = load_description(sub, args, loaded); rc >= 0) return rc;
  const hal::eds::Description* eds = loaded.description.get();
  if (sub == "info") return drive_info(args, eds, loaded.warnings);
  if (sub == "read") return drive_read(args, eds);
  if (sub == "write") return drive_write(args, eds);
  if (sub == "config") return drive_config(args, eds, loaded.warnings);
  if (sub == "nmt") return drive_nmt(args, eds);
  return drive_scan(args, eds);
}

}  // namespace settle::app
