// SPDX-License-Identifier: Apache-2.0
#include "settle/hal/canopen/default_mapping.hpp"

#include "settle/hal/canopen/byte_order.hpp"

namespace settle::hal::canopen {

namespace {
[[nodiscard]] CanFrame pdo_frame(std::uint16_t function_code, NodeId node, std::uint8_t len) noexcept {
  CanFrame f{};
  f.id = cob_id(function_code, node);
  f.len = len;
  return f;
}

[[nodiscard]] bool is_pdo(const CanFrame& f, std::uint16_t function_code, NodeId node, std::uint8_t len) noexcept {
  return is_canopen_data_frame(f) && f.id == cob_id(function_code, node) && f.len == len && is_valid_node(node);
}
}  // namespace

CanFrame encode_rpdo1(NodeId node, const Rpdo1& pdo) noexcept {
  CanFrame f{};
  encode_rpdo1(node, pdo, f);
  return f;
}

CanFrame encode_tpdo1(NodeId node, const Tpdo1& pdo) noexcept {
  CanFrame f = pdo_frame(cob::tpdo1, node, 6);
  put_u16(&f.data[0], pdo.statusword);
  put_i32(&f.data[2], pdo.position_actual);
  return f;
}

CanFrame encode_tpdo2(NodeId node, const Tpdo2& pdo) noexcept {
  CanFrame f = pdo_frame(cob::tpdo2, node, 8);
  put_i32(&f.data[0], pdo.load_position);
  put_i32(&f.data[4], pdo.velocity_actual);
  return f;
}

std::optional<Rpdo1> decode_rpdo1(const CanFrame& frame, NodeId node) noexcept {
  if (!is_pdo(frame, cob::rpdo1, node, 6)) {
    return std::nullopt;
  }
  return Rpdo1{get_u16(&frame.data[0]), get_i32(&frame.data[2])};
}

std::optional<Tpdo1> decode_tpdo1(const CanFrame& frame, NodeId node) noexcept {
  if (!is_pdo(frame, cob::tpdo1, node, tpdo1_len)) {
    return std::nullopt;
  }
  return tpdo1_fields(frame);
}

std::optional<Tpdo2> decode_tpdo2(const CanFrame& frame, NodeId node) noexcept {
  if (!is_pdo(frame, cob::tpdo2, node, tpdo2_len)) {
    return std::nullopt;
  }
  return tpdo2_fields(frame);
}

}  // namespace settle::hal::canopen
