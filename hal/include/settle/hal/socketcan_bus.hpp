// SPDX-License-Identifier: Apache-2.0
// Linux SocketCAN backend: a raw CAN socket behind the CanBus interface (filters, optional FD,
// non-blocking sends where a full queue is reported busy, kernel drop counting, receive
// timestamps), and CanInterface, link control through libsocketcan. Host-only; the Linux CAN
// headers stay inside src/socketcan.cpp.
//
// Controller errors: the socket subscribes to the kernel's error frames (CAN_RAW_ERR_FILTER:
// controller problems, bus-off, restarted, transmit timeout). receive() never returns them as
// frames; it turns them into bus_state() (confirmed through libsocketcan's can_get_state where
// the interface has a controller) and counts them. restart() is can_do_restart, which a virtual
// interface refuses (not_supported).
//
// Receive timestamps are the kernel's (SO_TIMESTAMP, CLOCK_REALTIME, µs since the epoch).
// rx_overflow_drops is exact once receive() has found the queue empty.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "settle/hal/can_bus.hpp"
#include "settle/hal/enum_text.hpp"

namespace settle::hal {

struct SocketCanOptions {
  bool fd_frames{false};      // CAN_RAW_FD_FRAMES: send and receive FD frames too
  bool receive_own{false};    // CAN_RAW_RECV_OWN_MSGS: hear this socket's own frames
  bool timestamps{true};      // SO_TIMESTAMP: CanFrame::timestamp_us = kernel receive time
  int receive_buffer_bytes{0};  // SO_RCVBUF(FORCE); 0 keeps the kernel default
  int send_buffer_bytes{0};     // SO_SNDBUF(FORCE); 0 keeps the kernel default
};

// Made from one list (enum_text.hpp): the enumerator and the sentence to_string() gives.
#define SETTLE_HAL_OPEN_STATUSES(X) \
  X(ok, "ok") \
  X(no_such_interface, "no such interface") \
  X(not_can_interface, "not a CAN interface") \
  X(permission_denied, "permission denied") \
  /* FD asked for, the interface's MTU is classic (ip link set <if> mtu 72) */ \
  X(fd_not_supported, "CAN FD not supported by the interface (MTU 16)") \
  X(already_open, "already open") \
  X(error, "error")
enum class OpenStatus : std::uint8_t { SETTLE_HAL_OPEN_STATUSES(SETTLE_ENUM_ENUMERATOR) };

[[nodiscard]] const char* to_string(OpenStatus status) noexcept;

// What one kernel error frame (its can_id with CAN_ERR_FLAG, and its 8 data bytes) says about the
// controller's state, given the state before it: bus-off, restarted (-> error_active), or the
// controller-problem byte's warning/passive/active bits; anything else leaves the state as it was.
// Defined with the kernel's constants (linux/can/error.h) in socketcan.cpp.
[[nodiscard]] BusState bus_state_from_error_frame(std::uint32_t can_id, std::span<const std::uint8_t> data,
                                                  BusState before) noexcept;


// Made from one list (enum_text.hpp): the enumerator and the sentence to_string() gives.
#define SETTLE_HAL_CONTROL_STATUSES(X) \
  X(ok, "ok") \
  /* the interface has no CAN controller settings (vcan, vxcan, slcan) */ \
  X(not_supported, "not supported by this interface") \
  X(no_such_interface, "no such interface") \
  X(permission_denied, "permission denied") \
  X(error, "error")
enum class ControlStatus : std::uint8_t { SETTLE_HAL_CONTROL_STATUSES(SETTLE_ENUM_ENUMERATOR) };

[[nodiscard]] const char* to_string(ControlStatus status) noexcept;

enum class CanControllerState : std::uint8_t {
  error_active,
  error_warning,
  error_passive,
  bus_off,
  stopped,
  sleeping,
  unknown,
};

struct CanErrorCounters {
  std::uint16_t tx_errors{0};
  std::uint16_t rx_errors{0};
};

// Link control of one CAN network interface (libsocketcan over netlink). On a virtual
// interface only link up/down apply; the rest report not_supported instead of failing.
class CanInterface {
 public:
  explicit CanInterface(const char* name) noexcept;

  [[nodiscard]] bool exists() const noexcept;
  // True for a real controller (can-dev), false for virtual interfaces.
  [[nodiscard]] bool has_controller() const noexcept;

  [[nodiscard]] ControlStatus link_up() noexcept;
  [[nodiscard]] ControlStatus link_down() noexcept;
  [[nodiscard]] ControlStatus restart() noexcept;  // after bus-off
  [[nodiscard]] ControlStatus set_bitrate(std::uint32_t bits_per_second) noexcept;
  [[nodiscard]] ControlStatus bitrate(std::uint32_t& bits_per_second) const noexcept;
  [[nodiscard]] ControlStatus state(CanControllerState& state) const noexcept;
  [[nodiscard]] ControlStatus error_counters(CanErrorCounters& counters) const noexcept;

  [[nodiscard]] const char* name() const noexcept { return name_.data(); }

 private:
  [[nodiscard]] ControlStatus precheck(bool needs_controller) const noexcept;

  std::array<char, 16> name_{};
};

class SocketCanBus final : public CanBus {
 public:
  SocketCanBus() noexcept = default;
  ~SocketCanBus() override;

  [[nodiscard]] OpenStatus open(const char* interface, const SocketCanOptions& options = {}) noexcept;
  void close() noexcept;

  [[nodiscard]] bool is_open() const noexcept { return fd_ >= 0; }
  // The socket, for a caller that multiplexes with poll/epoll; reading it directly bypasses
  // the counters.
  [[nodiscard]] int native_handle() const noexcept { return fd_; }
  // errno of the last failed system call (send, receive, open), for diagnostics.
  [[nodiscard]] int last_errno() const noexcept { return last_errno_; }

 private:
  [[nodiscard]] SendStatus do_send(const CanFrame& frame) noexcept override;
  [[nodiscard]] ReceiveStatus do_receive(CanFrame& frame, std::uint32_t timeout_us) noexcept override;
  // One recvmsg: a data frame into `frame`, or an error frame taken (error_frame set).
  [[nodiscard]] ReceiveStatus receive_one(CanFrame& frame, bool& error_frame) noexcept;
  [[nodiscard]] BusStatus do_set_filters(std::span<const CanFilter> filters) noexcept override;
  [[nodiscard]] BusStatus do_restart() noexcept override;
  // An error frame: the state it implies, or the driver's own (can_get_state) where it has one.
  void take_error_frame(std::uint32_t can_id, std::span<const std::uint8_t> data) noexcept;
  void refresh_controller_state() noexcept;
  void refresh_kernel_drops() noexcept;
  void account_kernel_drops(std::uint32_t total) noexcept;

  int fd_{-1};
  int last_errno_{0};
  bool fd_frames_{false};
  std::uint32_t kernel_drops_{0};  // last SO_RXQ_OVFL value, which the kernel reports cumulatively
  bool has_controller_{false};     // can-dev: can_get_state and can_do_restart apply
  bool controller_known_{false};
  CanInterface interface_{""};
};

}  // namespace settle::hal
