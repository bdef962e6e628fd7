// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the Cortex-M board runtime (startup, vector table, no-heap C/C++ support) offers an image:
// the entry point it calls after reset, the fatal-error exit and the stack high-water mark.

#include <cstddef>
#include <string_view>

namespace settle::firmware {

// Defined by each image; called once .data and .bss are set up and static constructors have run.
// Its return value becomes QEMU's exit status (through semihosting).
int image_main();

// Reports `what` on the host console and ends the emulation with `status` (never 0).
[[noreturn]] void fatal(std::string_view what, int status);

// Bytes of the main stack that have ever been written since reset: the startup code paints the
// stack with a pattern, this finds the deepest unpainted word. Complements -fstack-usage, which
// cannot see through calls into libgcc/libm or indirect calls.
[[nodiscard]] std::size_t stack_high_water();
[[nodiscard]] std::size_t stack_size();

}  // namespace settle::firmware
