# SPDX-License-Identifier: Apache-2.0
# One place for the warning set, so every target of the project is held to the same bar.
# -Wconversion is on: fixed-point and count conversions are where silent narrowing bites.
set(SETTLE_CXX_WARNINGS
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wold-style-cast
  -Wnon-virtual-dtor -Wdouble-promotion)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # GCC 12 reports false -Wrestrict on std::string concatenation (GCC PR105329).
  list(APPEND SETTLE_CXX_WARNINGS -Wno-restrict)
endif()

function(settle_warnings target)
  target_compile_options(${target} PRIVATE "$<$<COMPILE_LANGUAGE:CXX>:${SETTLE_CXX_WARNINGS}>")
endfunction()

# Freestanding discipline for code that must run inside the servo loop on any target.
function(settle_freestanding target)
  target_compile_options(${target} PRIVATE "$<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions;-fno-rtti;-fno-threadsafe-statics>")
endfunction()

# Settle's own build flag for code that uses hal's polymorphic types (hal/CMakeLists.txt): PRIVATE,
# so it never reaches a consumer of the installed package.
function(settle_no_rtti target)
  target_compile_options(${target} PRIVATE "$<$<COMPILE_LANGUAGE:CXX>:-fno-rtti>")
endfunction()
