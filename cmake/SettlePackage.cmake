# SPDX-License-Identifier: Apache-2.0
# The installed package: `cmake --install <build>` puts the headers, the static libraries, the
# CMake package (find_package(settle CONFIG COMPONENTS ...), imported targets settle::<name>) and
# settle-core.pc under the prefix. Each component is one export set, installed only when this
# build has its targets (a cross build has no hal_socketcan, plant or testbed; only a bare-metal build has a
# board). Included last by the top-level CMakeLists.txt, when SETTLE_INSTALL is on.
include(CMakePackageConfigHelpers)

set(SETTLE_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/settle CACHE STRING
    "Where the CMake package goes, relative to the install prefix")

# component -> targets (build name:exported name); a component's dependencies are in the config.
set(_settle_component_core settle_core:core)
set(_settle_component_hal settle_hal:hal settle_hal_testing:hal_testing)
set(_settle_component_runtime settle_runtime:runtime settle_runtime_linux:runtime_linux)
set(_settle_component_hal_socketcan settle_hal_socketcan:hal_socketcan)
set(_settle_component_plant settle_plant:plant)
set(_settle_component_testbed settle_testbed_node:testbed_node)
set(_settle_component_board settle_semihosting:semihosting)
get_property(_settle_boards GLOBAL PROPERTY SETTLE_BOARD_TARGETS)  # firmware/CMakeLists.txt
foreach(target IN LISTS _settle_boards)
  string(REGEX REPLACE "^settle_" "" export_name ${target})
  list(APPEND _settle_component_board ${target}:${export_name})
endforeach()

set(SETTLE_INSTALLED_COMPONENTS)
foreach(component core hal runtime hal_socketcan plant testbed board)
  set(targets)
  foreach(pair IN LISTS _settle_component_${component})
    string(REPLACE ":" ";" pair "${pair}")
    list(GET pair 0 target)
    list(GET pair 1 export_name)
    if(TARGET ${target})
      set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
      list(APPEND targets ${target})
    endif()
  endforeach()
  if(NOT targets)
    continue()
  endif()
  list(APPEND SETTLE_INSTALLED_COMPONENTS ${component})
  install(TARGETS ${targets} EXPORT settle-${component}-targets COMPONENT ${component}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          OBJECTS DESTINATION ${CMAKE_INSTALL_LIBDIR}/settle/objects)
  install(EXPORT settle-${component}-targets NAMESPACE settle:: DESTINATION ${SETTLE_INSTALL_CMAKEDIR}
          COMPONENT ${component})
endforeach()

# Headers: every public include tree, whole (each header names its own dependencies).
set(_settle_header_dirs
  core:core/include
  hal:hal/include
  hal:hal/testing/include
  runtime:runtime/include
  runtime:runtime/linux/include
  plant:plant/include
  board:firmware/include)
foreach(pair IN LISTS _settle_header_dirs)
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 component)
  list(GET pair 1 dir)
  if(component IN_LIST SETTLE_INSTALLED_COMPONENTS)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT ${component})
  endif()
endforeach()
# The testbed's installed part is the simulated drive node (settle::testbed_node); the stream runner
# and its buses stay in the build tree.
if("testbed" IN_LIST SETTLE_INSTALLED_COMPONENTS)
  install(FILES ${SETTLE_TESTBED_NODE_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/settle/testbed COMPONENT testbed)
endif()
if("board" IN_LIST SETTLE_INSTALLED_COMPONENTS)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/firmware/boards/ DESTINATION ${CMAKE_INSTALL_DATADIR}/settle/boards
          COMPONENT board FILES_MATCHING PATTERN "*.ld")
endif()

# The licence and the notice of what Settle is built with travel with every installation.
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/NOTICE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/settle
        COMPONENT core)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/settleConfig.cmake.in
  ${PROJECT_BINARY_DIR}/package/settleConfig.cmake
  INSTALL_DESTINATION ${SETTLE_INSTALL_CMAKEDIR})
# 0.x: a minor version may break the API, so only the same minor version is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/settleConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/package/settleConfig.cmake ${PROJECT_BINARY_DIR}/package/settleConfigVersion.cmake
        DESTINATION ${SETTLE_INSTALL_CMAKEDIR} COMPONENT core)

# pkg-config for core, for builds that do not use CMake (relocatable: paths from ${pcfiledir}).
file(RELATIVE_PATH _settle_pc_to_prefix /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
string(REGEX REPLACE "/$" "" _settle_pc_to_prefix "${_settle_pc_to_prefix}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/settle-core.pc.in ${PROJECT_BINARY_DIR}/package/settle-core.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/package/settle-core.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig
        COMPONENT core)
