# SPDX-License-Identifier: Apache-2.0
# The libFuzzer harnesses need clang (the main build uses g++), so they are compiled by custom
# commands with clang++ and the sanitizers; the brief runs are default tests (label fuzz), the
# long runs have the fuzz-long label:  ctest -L fuzz-long  (or SETTLE_TEST_LABELS=fuzz-long tools/test).
#   hal_fuzz_canopen  every decoder, the SDO server, the drive node and the master, frame by frame
#   hal_fuzz_servo    the master against the drive through the fault-injecting bus (fuzz_servo.cpp)
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

# ---- The master-vs-drive harness (fuzz_servo.cpp): ServoLoop + RemoteDrive against DriveNode and
# an ideal plant through the fault-injecting bus, with invariants on every tick. It needs core and
# runtime too, so its sources are compiled one object each (ccache-able, rebuilt only when
# they change), instrumented for the fuzzer, and linked with libFuzzer's main.
set(servo_fuzz_dir ${fuzz_dir}/servo)
set(servo_fuzz_exe ${servo_fuzz_dir}/hal_fuzz_servo)
set(servo_fuzz_flags -std=c++20 -O1 -g -fno-exceptions -fno-rtti -ffp-contract=off
    -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined)
set(servo_fuzz_includes -I${PROJECT_SOURCE_DIR}/core/include -I${PROJECT_SOURCE_DIR}/hal/include
    -I${PROJECT_SOURCE_DIR}/hal/testing/include -I${PROJECT_SOURCE_DIR}/runtime/include)
set(servo_fuzz_sources)
foreach(lib_dir IN ITEMS "settle_core;core" "settle_hal;hal" "settle_hal_testing;hal" "settle_runtime;runtime")
  list(GET lib_dir 0 lib)
  list(GET lib_dir 1 dir)
  get_target_property(lib_sources ${lib} SOURCES)
  foreach(src IN LISTS lib_sources)
    if(NOT IS_ABSOLUTE ${src})
      set(src ${PROJECT_SOURCE_DIR}/${dir}/${src})
    endif()
    list(APPEND servo_fuzz_sources ${src})
  endforeach()
endforeach()
list(APPEND servo_fuzz_sources ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_servo.cpp)
set(servo_fuzz_objects)
foreach(src IN LISTS servo_fuzz_sources)
  file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${src})
  string(REPLACE "/" "_" obj_name ${rel})
  set(obj ${servo_fuzz_dir}/obj/${obj_name}.o)
  set(warnings -w)
  if(src MATCHES "fuzz_servo.cpp$")
    set(warnings -Wall -Wextra -Wconversion -Wsign-conversion -Wshadow -Wold-style-cast)
  endif()
  add_custom_command(OUTPUT ${obj}
    COMMAND ${CMAKE_CXX_COMPILER_LAUNCHER} ${SETTLE_CLANGXX} ${servo_fuzz_flags} ${warnings} ${servo_fuzz_includes}
            -MD -MF ${obj}.d -c ${src} -o ${obj}
    DEPENDS ${src}
    DEPFILE ${obj}.d
    COMMENT "clang (fuzzer, ASan + UBSan): ${rel}"
    VERBATIM)
  list(APPEND servo_fuzz_objects ${obj})
endforeach()
add_custom_command(OUTPUT ${servo_fuzz_exe}
  COMMAND ${SETTLE_CLANGXX} -fsanitize=fuzzer,address,undefined ${servo_fuzz_objects} -o ${servo_fuzz_exe}
  DEPENDS ${servo_fuzz_objects}
  COMMENT "Linking the master-vs-drive libFuzzer harness"
  VERBATIM)
add_custom_target(hal_fuzz_servo ALL DEPENDS ${servo_fuzz_exe})

# Committed inputs, read only: seeds/ (the starting corpus; each must pass) and regressions/ (one
# minimised input per invariant violation found; each is its own test).
set(servo_seeds_dir ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/servo_seeds)
set(servo_regressions_dir ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/regressions)
# The path the run takes follows the coverage map, so any change to the code under test moves
# where it finds the pending item08 violation: after the drive's dynamic PDO mapping (issue 14)
# seed 1 reaches it at run ~3750, no longer within 600.
set(SETTLE_SERVO_FUZZ_BRIEF_RUNS 4000 CACHE STRING "inputs the brief master-vs-drive fuzz run tries")
set(servo_fuzz_common -rss_limit_mb=2048 -max_len=1100 -artifact_prefix=${servo_fuzz_dir}/artifacts/)
file(MAKE_DIRECTORY ${servo_fuzz_dir}/artifacts ${servo_fuzz_dir}/corpus-long)
file(GLOB servo_seeds CONFIGURE_DEPENDS ${servo_seeds_dir}/*)
file(GLOB servo_regressions CONFIGURE_DEPENDS ${servo_regressions_dir}/*)

# Inputs that fail on the code this harness was written against and pass once the drive and loop
# fixes of issue 12 are merged (the file name says which item; "new_" ones are defects the
# harness found that no item names). Until then ctest expects them to end in an invariant
# violation (and nothing else: a sanitizer report or a missing binary does not pass). When a fix
# lands its test fails, because the input now passes: take its name out of this list. The brief
# random run is in it as well while today's code still has defects it finds within its runs.
set(servo_fuzz_expected "fuzz_servo: invariant \\([abc]\\) violated")
# Fixed by issue 12's drive and loop work and, for the item08 inputs (a delayed bus or a late
# drive delivering two of the master's SYNC+RPDO pairs within one period), by the drive's step
# window (hal/include/settle/hal/canopen/step_window.hpp): nothing is pending today. An input
# that reproduces a defect not fixed yet goes here by name until its fix lands.
set(servo_fuzz_pending)

# Every seed, run once (no fuzzing): the committed corpus stays green.
add_test(NAME hal_fuzz_servo_seeds COMMAND ${servo_fuzz_exe} ${servo_fuzz_common} ${servo_seeds})
set_tests_properties(hal_fuzz_servo_seeds PROPERTIES LABELS fuzz TIMEOUT 120)
foreach(input IN LISTS servo_regressions)
  get_filename_component(name ${input} NAME)
  add_test(NAME hal_fuzz_servo_regression.${name} COMMAND ${servo_fuzz_exe} ${servo_fuzz_common} ${input})
  set_tests_properties(hal_fuzz_servo_regression.${name} PROPERTIES LABELS fuzz TIMEOUT 120)
  if(name IN_LIST servo_fuzz_pending)
    set_tests_properties(hal_fuzz_servo_regression.${name} PROPERTIES PASS_REGULAR_EXPRESSION "${servo_fuzz_expected}")
  endif()
endforeach()

# The brief run: a fixed number of runs from a fixed seed, starting from the seeds in an emptied
# corpus, so it makes the same mutations every time (no wall-clock limit decides what it tries).
# -use_cmp=0: the comparison-guided mutations would insert operands of compared pointers, which
# differ from run to run (ASLR), and the run would no longer be reproducible.
add_test(NAME hal_fuzz_servo_brief_reset
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${servo_fuzz_dir}/corpus-brief)
add_test(NAME hal_fuzz_servo_brief_mkdir
  COMMAND ${CMAKE_COMMAND} -E make_directory ${servo_fuzz_dir}/corpus-brief)
set_tests_properties(hal_fuzz_servo_brief_reset PROPERTIES LABELS fuzz FIXTURES_SETUP servo_brief_corpus)
set_tests_properties(hal_fuzz_servo_brief_mkdir PROPERTIES LABELS fuzz FIXTURES_SETUP servo_brief_corpus
  DEPENDS hal_fuzz_servo_brief_reset)
add_test(NAME hal_fuzz_servo_brief
  COMMAND ${servo_fuzz_exe} ${servo_fuzz_common} -seed=1 -use_cmp=0 -runs=${SETTLE_SERVO_FUZZ_BRIEF_RUNS}
          ${servo_fuzz_dir}/corpus-brief ${servo_seeds_dir})
set_tests_properties(hal_fuzz_servo_brief PROPERTIES LABELS fuzz TIMEOUT 300
  FIXTURES_REQUIRED servo_brief_corpus)
if(hal_fuzz_servo_brief IN_LIST servo_fuzz_pending)
  set_tests_properties(hal_fuzz_servo_brief PROPERTIES PASS_REGULAR_EXPRESSION "${servo_fuzz_expected}")
endif()

# The long run: 15 minutes, time-limited, its corpus kept in the build tree between runs.
add_test(NAME hal_fuzz_servo_long
  COMMAND ${servo_fuzz_exe} ${servo_fuzz_common} -max_total_time=900 ${servo_fuzz_dir}/corpus-long ${servo_seeds_dir})
set_tests_properties(hal_fuzz_servo_long PROPERTIES LABELS fuzz-long TIMEOUT 1200)
