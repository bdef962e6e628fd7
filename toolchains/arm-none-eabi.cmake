# SPDX-License-Identifier: Apache-2.0
# Base toolchain for bare-metal Arm (GNU Arm Embedded + newlib). Per-core files set
# SETTLE_ARM_CORE and SETTLE_ARM_CPU_FLAGS and then include this one; it is not meant to be used
# on its own (it would build for the compiler's default architecture, which matches no board).
if(NOT SETTLE_ARM_CPU_FLAGS)
  message(FATAL_ERROR "arm-none-eabi.cmake is a base: use cortex-m4f.cmake or cortex-m0.cmake")
endif()

set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
# firmware/ reads this to decide which boards can be built (e.g. cortex-m4f -> mps2-an386).
set(SETTLE_ARM_CORE "${SETTLE_ARM_CORE}" CACHE STRING "Cortex-M core the images are built for" FORCE)

set(SETTLE_ARM_TRIPLE arm-none-eabi)
find_program(SETTLE_ARM_GCC ${SETTLE_ARM_TRIPLE}-gcc REQUIRED)
get_filename_component(_settle_arm_bin ${SETTLE_ARM_GCC} DIRECTORY)
set(CMAKE_C_COMPILER ${_settle_arm_bin}/${SETTLE_ARM_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER ${_settle_arm_bin}/${SETTLE_ARM_TRIPLE}-g++)
set(CMAKE_ASM_COMPILER ${_settle_arm_bin}/${SETTLE_ARM_TRIPLE}-gcc)
set(CMAKE_OBJCOPY ${_settle_arm_bin}/${SETTLE_ARM_TRIPLE}-objcopy CACHE FILEPATH "")
set(CMAKE_SIZE ${_settle_arm_bin}/${SETTLE_ARM_TRIPLE}-size CACHE FILEPATH "")

# There is no way to run a test executable without a board, and linking one needs a startup file
# and a linker script; so CMake's compiler checks build a static library instead.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# newlib lives where the compiler already looks (Debian: /usr/lib/arm-none-eabi, headers in
# /usr/include/newlib), so no --sysroot is passed; find_* is confined to that tree so that no
# host library or package can be picked up by mistake.
# Prefixes given in CMAKE_PREFIX_PATH hold packages built for this target (settle's own:
# `cmake --install build/cortex-m4f --prefix <p>`), so they are roots too.
set(CMAKE_FIND_ROOT_PATH /usr/lib/${SETTLE_ARM_TRIPLE} ${CMAKE_PREFIX_PATH})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# Sections per function and datum so --gc-sections drops what the image does not call; this is
# also what lets firmware's no-heap poison stay out of the image unless something allocates.
# -fstack-usage and -fcallgraph-info=su write a .su and a .ci file (frame sizes, call edges) next
# to every object, which firmware/tools/stack-report turns into per-function and per-path stack.
# nano.specs at compile time too: it selects newlib-nano's configuration headers.
set(_settle_arm_common
    "${SETTLE_ARM_CPU_FLAGS} --specs=nano.specs -ffunction-sections -fdata-sections -fstack-usage -fcallgraph-info=su")
set(CMAKE_C_FLAGS_INIT "${_settle_arm_common}")
set(CMAKE_CXX_FLAGS_INIT
    "${_settle_arm_common} -fno-exceptions -fno-rtti -fno-threadsafe-statics")
set(CMAKE_ASM_FLAGS_INIT "${SETTLE_ARM_CPU_FLAGS}")
# The compile flags above reach the link line too (so nano.specs selects newlib-nano, the small
# libc that provides memcpy and libm's sinf). No crt0: firmware has its own startup; and no
# libnosys, so nothing can quietly get an _sbrk.
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "-nostartfiles -Wl,--gc-sections")
