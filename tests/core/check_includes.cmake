# SPDX-License-Identifier: Apache-2.0
cmake_minimum_required(VERSION 3.25)
# Fails if any core source includes a header outside the freestanding-friendly allow list (no
# OS, stream, string, container or thread headers). Run by ctest with -DDIR=<core dir>.
# emmintrin.h: the compiler's own SSE2 intrinsics (no library behind them), included only where
# doubles are SSE2 arithmetic (__SSE2_MATH__: core/src/numeric/complex.hpp).
set(allowed array cmath cstdint cstddef cstring limits type_traits optional variant algorithm utility
            numbers bit concepts climits span emmintrin.h)
file(GLOB_RECURSE sources ${DIR}/*.hpp ${DIR}/*.cpp)
set(bad "")
foreach(src IN LISTS sources)
  file(STRINGS ${src} incs REGEX "^#include <")
  foreach(inc IN LISTS incs)
    string(REGEX REPLACE "^#include <([^>]+)>.*" "\\1" h "${inc}")
    if(NOT h IN_LIST allowed)
      list(APPEND bad "${src}: <${h}>")
    endif()
  endforeach()
endforeach()
if(bad)
  message(FATAL_ERROR "core includes non-freestanding headers:\n${bad}")
endif()
