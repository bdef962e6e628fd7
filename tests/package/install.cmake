# SPDX-License-Identifier: Apache-2.0
# Installs the build tree (already built: nothing is rebuilt) into a fresh prefix.
#   cmake -DBUILD=<build tree> -DPREFIX=<prefix> -P install.cmake
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${PREFIX}
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "cmake --install ${BUILD} failed:\n${out}\n${err}")
endif()
message(STATUS "installed ${BUILD} into ${PREFIX}")
