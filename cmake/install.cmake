# cmake/install.cmake: `cmake --install` of the firmware-facing parts.
#
# Installs the header-only core (include/ascorr/), the link protocol
# (include/ascorr_link/) and the freestanding HAL (include/ascorr_hal/), and
# exports them as ascorr::core and ascorr::hal:
#   <prefix>/share/ascorr/cmake/ascorrConfig.cmake, ascorrConfigVersion.cmake,
#   ascorrTargets.cmake                      -> find_package(ascorr 0.1 REQUIRED)
#   <prefix>/share/pkgconfig/ascorr.pc       -> pkg-config --cflags ascorr
# All three are header-only and architecture-independent (no compiled code),
# hence share/ for the pkg-config file and ARCH_INDEPENDENT for the version.
# The example consumer (examples/consumer/) is built against such an install
# in CI (tests/install/run).
include(CMakePackageConfigHelpers)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/firmware/include/ascorr ${PROJECT_SOURCE_DIR}/firmware/include/ascorr_link
                  ${PROJECT_SOURCE_DIR}/hal/include/ascorr_hal
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp")
install(TARGETS ascorr_core ascorr_hal EXPORT ascorrTargets)

set(ASCORR_CMAKE_DIR ${CMAKE_INSTALL_DATADIR}/ascorr/cmake)
install(EXPORT ascorrTargets NAMESPACE ascorr:: DESTINATION ${ASCORR_CMAKE_DIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/ascorrConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/ascorrConfig.cmake INSTALL_DESTINATION ${ASCORR_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/ascorrConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion ARCH_INDEPENDENT)
install(FILES ${PROJECT_BINARY_DIR}/ascorrConfig.cmake ${PROJECT_BINARY_DIR}/ascorrConfigVersion.cmake
        DESTINATION ${ASCORR_CMAKE_DIR})

configure_file(${CMAKE_CURRENT_LIST_DIR}/ascorr.pc.in ${PROJECT_BINARY_DIR}/ascorr.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/ascorr.pc DESTINATION ${CMAKE_INSTALL_DATADIR}/pkgconfig)
