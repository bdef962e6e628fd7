// SPDX-License-Identifier: Apache-2.0
// ARM semihosting calls (the "Semihosting for AArch32 and AArch64" interface): operation number
// in r0, pointer to an argument block in r1, BKPT 0xAB on M-profile; the host answers in r0.
#include "settle/firmware/semihosting.hpp"

#include <array>

namespace settle::firmware::semihosting {
namespace {

enum class Op : std::uint32_t {
  open = 0x01,
  close = 0x02,
  write = 0x05,
  exit_extended = 0x20,
};

// SYS_EXIT's reason code for a normal application exit; the subcode then carries the status.
constexpr std::uintptr_t adp_stopped_application_exit{0x20026};

std::int32_t call(Op op, const void* args) {
  std::uint32_t result{};
  // "memory": the host reads the argument block and may write guest memory.
  asm volatile(
      "mov r0, %[op]\n"
      "mov r1, %[args]\n"
      "bkpt 0xab\n"
      "mov %[result], r0\n"
      : [result] "=r"(result)
      : [op] "r"(static_cast<std::uint32_t>(op)), [args] "r"(args)
      : "r0", "r1", "memory");
  return static_cast<std::int32_t>(result);
}

std::uintptr_t word(const void* pointer) { return reinterpret_cast<std::uintptr_t>(pointer); }

}  // namespace

File& File::operator=(File&& other) noexcept {
  if (this != &other) {
    static_cast<void>(close());
    handle_ = other.handle_;
    other.handle_ = invalid_handle;
  }
  return *this;
}

File::~File() { static_cast<void>(close()); }

File File::open(std::string_view path, OpenMode mode) {
  // SYS_OPEN wants a NUL-terminated name plus its length without the NUL; a string_view has no
  // terminator, hence the bounded copy.
  std::array<char, 128> name{};
  if (path.size() >= name.size()) {
    return File{};
  }
  path.copy(name.data(), path.size());
  const std::array<std::uintptr_t, 3> args{word(name.data()), static_cast<std::uintptr_t>(mode),
                                           path.size()};
  const std::int32_t handle{call(Op::open, args.data())};
  return handle < 0 ? File{} : File{handle};
}

bool File::write(const void* data, std::size_t size) {
  if (!is_open()) {
    return false;
  }
  const std::array<std::uintptr_t, 3> args{static_cast<std::uintptr_t>(handle_), word(data), size};
  // SYS_WRITE returns the number of bytes NOT written.
  return call(Op::write, args.data()) == 0;
}

bool File::close() {
  if (!is_open()) {
    return true;
  }
  const std::array<std::uintptr_t, 1> args{static_cast<std::uintptr_t>(handle_)};
  handle_ = invalid_handle;
  return call(Op::close, args.data()) == 0;
}

bool write_console(std::string_view text) {
  // Function-local so that images which never print do not open the console.
  static File console{File::open(":tt", OpenMode::write)};
  return console.write(text);
}

void exit(int status) {
  const std::array<std::uintptr_t, 2> args{adp_stopped_application_exit,
                                           static_cast<std::uintptr_t>(status)};
  static_cast<void>(call(Op::exit_extended, args.data()));
  // Only reached without a semihosting host; there is nowhere to return to.
  for (;;) {
    asm volatile("bkpt 0");
  }
}

}  // namespace settle::firmware::semihosting
