// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/eds_semantics.hpp"

#include <cstdio>
#include <string>

namespace settle::hal::eds {
namespace {

std::string hex(std::uint32_t v, int digits) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%0*X", digits, static_cast<unsigned>(v));
  return text;
}

std::string name_of(const Pdo& p) { return std::string{p.receive ? "RPDO" : "TPDO"} + std::to_string(p.number); }

// The place of an object's value: its section, the key its value came from, its line.
Problem at_value(const Entry& e, std::string message) {
  return Problem{e.section, e.parameter_value.empty() ? "DefaultValue" : "ParameterValue", std::move(message), e.line};
}

// The 11-bit identifiers this node's own services use, and what each is.
struct Service {
  std::uint32_t id;
  const char* what;
};

// CiA 301 7.3.5: identifiers restricted from PDO use (any node's SDO, EMCY, heartbeat, ...).
const char* restricted(std::uint32_t id) {
  if (id == 0x000) return "NMT";
  if (id >= 0x001 && id <= 0x07F) return "reserved";
  if (id >= 0x101 && id <= 0x180) return "reserved (0x101..0x180, EMCY of nodes)";
  if (id >= 0x581 && id <= 0x5FF) return "SDO server to client (0x581..0x5FF)";
  if (id >= 0x601 && id <= 0x67F) return "SDO client to server (0x601..0x67F)";
  if (id >= 0x6E0 && id <= 0x6FF) return "reserved (0x6E0..0x6FF)";
  if (id >= 0x701 && id <= 0x77F) return "heartbeat (0x701..0x77F)";
  if (id >= 0x780 && id <= 0x7FF) return "LSS and reserved (0x780..0x7FF)";
  return nullptr;
}

}  // namespace

Semantics check_semantics(const Description& d, std::uint8_t node) {
  Semantics s{};
  const auto refuse = [&](Problem p) {
    if (!s.refusal) s.refusal = std::move(p);
  };

  if (const auto dcf = d.dcf_node_id(); dcf && *dcf != node) {
    refuse(Problem{"DeviceComissioning", "NodeID",
                   "the DCF configures node " + std::to_string(*dcf) + ", not node " + std::to_string(node) +
                       " (give --node " + std::to_string(*dcf) + ", or the drive's EDS)",
                   0});
  }

  if (const Entry* v = d.find(0x607F, 0); v != nullptr && v->value(node) == 0) {
    refuse(at_value(*v, "0x607F:0 (max profile velocity) is 0: the drive would refuse every step of a move"));
  }

  // This node's services, as its own objects set them (SYNC 0x1005, EMCY 0x1014) or by default.
  const auto id_of = [&](std::uint16_t index, std::uint32_t fallback) {
    const Entry* e = d.find(index, 0);
    const auto v = e != nullptr ? e->value(node) : std::nullopt;
    return v ? static_cast<std::uint32_t>(*v) & 0x7FFU : fallback;
  };
  const Service services[] = {{0x000, "NMT"},
                              {id_of(0x1005, 0x080), "SYNC (0x1005)"},
                              {id_of(0x1014, 0x080U + node), "this node's EMCY (0x1014)"},
                              {0x580U + node, "this node's SDO response"},
                              {0x600U + node, "this node's SDO request"},
                              {0x700U + node, "this node's heartbeat"}};

  std::vector<Pdo> all = d.rpdos(node);
  for (Pdo& p : d.tpdos(node)) all.push_back(std::move(p));
  std::vector<const Pdo*> seen;
  for (const Pdo& p : all) {
    const Entry* cob = d.find(p.communication_index(), 1);
    const Entry* type = d.find(p.communication_index(), 2);
    if (cob == nullptr || (p.cob_id & 0x80000000U) != 0) continue;  // not valid: never on the bus
    const std::string who = hex(p.communication_index(), 4) + ":1 (" + name_of(p) + " COB-ID " +
                            hex(p.cob_id & 0x1FFFFFFFU, 3) + ")";
    if ((p.cob_id & (1U << 29)) == 0) {
      const std::uint32_t id = p.cob_id & 0x7FFU;
      bool collided = false;
      for (const Service& svc : services) {
        if (id == svc.id) {
          refuse(at_value(*cob, who + " is " + svc.what + "'s identifier (CiA 301: a COB-ID serves one object)"));
          collided = true;
        }
      }
      for (const Pdo* other : seen) {
        if ((other->cob_id & 0x1FFFFFFFU) == (p.cob_id & 0x1FFFFFFFU) && (other->cob_id & (1U << 29)) == 0) {
          refuse(at_value(*cob, who + " is also " + name_of(*other) +
                                    "'s (CiA 301: a COB-ID serves one object)"));
          collided = true;
        }
      }
      if (const char* why = restricted(id); why != nullptr && !collided) {
        s.warnings.push_back(at_value(*cob, who + " is in a range CiA 301 restricts: " + why));
      }
    }
    seen.push_back(&p);
    if (type == nullptr || !type->value(node)) continue;
    const auto tt = static_cast<unsigned>(*type->value(node));
    const std::string tw = hex(p.communication_index(), 4) + ":2 (" + name_of(p) + " transmission type " +
                           std::to_string(tt) + ")";
    if (p.receive ? (tt >= 241 && tt <= 253) : (tt >= 241 && tt <= 251)) {
      refuse(at_value(*type, tw + " is reserved by CiA 301"));
    } else if (!p.receive && (tt == 0 || tt >= 252)) {
      const char* how = tt == 0      ? "only after a SYNC when its data changed (acyclic)"
                        : tt <= 253 ? "only when asked by a remote frame (RTR), which the master never sends"
                                    : "on its own events and timer, not per SYNC";
      s.warnings.push_back(at_value(*type, tw + ": the drive sends it " + how));
    }
  }
  return s;
}

}  // namespace settle::hal::eds
