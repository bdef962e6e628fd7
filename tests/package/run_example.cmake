# SPDX-License-Identifier: Apache-2.0
# Configures and builds one example (or consumer) project against an installed settle, and runs
# what it built. Fails on the first step that fails, with that step's output.
#   cmake -DSOURCE=<project> -DBINARY=<build dir> -DPREFIX=<settle prefix> -DGENERATOR=<gen>
#         [-DCONFIGURE_ARGS=a;b] [-DRUN=<program relative to BINARY>;args...]
#         [-DEXPECT=<regex the run's output must match>] [-DEXPECT_EXIT=<status, default 0>]
#         [-DEXPECT_CONFIGURE_ERROR=<regex>]   (the configure must fail with this message instead)
#         [-DNO_BUILD=ON]                      (configure only)
#         -P run_example.cmake
foreach(var SOURCE BINARY PREFIX GENERATOR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_example.cmake: ${var} is required")
  endif()
endforeach()

# Lists arrive from add_test with escaped separators ("a\;b"): make them lists again.
foreach(var CONFIGURE_ARGS RUN)
  string(REPLACE "\\;" ";" ${var} "${${var}}")
endforeach()

file(REMOVE_RECURSE ${BINARY})
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE} -B ${BINARY} -G ${GENERATOR}
                        -DCMAKE_PREFIX_PATH=${PREFIX} ${CONFIGURE_ARGS}
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(DEFINED EXPECT_CONFIGURE_ERROR)
  if(status EQUAL 0)
    message(FATAL_ERROR "configuring ${SOURCE} succeeded; expected it to fail with '${EXPECT_CONFIGURE_ERROR}'")
  endif()
  if(NOT err MATCHES "${EXPECT_CONFIGURE_ERROR}")
    message(FATAL_ERROR "configuring ${SOURCE} failed without '${EXPECT_CONFIGURE_ERROR}':\n${err}")
  endif()
  message(STATUS "configure failed as expected:\n${err}")
  return()
endif()
if(NOT status EQUAL 0)
  message(FATAL_ERROR "configuring ${SOURCE} failed:\n${out}\n${err}")
endif()
if(NO_BUILD)
  message(STATUS "configured ${SOURCE}")
  return()
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BINARY}
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "building ${SOURCE} failed:\n${out}\n${err}")
endif()
message(STATUS "built ${SOURCE} against ${PREFIX}")
if(NOT DEFINED RUN)
  return()
endif()
list(POP_FRONT RUN program)
if(NOT IS_ABSOLUTE ${program})
  set(program ${BINARY}/${program})
endif()
execute_process(COMMAND ${program} ${RUN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${program} ${RUN} exited with ${status}:\n${out}${err}")
if(NOT DEFINED EXPECT_EXIT)
  set(EXPECT_EXIT 0)
endif()
if(NOT status STREQUAL EXPECT_EXIT)
  message(FATAL_ERROR "expected exit status ${EXPECT_EXIT}")
endif()
if(DEFINED EXPECT AND NOT "${out}${err}" MATCHES "${EXPECT}")
  message(FATAL_ERROR "the output does not match '${EXPECT}'")
endif()
