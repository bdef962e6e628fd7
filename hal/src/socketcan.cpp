// SPDX-License-Identifier: Apache-2.0
// The only file of Settle that includes the Linux CAN headers: everything kernel-shaped is
// converted to and from settle::hal types here.
#include <fcntl.h>
#include <libsocketcan.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/netlink.h>
#include <linux/can/raw.h>
#include <linux/sock_diag.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include "settle/hal/socketcan_bus.hpp"

namespace settle::hal {

namespace {

[[nodiscard]] canid_t to_kernel_id(const CanFrame& f) noexcept {
  canid_t id = f.id;
  if (f.is_extended()) {
    id |= CAN_EFF_FLAG;
  }
  if (f.is_rtr()) {
    id |= CAN_RTR_FLAG;
  }
  return id;
}

void from_kernel_id(canid_t id, CanFrame& f) noexcept {
  if ((id & CAN_EFF_FLAG) != 0) {
    f.flags |= can_flag::extended;
    f.id = id & CAN_EFF_MASK;
  } else {
    f.id = id & CAN_SFF_MASK;
  }
  if ((id & CAN_RTR_FLAG) != 0) {
    f.flags |= can_flag::rtr;
  }
}

[[nodiscard]] OpenStatus open_status_from_errno(int err) noexcept {
  switch (err) {
    case ENODEV:
    case ENXIO: return OpenStatus::no_such_interface;
    case EPERM:
    case EACCES: return OpenStatus::permission_denied;
    default: return OpenStatus::error;
  }
}

}  // namespace

namespace {
constexpr const char* kOpenStatusTexts[] = {SETTLE_HAL_OPEN_STATUSES(SETTLE_ENUM_TEXT)};
constexpr const char* kControlStatusTexts[] = {SETTLE_HAL_CONTROL_STATUSES(SETTLE_ENUM_TEXT)};
}  // namespace

const char* to_string(OpenStatus status) noexcept { return enum_text(kOpenStatusTexts, status, "?"); }

SocketCanBus::~SocketCanBus() { close(); }

void SocketCanBus::close() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

OpenStatus SocketCanBus::open(const char* interface, const SocketCanOptions& options) noexcept {
  if (fd_ >= 0) {
    return OpenStatus::already_open;
  }
  if (interface == nullptr || std::strlen(interface) >= IFNAMSIZ) {
    return OpenStatus::no_such_interface;
  }
  const unsigned index = if_nametoindex(interface);
  if (index == 0) {
    last_errno_ = errno;
    return OpenStatus::no_such_interface;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    last_errno_ = errno;
    // No CAN protocol family in this kernel at all.
    return errno == EAFNOSUPPORT || errno == EPROTONOSUPPORT ? OpenStatus::not_can_interface
                                                              : open_status_from_errno(errno);
  }
  const auto fail = [&](OpenStatus status) {
    last_errno_ = errno;
    ::close(fd);
    return status;
  };

  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface, IFNAMSIZ - 1);
  if (::ioctl(fd, SIOCGIFMTU, &ifr) < 0) {
    return fail(open_status_from_errno(errno));
  }
  if (ifr.ifr_mtu != CAN_MTU && ifr.ifr_mtu != CANFD_MTU) {
    return fail(OpenStatus::not_can_interface);
  }
  if (options.fd_frames) {
    if (ifr.ifr_mtu != CANFD_MTU) {
      return fail(OpenStatus::fd_not_supported);
    }
    const int on = 1;
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) < 0) {
      return fail(OpenStatus::fd_not_supported);
    }
  }
  const int own = options.receive_own ? 1 : 0;
  const int on = 1;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof own) < 0 ||
      ::setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) < 0) {
    return fail(OpenStatus::error);
  }
  if (options.timestamps && ::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on) < 0) {
    return fail(OpenStatus::error);
  }
  // The *FORCE variants may exceed net.core.[rw]mem_max but need CAP_NET_ADMIN; without it
  // the plain option still gets as much as the system allows.
  if (options.receive_buffer_bytes > 0 &&
      ::setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &options.receive_buffer_bytes, sizeof options.receive_buffer_bytes) < 0 &&
      ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &options.receive_buffer_bytes, sizeof options.receive_buffer_bytes) < 0) {
    return fail(OpenStatus::error);
  }
  if (options.send_buffer_bytes > 0 &&
      ::setsockopt(fd, SOL_SOCKET, SO_SNDBUFFORCE, &options.send_buffer_bytes, sizeof options.send_buffer_bytes) < 0 &&
      ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &options.send_buffer_bytes, sizeof options.send_buffer_bytes) < 0) {
    return fail(OpenStatus::error);
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) < 0) {
    return fail(open_status_from_errno(errno));
  }
  // Controller errors arrive as error frames: problems (warning, passive, active again),
  // bus-off, restarted, and transmit timeouts (a frame nobody acknowledged).
  const can_err_mask_t err_mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) < 0) {
    return fail(OpenStatus::error);
  }
  fd_ = fd;
  fd_frames_ = options.fd_frames;
  kernel_drops_ = 0;
  interface_ = CanInterface{interface};
  // Whether it has a controller to ask is learnt with the first error frame: libsocketcan's query
  // prints to stderr on a virtual interface, which never sends one.
  controller_known_ = false;
  set_bus_state(BusState::error_active);
  return OpenStatus::ok;
}

SendStatus SocketCanBus::do_send(const CanFrame& frame) noexcept {
  if (fd_ < 0 || (frame.is_fd() && !fd_frames_)) {
    return SendStatus::error;
  }
  canfd_frame k{};
  k.can_id = to_kernel_id(frame);
  k.len = frame.len;
  if (frame.is_fd()) {
    k.flags = static_cast<__u8>(((frame.flags & can_flag::brs) != 0 ? CANFD_BRS : 0) |
                                ((frame.flags & can_flag::esi) != 0 ? CANFD_ESI : 0));
  }
  const auto payload = frame.payload();
  std::memcpy(k.data, payload.data(), payload.size());
  // struct can_frame is the first CAN_MTU bytes of struct canfd_frame (same layout).
  const std::size_t size = frame.is_fd() ? CANFD_MTU : CAN_MTU;
  const ssize_t n = ::send(fd_, &k, size, MSG_DONTWAIT);
  if (n == static_cast<ssize_t>(size)) {
    return SendStatus::sent;
  }
  last_errno_ = n < 0 ? errno : EMSGSIZE;
  // A full socket or device queue is back-pressure, not a failure: the caller decides.
  return (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) ? SendStatus::busy
                                                                                    : SendStatus::error;
}

ReceiveStatus SocketCanBus::do_receive(CanFrame& frame, std::uint32_t timeout_us) noexcept {
  if (fd_ < 0) {
    return ReceiveStatus::error;
  }
  if (timeout_us > 0) {
    pollfd p{fd_, POLLIN, 0};
    const timespec ts{static_cast<time_t>(timeout_us / 1'000'000U), static_cast<long>(timeout_us % 1'000'000U) * 1000L};
    const int ready = ::ppoll(&p, 1, &ts, nullptr);
    if (ready == 0) {
      refresh_kernel_drops();
      return ReceiveStatus::empty;
    }
    if (ready < 0) {
      last_errno_ = errno;
      return errno == EINTR ? ReceiveStatus::empty : ReceiveStatus::error;
    }
  }
  // Error frames are taken here, not returned: a bounded number per call, then "empty" (the
  // next call goes on), so a controller flooding errors cannot hold the caller.
  for (int error_frames = 0; error_frames < 16; ++error_frames) {
    bool error_frame = false;
    const ReceiveStatus status = receive_one(frame, error_frame);
    if (status != ReceiveStatus::received || !error_frame) {
      return status;
    }
  }
  return ReceiveStatus::empty;
}

ReceiveStatus SocketCanBus::receive_one(CanFrame& frame, bool& error_frame) noexcept {
  canfd_frame k{};
  iovec iov{&k, sizeof k};
  alignas(cmsghdr) std::array<char, CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(std::uint32_t))> control{};
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control.data();
  msg.msg_controllen = control.size();
  const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
  if (n < 0) {
    last_errno_ = errno;
    if (errno == EAGAIN || errno == EWOULDBLOCK) {
      refresh_kernel_drops();
      return ReceiveStatus::empty;
    }
    return errno == EINTR ? ReceiveStatus::empty : ReceiveStatus::error;
  }
  if (n != CAN_MTU && n != CANFD_MTU) {
    last_errno_ = EMSGSIZE;
    return ReceiveStatus::error;
  }
  if ((k.can_id & CAN_ERR_FLAG) != 0) {
    error_frame = true;
    take_error_frame(k.can_id, std::span<const std::uint8_t>{k.data, CAN_ERR_DLC});
    return ReceiveStatus::received;
  }
  frame = CanFrame{};
  from_kernel_id(k.can_id, frame);
  if (n == CANFD_MTU) {
    frame.flags |= can_flag::fd;
    frame.flags |= (k.flags & CANFD_BRS) != 0 ? can_flag::brs : std::uint8_t{0};
    frame.flags |= (k.flags & CANFD_ESI) != 0 ? can_flag::esi : std::uint8_t{0};
    frame.len = k.len <= CANFD_MAX_DLEN ? k.len : std::uint8_t{CANFD_MAX_DLEN};
  } else {
    frame.len = k.len <= CAN_MAX_DLEN ? k.len : std::uint8_t{CAN_MAX_DLEN};
  }
  std::memcpy(frame.data.data(), k.data, frame.len);
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level != SOL_SOCKET) {
      continue;
    }
    if (c->cmsg_type == SO_TIMESTAMP) {
      timeval tv{};
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      frame.timestamp_us = static_cast<std::uint64_t>(tv.tv_sec) * 1'000'000U + static_cast<std::uint64_t>(tv.tv_usec);
    } else if (c->cmsg_type == SO_RXQ_OVFL) {
      std::uint32_t drops = 0;
      std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
      account_kernel_drops(drops);
    }
  }
  return ReceiveStatus::received;
}

BusState bus_state_from_error_frame(std::uint32_t can_id, std::span<const std::uint8_t> data,
                                   BusState before) noexcept {
  if ((can_id & CAN_ERR_BUSOFF) != 0) {
    return BusState::bus_off;
  }
  if ((can_id & CAN_ERR_RESTARTED) != 0) {
    return BusState::error_active;
  }
  if ((can_id & CAN_ERR_CRTL) != 0 && data.size() > 1) {
    const std::uint8_t c = data[1];
    if ((c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
      return BusState::error_passive;
    }
    if ((c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
      return BusState::error_warning;
    }
    if ((c & CAN_ERR_CRTL_ACTIVE) != 0) {
      return BusState::error_active;
    }
  }
  return before;
}

void SocketCanBus::take_error_frame(std::uint32_t can_id, std::span<const std::uint8_t> data) noexcept {
  count_error_frame();
  set_bus_state(bus_state_from_error_frame(can_id, data, bus_state()));
  // The frame says what changed; the driver knows where the controller is now (a restart, say,
  // may already be over). Only on error frames: a netlink round trip is not for every tick.
  if ((can_id & (CAN_ERR_BUSOFF | CAN_ERR_RESTARTED | CAN_ERR_CRTL)) != 0) {
    refresh_controller_state();
  }
}

void SocketCanBus::refresh_controller_state() noexcept {
  if (!controller_known_) {
    has_controller_ = interface_.has_controller();
    controller_known_ = true;
  }
  if (!has_controller_) {
    return;  // no controller to ask: the error frames alone speak
  }
  CanControllerState state{};
  if (interface_.state(state) != ControlStatus::ok) {
    return;
  }
  switch (state) {
    case CanControllerState::error_active: set_bus_state(BusState::error_active); break;
    case CanControllerState::error_warning: set_bus_state(BusState::error_warning); break;
    case CanControllerState::error_passive: set_bus_state(BusState::error_passive); break;
    case CanControllerState::bus_off:
    case CanControllerState::stopped: set_bus_state(BusState::bus_off); break;  // off the bus either way
    case CanControllerState::sleeping:
    case CanControllerState::unknown: break;
  }
}

BusStatus SocketCanBus::do_restart() noexcept {
  if (fd_ < 0) {
    return BusStatus::error;
  }
  const ControlStatus s = interface_.restart();
  if (s == ControlStatus::ok) {
    refresh_controller_state();
    return BusStatus::ok;
  }
  return s == ControlStatus::not_supported ? BusStatus::not_supported : BusStatus::error;
}

void SocketCanBus::refresh_kernel_drops() noexcept {
  // SO_RXQ_OVFL reports drops only with a later frame, so drops after the last queued frame
  // would stay invisible; with the queue drained, read the socket's total instead.
  std::array<std::uint32_t, SK_MEMINFO_VARS> meminfo{};
  socklen_t size = sizeof meminfo;
  if (::getsockopt(fd_, SOL_SOCKET, SO_MEMINFO, meminfo.data(), &size) == 0 &&
      size >= (SK_MEMINFO_DROPS + 1) * sizeof(std::uint32_t)) {
    account_kernel_drops(meminfo[SK_MEMINFO_DROPS]);
  }
}

void SocketCanBus::account_kernel_drops(std::uint32_t total) noexcept {
  // The kernel's count is cumulative and 32-bit; a frame's SO_RXQ_OVFL value is the count when
  // it was queued, which may lag a SO_MEMINFO reading already taken, so only forward steps
  // (modulo 2^32) are counted.
  const std::uint32_t step = total - kernel_drops_;
  if (step != 0 && step < 0x8000'0000U) {
    count_rx_overflow(step);
    kernel_drops_ = total;
  }
}

BusStatus SocketCanBus::do_set_filters(std::span<const CanFilter> filters) noexcept {
  if (filters.size() > max_can_filters) {
    return BusStatus::too_many_filters;
  }
  if (fd_ < 0) {
    return BusStatus::error;
  }
  std::array<can_filter, max_can_filters> k{};
  std::size_t count = filters.size();
  if (count == 0) {
    k[0] = can_filter{0, 0};  // the kernel's "everything"; no filters at all would be "nothing"
    count = 1;
  }
  for (std::size_t i = 0; i < filters.size(); ++i) {
    const CanFilter& f = filters[i];
    k[i].can_id = f.id;
    k[i].can_mask = f.mask;
    if (f.format == FrameFormat::extended) {
      k[i].can_id |= CAN_EFF_FLAG;
    }
    if (f.format != FrameFormat::any) {
      k[i].can_mask |= CAN_EFF_FLAG;
    }
  }
  if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, k.data(), static_cast<socklen_t>(count * sizeof(can_filter))) < 0) {
    last_errno_ = errno;
    return BusStatus::error;
  }
  return BusStatus::ok;
}

const char* to_string(ControlStatus status) noexcept { return enum_text(kControlStatusTexts, status, "?"); }

CanInterface::CanInterface(const char* name) noexcept {
  if (name != nullptr) {
    std::strncpy(name_.data(), name, name_.size() - 1);
  }
}

bool CanInterface::exists() const noexcept { return if_nametoindex(name_.data()) != 0; }

bool CanInterface::has_controller() const noexcept {
  // Only can-dev drivers answer the CAN netlink attributes; vcan has none.
  can_ctrlmode mode{};
  return exists() && can_get_ctrlmode(name_.data(), &mode) == 0;
}

ControlStatus CanInterface::precheck(bool needs_controller) const noexcept {
  if (!exists()) {
    return ControlStatus::no_such_interface;
  }
  if (needs_controller && !has_controller()) {
    return ControlStatus::not_supported;
  }
  return ControlStatus::ok;
}

namespace {
[[nodiscard]] ControlStatus control_result(int rc) noexcept {
  if (rc == 0) {
    return ControlStatus::ok;
  }
  if (errno == EPERM || errno == EACCES) {
    return ControlStatus::permission_denied;
  }
  return errno == EOPNOTSUPP ? ControlStatus::not_supported : ControlStatus::error;
}
}  // namespace

ControlStatus CanInterface::link_up() noexcept {
  if (const ControlStatus s = precheck(false); s != ControlStatus::ok) {
    return s;
  }
  return control_result(can_do_start(name_.data()));
}

ControlStatus CanInterface::link_down() noexcept {
  if (const ControlStatus s = precheck(false); s != ControlStatus::ok) {
    return s;
  }
  return control_result(can_do_stop(name_.data()));
}

ControlStatus CanInterface::restart() noexcept {
  if (const ControlStatus s = precheck(true); s != ControlStatus::ok) {
    return s;
  }
  return control_result(can_do_restart(name_.data()));
}

ControlStatus CanInterface::set_bitrate(std::uint32_t bits_per_second) noexcept {
  if (const ControlStatus s = precheck(true); s != ControlStatus::ok) {
    return s;
  }
  return control_result(can_set_bitrate(name_.data(), bits_per_second));
}

ControlStatus CanInterface::bitrate(std::uint32_t& bits_per_second) const noexcept {
  if (const ControlStatus s = precheck(true); s != ControlStatus::ok) {
    return s;
  }
  can_bittiming bt{};
  const ControlStatus s = control_result(can_get_bittiming(name_.data(), &bt));
  if (s == ControlStatus::ok) {
    bits_per_second = bt.bitrate;
  }
  return s;
}

ControlStatus CanInterface::state(CanControllerState& state) const noexcept {
  if (const ControlStatus s = precheck(true); s != ControlStatus::ok) {
    return s;
  }
  int raw = 0;
  const ControlStatus s = control_result(can_get_state(name_.data(), &raw));
  if (s != ControlStatus::ok) {
    return s;
  }
  switch (raw) {
    case CAN_STATE_ERROR_ACTIVE: state = CanControllerState::error_active; break;
    case CAN_STATE_ERROR_WARNING: state = CanControllerState::error_warning; break;
    case CAN_STATE_ERROR_PASSIVE: state = CanControllerState::error_passive; break;
    case CAN_STATE_BUS_OFF: state = CanControllerState::bus_off; break;
    case CAN_STATE_STOPPED: state = CanControllerState::stopped; break;
    case CAN_STATE_SLEEPING: state = CanControllerState::sleeping; break;
    default: state = CanControllerState::unknown; break;
  }
  return ControlStatus::ok;
}

ControlStatus CanInterface::error_counters(CanErrorCounters& counters) const noexcept {
  if (const ControlStatus s = precheck(true); s != ControlStatus::ok) {
    return s;
  }
  can_berr_counter bc{};
  const ControlStatus s = control_result(can_get_berr_counter(name_.data(), &bc));
  if (s == ControlStatus::ok) {
    counters.tx_errors = bc.txerr;
    counters.rx_errors = bc.rxerr;
  }
  return s;
}

}  // namespace settle::hal
