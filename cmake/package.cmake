# The installed CMake package: find_package(zcheck) → zcheck::zcheck (everything) and the
# finer targets zcheck::core, io, depthmaps, imageio, cameras, scene, raycast, raster, check, diagnose, report.
include(CMakePackageConfigHelpers)
add_library(zcheck_all INTERFACE)
set_target_properties(zcheck_all PROPERTIES EXPORT_NAME zcheck)
target_link_libraries(zcheck_all INTERFACE zcheck_report zcheck_imageio)
add_library(zcheck::zcheck ALIAS zcheck_all)

install(TARGETS ${ZCHECK_INSTALLED_TARGETS} zcheck_all EXPORT zcheckTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
set(ZCHECK_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/zcheck)
install(EXPORT zcheckTargets NAMESPACE zcheck:: DESTINATION ${ZCHECK_CMAKE_DIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/zcheckConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/zcheckConfig.cmake INSTALL_DESTINATION ${ZCHECK_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/zcheckConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/zcheckConfig.cmake ${PROJECT_BINARY_DIR}/zcheckConfigVersion.cmake
        DESTINATION ${ZCHECK_CMAKE_DIR})
