# SPDX-License-Identifier: Apache-2.0
# Cortex-M4 with its single-precision FPU (mps2-an386 and most motor-control parts): floats run
# in hardware with the hard-float ABI, doubles fall back to libgcc's soft-float routines.
set(SETTLE_ARM_CORE cortex-m4f)
set(SETTLE_ARM_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi.cmake)
