# SPDX-License-Identifier: Apache-2.0
# cmake -DSOURCE_DIR=<hal> -DLIBS=<a;b> -DNM=<nm> -P check_freestanding.cmake
# settle_hal and settle_hal_testing must cross-compile for bare metal unchanged: no OS or
# hosted-library headers in their sources, and no heap, exception or RTTI symbols in their
# objects. (Deleting destructors name operator delete; the firmware runtime defines it.)
set(forbidden_headers
  "<string>" "<vector>" "<map>" "<memory>" "<iostream>" "<sstream>" "<fstream>" "<chrono>"
  "<functional>" "<thread>" "<mutex>" "<stdexcept>" "<exception>" "<cstdio>" "<cstdlib>"
  "<stdio.h>" "<stdlib.h>" "<unistd.h>" "<sys/" "<linux/" "<net/" "<poll.h>" "<libsocketcan.h>")
file(GLOB_RECURSE sources
  ${SOURCE_DIR}/include/*.hpp ${SOURCE_DIR}/src/*.cpp ${SOURCE_DIR}/testing/*.hpp ${SOURCE_DIR}/testing/*.cpp)
set(failures "")
foreach(source IN LISTS sources)
  get_filename_component(name ${source} NAME)
  if(name STREQUAL "socketcan.cpp" OR name STREQUAL "socketcan_bus.hpp" OR name STREQUAL "candump_file.cpp"
     OR name STREQUAL "candump_file.hpp" OR name STREQUAL "eds_reader.cpp" OR name STREQUAL "eds_reader.hpp"
     OR name STREQUAL "eds_drive_config.cpp" OR name STREQUAL "eds_drive_config.hpp"
     OR name STREQUAL "eds_semantics.cpp" OR name STREQUAL "eds_semantics.hpp"
     OR name STREQUAL "bus_capture.cpp" OR name STREQUAL "bus_capture.hpp")
    # The host-only libraries: the Linux adapters (settle_hal_socketcan), the one place OS headers
    # belong, and the EDS/DCF reader and the start-up configuration built from it (settle_hal_eds:
    # files, strings).
    continue()
  endif()
  file(STRINGS ${source} includes REGEX "^#include")
  foreach(line IN LISTS includes)
    foreach(header IN LISTS forbidden_headers)
      string(FIND "${line}" "${header}" at)
      if(NOT at EQUAL -1)
        list(APPEND failures "${source}: ${line}")
      endif()
    endforeach()
  endforeach()
endforeach()

foreach(lib IN LISTS LIBS)
  execute_process(COMMAND ${NM} --undefined-only --demangle ${lib} OUTPUT_VARIABLE symbols RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    list(APPEND failures "${NM} failed on ${lib}")
  endif()
  string(REPLACE "\n" ";" symbols "${symbols}")
  foreach(symbol IN LISTS symbols)
    if(symbol MATCHES "malloc|calloc|realloc| free$|operator new|__cxa_throw|__cxa_allocate_exception|__throw_|typeinfo|__cxa_guard|__cxa_atexit")
      list(APPEND failures "${lib}: needs ${symbol}")
    endif()
  endforeach()
endforeach()

if(failures)
  list(JOIN failures "\n  " text)
  message(FATAL_ERROR "hal is not freestanding:\n  ${text}")
endif()
message(STATUS "hal: sources and objects are freestanding")
