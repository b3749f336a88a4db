# toolchain/targets.cmake: how the Cortex-M images are built, driven from the
# host build (included by the top CMakeLists.txt when ASCORR_TARGETS is ON; the
# `ci` preset sets it). What they are expected to do is tests/target/
# target-tests.cmake, included at the end.
#
# Each target of toolchain/targets.txt is a separate CMake build of this
# source tree with its toolchain file (ExternalProject ascorr_<cpu>, binary dir
# ASCORR_TARGET_<cpu>_BINARY_DIR = <host build>/<cpu>), so that host and cross
# flags never mix; it is rebuilt whenever the host build is (BUILD_ALWAYS, a
# no-op when nothing changed). Besides, for each fixed-point target (no FPU:
# flight scalar fixed), a Debug (-O0) build of its flight image
# (ascorr_<cpu>-debug, <host build>/<cpu>-debug, listed in
# ASCORR_TARGET_DEBUG_BUILDS), for the no-soft-float check at -O0. The images run under QEMU through
# toolchain/qemu-run on each target's board.
include(ExternalProject)
find_program(ASCORR_ARM_GXX arm-none-eabi-g++ REQUIRED)
find_program(ASCORR_ARM_NM arm-none-eabi-nm REQUIRED)
find_program(ASCORR_QEMU qemu-system-arm REQUIRED)

# Each target's QEMU board and scalars: toolchain/targets.txt.
include(${PROJECT_SOURCE_DIR}/toolchain/target-table.cmake)
ascorr_read_targets()
set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${ASCORR_TARGET_TABLE})

foreach(t ${ASCORR_TARGET_LIST})
  set(ASCORR_TARGET_${t}_BINARY_DIR ${CMAKE_BINARY_DIR}/${t})
  ExternalProject_Add(ascorr_${t}
    SOURCE_DIR ${PROJECT_SOURCE_DIR}
    BINARY_DIR ${ASCORR_TARGET_${t}_BINARY_DIR}
    CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/toolchain/${t}.cmake
               -DASCORR_BUILD_HOST=OFF -DASCORR_WERROR=${ASCORR_WERROR}
               -DCMAKE_BUILD_TYPE=Release
    BUILD_ALWAYS ON
    INSTALL_COMMAND ""
    USES_TERMINAL_BUILD ON)
endforeach()

# The fixed-point (no FPU) targets' builds at -O0 (Debug): no constant of the
# core may be converted from double at run time (scalar_traits.hpp,
# constant<T>()), so the per-solution objects stay free of soft-float there
# too. Only the flight image (and with it those objects) is built.
set(ASCORR_TARGET_DEBUG_BUILDS "")
foreach(t ${ASCORR_TARGET_LIST})
  if(NOT ASCORR_TARGET_${t}_SCALAR STREQUAL "fixed")
    continue()
  endif()
  set(ASCORR_TARGET_${t}-debug_CPU ${t})
  set(ASCORR_TARGET_${t}-debug_BINARY_DIR ${CMAKE_BINARY_DIR}/${t}-debug)
  list(APPEND ASCORR_TARGET_DEBUG_BUILDS ${t}-debug)
  ExternalProject_Add(ascorr_${t}-debug
    SOURCE_DIR ${PROJECT_SOURCE_DIR}
    BINARY_DIR ${ASCORR_TARGET_${t}-debug_BINARY_DIR}
    CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/toolchain/${t}.cmake
               -DASCORR_BUILD_HOST=OFF -DASCORR_WERROR=${ASCORR_WERROR}
               -DCMAKE_BUILD_TYPE=Debug
    BUILD_COMMAND ${CMAKE_COMMAND} --build <BINARY_DIR> --target ascorr_firmware
    BUILD_ALWAYS ON
    INSTALL_COMMAND ""
    USES_TERMINAL_BUILD ON)
endforeach()

include(${PROJECT_SOURCE_DIR}/tests/target/target-tests.cmake)
