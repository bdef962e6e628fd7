# SPDX-License-Identifier: Apache-2.0
# The library-only configure the examples guide documents: Settle's libraries, headers and CMake
# package, without the test suites, fuzzers, benchmarks, simulator, CLI, Python module or images.
# Configures the source tree into a fresh build tree, fails if any test, fuzz or benchmark target
# exists there, then builds and installs it and checks what was installed.
#   cmake -DSOURCE=<settle source> -DBINARY=<build dir> -DPREFIX=<prefix> -DGENERATOR=<gen>
#         [-DLAUNCHER=<compiler launcher>] [-DCXX=<compiler>] -P library_only.cmake
cmake_policy(SET CMP0057 NEW)  # if(IN_LIST) in a -P script
file(REMOVE_RECURSE ${BINARY} ${PREFIX})
set(args -DSETTLE_BUILD_TESTS=OFF -DSETTLE_BUILD_BENCH=OFF -DSETTLE_BUILD_SIM=OFF -DSETTLE_BUILD_PYTHON=OFF
    -DSETTLE_BUILD_IMAGES=OFF -DCMAKE_BUILD_TYPE=Release)
if(LAUNCHER)
  list(APPEND args -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER} -DCMAKE_C_COMPILER_LAUNCHER=${LAUNCHER}
       -DCMAKE_POSITION_INDEPENDENT_CODE=ON)
endif()
if(CXX)
  list(APPEND args -DCMAKE_CXX_COMPILER=${CXX})
endif()
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${what} failed:\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

run("configure" ${CMAKE_COMMAND} -S ${SOURCE} -B ${BINARY} -G ${GENERATOR} ${args})
run("listing the targets" ${CMAKE_COMMAND} --build ${BINARY} --target help)
string(REGEX MATCHALL "[^\n: ]*(test|fuzz|bench|gtest|python)[^\n: ]*" found "${out}")
# Not suites: ctest's phony "test" targets (one per directory) and hal's installed test double
# library (settle::hal_testing, part of the hal component).
list(FILTER found EXCLUDE REGEX "(^|/)test$|hal_testing")
if(found)
  message(FATAL_ERROR "the library-only configure has test, fuzz, benchmark or Python targets: ${found}")
endif()
string(REGEX MATCHALL "settle[a-z_]*" libraries "${out}")
foreach(expected settle_core settle_hal settle_runtime)
  if(NOT expected IN_LIST libraries)
    message(FATAL_ERROR "the library-only configure lacks ${expected}; it has: ${libraries}")
  endif()
endforeach()
run("build" ${CMAKE_COMMAND} --build ${BINARY})
run("install" ${CMAKE_COMMAND} --install ${BINARY} --prefix ${PREFIX})
file(GLOB_RECURSE config ${PREFIX}/*/settleConfig.cmake)
if(NOT config OR NOT EXISTS ${PREFIX}/include/settle/core/planner.hpp)
  message(FATAL_ERROR "the library-only install has no CMake package or no headers under ${PREFIX}")
endif()
message(STATUS "library-only: configured, built and installed into ${PREFIX} (${libraries})")
