# SPDX-License-Identifier: Apache-2.0
# Writes a compiler response file with `-Wl,-u,<symbol>` for every external definition in an
# archive, so an image can be linked with all of a library kept despite --gc-sections.
#   cmake -DNM=<nm> -DARCHIVE=<lib.a> -DOUTPUT=<file.rsp> -P force_symbols.cmake
execute_process(COMMAND ${NM} -g --defined-only ${ARCHIVE}
                OUTPUT_VARIABLE listing RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "force_symbols: ${NM} failed on ${ARCHIVE}")
endif()
string(REPLACE "\n" ";" lines "${listing}")
set(options "")
foreach(line IN LISTS lines)
  # "<address> <type> <symbol>": code (T), data (D, B) and read-only data (R).
  if(line MATCHES "^[0-9a-fA-F]+ [TDBR] (.+)$")
    string(APPEND options "-Wl,-u,${CMAKE_MATCH_1}\n")
  endif()
endforeach()
file(WRITE ${OUTPUT}.tmp "${options}")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
