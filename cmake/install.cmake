# Install rules and the CMake package: `cmake --install build --prefix P` puts the library, the
# public headers and rtcostConfig.cmake in P, so that a consumer's
#   find_package(rtcost CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE rtcost::rtcost)
# builds against it. The library stays static: hierarchies register themselves from static
# objects, so rtcost::rtcost links the archive whole (WHOLE_ARCHIVE), in the build tree and for
# installed consumers alike (the exported target carries the same generator expression).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(RTCOST_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/rtcost CACHE STRING "where rtcostConfig.cmake is installed")
set_target_properties(rtcost_core PROPERTIES EXPORT_NAME rtcost_core)

install(TARGETS rtcost_core rtcost EXPORT rtcostTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/rtcost DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.hpp")
install(TARGETS rtcost_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT rtcostTargets NAMESPACE rtcost:: DESTINATION ${RTCOST_CMAKE_DIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/rtcostConfig.cmake.in
  ${PROJECT_BINARY_DIR}/rtcostConfig.cmake INSTALL_DESTINATION ${RTCOST_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/rtcostConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/rtcostConfig.cmake ${PROJECT_BINARY_DIR}/rtcostConfigVersion.cmake
  DESTINATION ${RTCOST_CMAKE_DIR})
