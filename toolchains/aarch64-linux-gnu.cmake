# SPDX-License-Identifier: Apache-2.0
# 64-bit Arm Linux (embedded Linux drives), Debian's cross g++ and multiarch sysroot. Test
# executables run through qemu-aarch64 user mode, so ctest works on an x86-64 host as is.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

set(SETTLE_AARCH64_TRIPLE aarch64-linux-gnu)
set(CMAKE_C_COMPILER ${SETTLE_AARCH64_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER ${SETTLE_AARCH64_TRIPLE}-g++)

# Debian installs the target's libc and libstdc++ under /usr/aarch64-linux-gnu.
set(SETTLE_AARCH64_SYSROOT /usr/${SETTLE_AARCH64_TRIPLE})
set(CMAKE_FIND_ROOT_PATH ${SETTLE_AARCH64_SYSROOT})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# -L tells qemu where the target's dynamic loader and shared libraries are.
find_program(SETTLE_QEMU_AARCH64 qemu-aarch64 REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR ${SETTLE_QEMU_AARCH64} -L ${SETTLE_AARCH64_SYSROOT})

# GoogleTest has no Debian aarch64 build, but libgtest-dev ships its sources: tests/ compiles
# them with this toolchain when this is set (the sources are the same version as the host's).
if(EXISTS /usr/src/googletest/CMakeLists.txt)
  set(SETTLE_GTEST_SOURCE_DIR /usr/src/googletest CACHE PATH "GoogleTest sources to build for the target")
endif()
