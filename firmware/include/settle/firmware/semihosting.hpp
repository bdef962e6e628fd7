// SPDX-License-Identifier: Apache-2.0
#pragma once
// ARM semihosting, freestanding: lets an image running under a debugger or QEMU
// (`-semihosting-config enable=on,target=native`) write files on the host and exit with a status.
// Only meaningful with a host attached: on a bare board the BKPT traps into HardFault.

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace settle::firmware::semihosting {

// SYS_OPEN's mode numbers are the index of an fopen() mode string in this order.
enum class OpenMode : std::uint32_t {
  read = 0,
  read_binary = 1,
  write = 4,
  write_binary = 5,
  append = 8,
  append_binary = 9,
};

// A host file opened through SYS_OPEN; closed by its destructor. Move-only, never allocates.
class File {
 public:
  File() = default;
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  File(File&& other) noexcept : handle_{other.handle_} { other.handle_ = invalid_handle; }
  File& operator=(File&& other) noexcept;
  ~File();

  // The path is relative to QEMU's working directory; ":tt" is the host console.
  [[nodiscard]] static File open(std::string_view path, OpenMode mode);
  [[nodiscard]] bool is_open() const { return handle_ != invalid_handle; }
  // True when every byte was written.
  [[nodiscard]] bool write(const void* data, std::size_t size);
  [[nodiscard]] bool write(std::string_view text) { return write(text.data(), text.size()); }
  [[nodiscard]] bool close();

 private:
  static constexpr std::int32_t invalid_handle{-1};
  explicit File(std::int32_t handle) : handle_{handle} {}
  std::int32_t handle_{invalid_handle};
};

// Writes to the host console (QEMU's stdout), opening it on first use.
[[nodiscard]] bool write_console(std::string_view text);

// Ends the emulation; QEMU exits with `status` as its own exit code (SYS_EXIT_EXTENDED).
[[noreturn]] void exit(int status);

}  // namespace settle::firmware::semihosting
