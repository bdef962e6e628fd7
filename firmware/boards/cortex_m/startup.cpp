// SPDX-License-Identifier: Apache-2.0
// Reset, vector table and exception handlers shared by the Cortex-M boards (ARMv6-M and ARMv7E-M):
// set up .data/.bss, paint the stack, run static constructors, call the image, exit through
// semihosting. Any unexpected exception ends the emulation with a message instead of hanging.
#include <cstdint>

#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/firmware/text.hpp"

// Symbols of the linker script (boards/cortex_m/sections.ld).
extern "C" {
extern std::uint32_t __data_load[];
extern std::uint32_t __data_start[];
extern std::uint32_t __data_end[];
extern std::uint32_t __bss_start[];
extern std::uint32_t __bss_end[];
extern std::uint32_t __stack_bottom[];
extern std::uint32_t __stack_top[];
using InitFunction = void (*)();
extern InitFunction __init_array_start[];
extern InitFunction __init_array_end[];

void settle_reset_handler() noexcept;
void settle_default_handler() noexcept;
[[noreturn]] void settle_startup();
[[noreturn]] void settle_fault_report(const std::uint32_t* frame, std::uint32_t exception);

// Images and libraries override these by defining a function of the same name.
void settle_nmi_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
void settle_hardfault_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
void settle_memmanage_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
void settle_busfault_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
void settle_usagefault_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
void settle_svcall_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
void settle_debugmon_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
void settle_pendsv_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
void settle_systick_handler() noexcept __attribute__((weak, alias("settle_default_handler")));
}

namespace settle::firmware {
namespace {

using Handler = void (*)();

// Both boards have 32 external interrupts; none is enabled yet, so all go to the default.
constexpr std::size_t external_interrupts{32};

struct VectorTable {
  std::uint32_t* initial_stack;
  Handler system[15];
  Handler external[external_interrupts];
};

constexpr VectorTable make_vector_table() {
  VectorTable table{.initial_stack = __stack_top,
                    .system = {settle_reset_handler, settle_nmi_handler, settle_hardfault_handler,
                               settle_memmanage_handler, settle_busfault_handler,
                               settle_usagefault_handler, nullptr, nullptr, nullptr, nullptr,
                               settle_svcall_handler, settle_debugmon_handler, nullptr,
                               settle_pendsv_handler, settle_systick_handler},
                    .external = {}};
  for (Handler& handler : table.external) {
    handler = settle_default_handler;
  }
  return table;
}

// Placed at the start of flash by the linker script; the core reads SP and PC from it at reset.
[[gnu::section(".settle_vectors"), gnu::used]] constinit const VectorTable vector_table{
    make_vector_table()};

// Recognisable and unlikely as data, so the high-water scan does not stop early by chance.
constexpr std::uint32_t stack_paint{0x5E77'1E57};
// Left unpainted under the live frame of settle_startup while painting.
constexpr std::uintptr_t paint_margin{256};

}  // namespace

std::size_t stack_size() {
  return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(__stack_top) -
                                  reinterpret_cast<std::uintptr_t>(__stack_bottom));
}

std::size_t stack_high_water() {
  const std::uint32_t* word{__stack_bottom};
  while (word < __stack_top && *word == stack_paint) {
    ++word;
  }
  return static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(__stack_top) -
                                  reinterpret_cast<std::uintptr_t>(word));
}

void fatal(std::string_view what, int status) {
  static_cast<void>(semihosting::write_console(what));
  semihosting::exit(status == 0 ? 1 : status);
}

}  // namespace settle::firmware

// Naked: the FPU must be on before any compiled code can touch an FP register, and on ARMv6-M a
// plain B cannot reach far, hence the register branch.
extern "C" [[gnu::naked]] void settle_reset_handler() noexcept {
#if defined(__ARM_FP)
  asm volatile(
      "ldr r0, =0xE000ED88\n"  // CPACR: full access to CP10 and CP11
      "ldr r1, [r0]\n"
      "ldr r2, =0x00F00000\n"
      "orrs r1, r1, r2\n"
      "str r1, [r0]\n"
      "dsb\n"
      "isb\n"
      "ldr r0, =settle_startup\n"
      "bx r0\n"
      ".ltorg\n");
#else
  asm volatile(
      "ldr r0, =settle_startup\n"
      "bx r0\n"
      ".ltorg\n");
#endif
}

extern "C" void settle_startup() {
  const std::uint32_t* source{__data_load};
  for (std::uint32_t* target{__data_start}; target < __data_end; ++target, ++source) {
    *target = *source;
  }
  for (std::uint32_t* target{__bss_start}; target < __bss_end; ++target) {
    *target = 0;
  }

  const auto live{reinterpret_cast<std::uintptr_t>(__builtin_frame_address(0))};
  for (std::uint32_t* word{__stack_bottom};
       reinterpret_cast<std::uintptr_t>(word) + settle::firmware::paint_margin < live; ++word) {
    *word = settle::firmware::stack_paint;
  }

  for (InitFunction* init{__init_array_start}; init < __init_array_end; ++init) {
    (*init)();
  }
  settle::firmware::semihosting::exit(settle::firmware::image_main());
}

// Hands the exception frame (on the main stack: nothing here uses the process stack) to C++.
extern "C" [[gnu::naked]] void settle_default_handler() noexcept {
  asm volatile(
      "mrs r0, msp\n"
      "mrs r1, ipsr\n"
      "ldr r2, =settle_fault_report\n"
      "bx r2\n"
      ".ltorg\n");
}

extern "C" void settle_fault_report(const std::uint32_t* frame, std::uint32_t exception) {
  // The hardware stacks r0-r3, r12, lr, pc, xpsr; the faulting pc is the seventh word.
  settle::firmware::Text<80> message{};
  message.append("settle: unexpected exception ")
      .append_unsigned(exception & 0x1FFU)
      .append(" at pc 0x")
      .append_hex(frame[6], 8)
      .append("\n");
  settle::firmware::fatal(message.view(), 128 + static_cast<int>(exception & 0x7FU));
}
