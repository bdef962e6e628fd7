# SPDX-License-Identifier: Apache-2.0
# Included by ctest (TEST_INCLUDE_FILES, through the generated e2e_scenarios.cmake, which sets
# SETTLE, PYTHON and E2E): one e2e test per paper scenario, from the built settle's own table. When
# settle cannot list them, one failing test says so instead of the scenarios silently vanishing.
execute_process(COMMAND "${SETTLE}" demo --list --json OUTPUT_VARIABLE table RESULT_VARIABLE status
                ERROR_VARIABLE error TIMEOUT 60)
set(count 0)
if(status EQUAL 0)
  string(JSON count ERROR_VARIABLE json_error LENGTH "${table}" scenarios)
  if(json_error)
    set(count 0)
  endif()
endif()
if(count EQUAL 0)
  string(REPLACE "\n" " " error "${error}")
  add_test(e2e.scenario-list "${PYTHON}" -c "import sys; sys.exit(sys.argv[1])"
           "settle demo --list --json (${SETTLE}) listed no scenario: exit ${status} ${error}")
  set_tests_properties(e2e.scenario-list PROPERTIES LABELS vcan)
else()
  math(EXPR last "${count} - 1")
  foreach(i RANGE ${last})
    string(JSON id GET "${table}" scenarios ${i} id)
    add_test(e2e.${id} "${PYTHON}" "${E2E}" "${SETTLE}" "${id}")
    # One bus: these tests must not overlap each other or hal's vcan tests.
    set_tests_properties(e2e.${id} PROPERTIES LABELS vcan RESOURCE_LOCK vcan0 TIMEOUT 300)
  endforeach()
endif()
