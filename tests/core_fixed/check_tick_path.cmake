# SPDX-License-Identifier: Apache-2.0
cmake_minimum_required(VERSION 3.25)
# The fixed-point tick path compiled for a Cortex-M0 (no FPU, no divide instruction) may call
# nothing but integer helpers: 64-bit multiply and shifts, memcpy/memset, and itself. Any float
# routine (__aeabi_d*, __aeabi_f*), division (__aeabi_*div*, *mod*) or libm call fails the test.
# Run by ctest with -DCXX=<arm-none-eabi-g++> -DNM=<arm-none-eabi-nm> -DCORE=<core dir> -DOUT=<dir>.
set(sources motion_eval.cpp position_eval.cpp poly.cpp trig.cpp cam_eval.cpp)
set(allowed "^_ZN6settle" "^__aeabi_lmul$" "^__aeabi_ll(sl|sr)$" "^__aeabi_lasr$" "^__aeabi_u?lcmp$"
            "^memcpy$" "^memset$" "^memmove$" "^__aeabi_mem(cpy|set|clr|move)[48]?$")
file(MAKE_DIRECTORY ${OUT})
set(bad "")
foreach(src IN LISTS sources)
  set(obj ${OUT}/${src}.o)
  execute_process(
    COMMAND ${CXX} -mcpu=cortex-m0 -mthumb -mfloat-abi=soft -O2 -std=c++20 -fno-exceptions -fno-rtti
            -ffunction-sections -I${CORE}/include -c ${CORE}/src/fixed/${src} -o ${obj}
    RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "compiling ${src} for Cortex-M0 failed:\n${err}")
  endif()
  execute_process(COMMAND ${NM} -u ${obj} OUTPUT_VARIABLE undefined)
  string(REPLACE "\n" ";" lines "${undefined}")
  foreach(line IN LISTS lines)
    string(REGEX REPLACE "^ *U " "" sym "${line}")
    if(sym STREQUAL "")
      continue()
    endif()
    set(ok FALSE)
    foreach(pattern IN LISTS allowed)
      if(sym MATCHES "${pattern}")
        set(ok TRUE)
      endif()
    endforeach()
    if(NOT ok)
      list(APPEND bad "${src}: ${sym}")
    endif()
  endforeach()
endforeach()
if(bad)
  message(FATAL_ERROR "the fixed-point tick path calls non-integer or division helpers on Cortex-M0:\n${bad}")
endif()
message(STATUS "fixed-point tick path on Cortex-M0: integer helpers only")
