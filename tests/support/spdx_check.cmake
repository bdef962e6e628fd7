# SPDX-License-Identifier: Apache-2.0
# Every source file of Settle's names its licence (LICENSE, Apache-2.0) in an SPDX line within
# its first three lines. cmake -DROOT=<source tree> -P spdx_check.cmake
file(GLOB_RECURSE files RELATIVE ${ROOT} ${ROOT}/*.cpp ${ROOT}/*.hpp ${ROOT}/*.h ${ROOT}/*.c
     ${ROOT}/*CMakeLists.txt ${ROOT}/*.cmake ${ROOT}/*.py)
set(missing)
set(count 0)
foreach(f IN LISTS files)
  if(f MATCHES "^(build|\\.git)/")
    continue()
  endif()
  math(EXPR count "${count} + 1")
  file(STRINGS ${ROOT}/${f} head LIMIT_COUNT 3)
  if(NOT head MATCHES "SPDX-License-Identifier: Apache-2\\.0")
    list(APPEND missing ${f})
  endif()
endforeach()
if(missing)
  list(JOIN missing "\n  " text)
  message(FATAL_ERROR "source files without 'SPDX-License-Identifier: Apache-2.0':\n  ${text}")
endif()
message(STATUS "${count} source files, each with its SPDX licence line")
