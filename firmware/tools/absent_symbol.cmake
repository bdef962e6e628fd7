# SPDX-License-Identifier: Apache-2.0
# Fails when an archive defines a symbol whose demangled name matches PATTERN (a CMake regex):
# what a board's libraries must leave out stays out.
#   cmake -DNM=<nm> -DARCHIVE=<lib.a> -DPATTERN=<regex> -P absent_symbol.cmake
execute_process(COMMAND ${NM} -g -C --defined-only ${ARCHIVE}
                OUTPUT_VARIABLE listing RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "absent_symbol: ${NM} failed on ${ARCHIVE}")
endif()
string(REPLACE "\n" ";" lines "${listing}")
set(found 0)
foreach(line IN LISTS lines)
  if(line MATCHES "^[0-9a-fA-F]+ [TDBRW] (.+)$")
    set(name "${CMAKE_MATCH_1}")
    if(name MATCHES "${PATTERN}")
      message(SEND_ERROR "absent_symbol: ${ARCHIVE} defines ${name}")
      set(found 1)
    endif()
  endif()
endforeach()
if(NOT found)
  message(STATUS "absent_symbol: nothing in ${ARCHIVE} matches ${PATTERN}")
endif()
