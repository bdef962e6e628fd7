# SPDX-License-Identifier: Apache-2.0
# Builds examples/core_plan without CMake: the compiler and `pkg-config settle-core` from the prefix.
#   cmake -DPREFIX=<prefix> -DLIBDIR=<lib dir name> -DCXX=<compiler> [-DFLAGS=<the build's flags>]
#         -DSOURCE=<main.cpp> -DOUT=<exe> -P pkg_config.cmake
find_program(PKG_CONFIG pkg-config REQUIRED)
set(ENV{PKG_CONFIG_PATH} ${PREFIX}/${LIBDIR}/pkgconfig)
execute_process(COMMAND ${PKG_CONFIG} --cflags --libs settle-core RESULT_VARIABLE status
                OUTPUT_VARIABLE flags ERROR_VARIABLE err OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "pkg-config settle-core failed: ${err}")
endif()
message(STATUS "pkg-config --cflags --libs settle-core: ${flags}")
separate_arguments(flags UNIX_COMMAND "${flags}")
separate_arguments(build_flags UNIX_COMMAND "${FLAGS}")  # e.g. an ASan tree's -fsanitize
execute_process(COMMAND ${CXX} -std=c++20 ${build_flags} ${SOURCE} ${flags} -o ${OUT} RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "compiling with pkg-config's flags failed:\n${err}")
endif()
execute_process(COMMAND ${OUT} RESULT_VARIABLE status OUTPUT_VARIABLE out)
if(NOT status EQUAL 0 OR NOT out MATCHES "t 0.6000 s  p 0.050000 m")
  message(FATAL_ERROR "${OUT} failed (${status}):\n${out}")
endif()
message(STATUS "${out}")
