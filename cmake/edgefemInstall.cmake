# Installation and the exported CMake package:
#
#   find_package(edgefem REQUIRED)
#   target_link_libraries(app PRIVATE edgefem::edgefem)
#
# edgefem::edgefem is everything (core, plus parallel and partition when
# built); the per-module targets are edgefem::core, edgefem::parallel,
# edgefem::partition and edgefem::capi.
# Included from the top CMakeLists.txt after every module's add_subdirectory.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(EDGEFEM_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/edgefem CACHE STRING
    "Where edgefemConfig.cmake is installed (relative to the prefix)")

# A static library's PRIVATE dependencies are exported as $<LINK_ONLY:dep>;
# build-only helpers (the warning/-march flags) must not reach consumers.
# Modules should write $<BUILD_INTERFACE:edgefem_build_flags>; this rewrites
# any that still name it bare, so the export never requires it.
function(edgefem_hide_build_only target)
  get_target_property(libs ${target} INTERFACE_LINK_LIBRARIES)
  if(NOT libs)
    return()
  endif()
  list(TRANSFORM libs REPLACE "^\\$<LINK_ONLY:edgefem_build_flags>$"
       "$<LINK_ONLY:$<BUILD_INTERFACE:edgefem_build_flags>>")
  list(TRANSFORM libs REPLACE "^edgefem_build_flags$" "$<BUILD_INTERFACE:edgefem_build_flags>")
  set_property(TARGET ${target} PROPERTY INTERFACE_LINK_LIBRARIES "${libs}")
endfunction()

# The umbrella target. (The name `edgefem` belongs to the CLI executable, so
# the library target is edgefem_all, exported as edgefem::edgefem.)
add_library(edgefem_all INTERFACE)
add_library(edgefem::edgefem ALIAS edgefem_all)
set_target_properties(edgefem_all PROPERTIES EXPORT_NAME edgefem)
target_link_libraries(edgefem_all INTERFACE edgefem_core)

set(edgefem_export_targets edgefem_core edgefem_all)
# Optional modules, exported when their target exists at configure time.
set(EDGEFEM_HAS_PARALLEL OFF)
set(EDGEFEM_HAS_PARTITION OFF)
foreach(module parallel partition)
  if(TARGET edgefem_${module})
    string(TOUPPER ${module} upper)
    set(EDGEFEM_HAS_${upper} ON)
    set_target_properties(edgefem_${module} PROPERTIES EXPORT_NAME ${module})
    target_link_libraries(edgefem_all INTERFACE edgefem_${module})
    list(APPEND edgefem_export_targets edgefem_${module})
  endif()
endforeach()
set(EDGEFEM_HAS_CAPI OFF)
if(TARGET edgefem_capi)
  set(EDGEFEM_HAS_CAPI ON)
  list(APPEND edgefem_export_targets edgefem_capi)
endif()
foreach(t IN LISTS edgefem_export_targets)
  edgefem_hide_build_only(${t})
endforeach()

install(TARGETS ${edgefem_export_targets}
  EXPORT edgefemTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(module core parallel partition capi)
  if(IS_DIRECTORY ${PROJECT_SOURCE_DIR}/${module}/include/edgefem)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/${module}/include/edgefem
            DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
            FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
  endif()
endforeach()
if(TARGET edgefem)
  install(TARGETS edgefem RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

install(EXPORT edgefemTargets
  NAMESPACE edgefem::
  FILE edgefemTargets.cmake
  DESTINATION ${EDGEFEM_INSTALL_CMAKEDIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/edgefemConfig.cmake.in
  ${PROJECT_BINARY_DIR}/edgefemConfig.cmake
  INSTALL_DESTINATION ${EDGEFEM_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/edgefemConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/edgefemConfig.cmake ${PROJECT_BINARY_DIR}/edgefemConfigVersion.cmake
  DESTINATION ${EDGEFEM_INSTALL_CMAKEDIR})

# The consumer check: install into a prefix inside the build tree, then
# configure, build and run examples/consumer against it.
if(EDGEFEM_BUILD_TESTS)
  set(consumer_prefix ${PROJECT_BINARY_DIR}/consumer-test/prefix)
  set(consumer_build ${PROJECT_BINARY_DIR}/consumer-test/build)
  add_test(NAME install_consumer COMMAND ${CMAKE_COMMAND}
    -DBUILD_DIR=${PROJECT_BINARY_DIR}
    -DPREFIX=${consumer_prefix}
    -DCONSUMER_SOURCE=${PROJECT_SOURCE_DIR}/examples/consumer
    -DCONSUMER_BUILD=${consumer_build}
    -DCONFIG=$<CONFIG>
    -DGENERATOR=${CMAKE_GENERATOR}
    -DCXX=${CMAKE_CXX_COMPILER}
    -P ${CMAKE_CURRENT_LIST_DIR}/consumer_test.cmake)
  set_tests_properties(install_consumer PROPERTIES TIMEOUT 600
    PASS_REGULAR_EXPRESSION "consumer: ok")
endif()
