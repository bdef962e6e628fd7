# SPDX-License-Identifier: Apache-2.0
# Cortex-M0 (ARMv6-M, nRF51 on the micro:bit): no FPU and no hardware divide, so float maths is
# all libgcc soft-float; this is the target the fixed-point evaluators exist for.
set(SETTLE_ARM_CORE cortex-m0)
set(SETTLE_ARM_CPU_FLAGS "-mcpu=cortex-m0 -mthumb -mfloat-abi=soft")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi.cmake)
