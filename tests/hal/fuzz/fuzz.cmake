# The libFuzzer harness needs clang (the main build uses g++), so it is compiled by a custom
# command with clang++ and the sanitizers; the brief run is a default test, the long run has
# the fuzz-long label:  ctest -L fuzz-long  (or SETTLE_TEST_LABELS=fuzz-long tools/test).
find_program(SETTLE_CLANGXX NAMES clang++ clang++-14 clang++-15 clang++-16)
set(fuzz_dir ${CMAKE_CURRENT_BINARY_DIR}/fuzz)
if(NOT SETTLE_CLANGXX)
  message(STATUS "hal: clang++ not found; the libFuzzer harness is skipped (apt-get install clang libclang-rt-14-dev)")
  add_test(NAME hal_fuzz_skipped
    COMMAND ${CMAKE_COMMAND} -E echo "hal fuzz harness skipped: clang++ not found (apt-get install clang libclang-rt-14-dev)")
  set_tests_properties(hal_fuzz_skipped PROPERTIES LABELS fuzz)
  return()
endif()

get_target_property(hal_sources settle_hal SOURCES)
list(TRANSFORM hal_sources PREPEND ${PROJECT_SOURCE_DIR}/hal/)
file(GLOB_RECURSE hal_headers ${PROJECT_SOURCE_DIR}/hal/include/*.hpp)
set(fuzz_exe ${fuzz_dir}/hal_fuzz_canopen)
file(MAKE_DIRECTORY ${fuzz_dir}/corpus ${fuzz_dir}/artifacts)
add_custom_command(OUTPUT ${fuzz_exe}
  COMMAND ${SETTLE_CLANGXX} -std=c++20 -O1 -g -fno-exceptions -fno-rtti
          -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
          -Wall -Wextra -Wconversion -Wsign-conversion -Wshadow -Wold-style-cast
          -I${PROJECT_SOURCE_DIR}/hal/include
          ${hal_sources} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_canopen.cpp -o ${fuzz_exe}
  DEPENDS ${hal_sources} ${hal_headers} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_canopen.cpp
  COMMENT "Building the hal libFuzzer harness with clang (ASan + UBSan)"
  VERBATIM)
add_custom_target(hal_fuzz_canopen ALL DEPENDS ${fuzz_exe})

# New inputs go to the build tree's corpus; the committed seeds are read only.
set(fuzz_args -rss_limit_mb=2048 -artifact_prefix=${fuzz_dir}/artifacts/ ${fuzz_dir}/corpus
              ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/seeds)
add_test(NAME hal_fuzz_brief COMMAND ${fuzz_exe} -max_total_time=5 -seed=1 ${fuzz_args})
set_tests_properties(hal_fuzz_brief PROPERTIES LABELS fuzz TIMEOUT 120)
add_test(NAME hal_fuzz_long COMMAND ${fuzz_exe} -max_total_time=900 ${fuzz_args})
set_tests_properties(hal_fuzz_long PROPERTIES LABELS fuzz-long TIMEOUT 1200)
