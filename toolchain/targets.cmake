# toolchain/targets.cmake: the Cortex-M builds and their tests, driven from the
# host build (included by the top CMakeLists.txt when ASCORR_TARGETS is ON; the
# `ci` preset sets it).
#
# Each target is a separate CMake build of this source tree with its toolchain
# file (ExternalProject, binary dir <host build>/<target>), so that host and
# cross flags never mix; it is rebuilt whenever the host build is (BUILD_ALWAYS,
# a no-op when nothing changed). The images run under QEMU in CTest, label
# `target`:
#   target_<t>_accuracy_<scalar>   worked examples + random set vs the double core
#   target_<t>_firmware            the 22 Hz loop for 352 cycles, no overrun
#   target_cortex-m3_no_soft_float the M3's per-solution and per-cycle code (the
#                                  core's entry, the velocity query,
#                                  firmware/app/*_entry_fixed.cpp, and the
#                                  fixed-point thermistor acquisition,
#                                  hal_temperatures.cpp) references no soft-float routine (negative
#                                  control: the M3 application image, whose
#                                  velocity service propagates in double, has);
#                                  the same on a Debug (-O0) M3 build
#                                  (target_cortex-m3-debug_no_soft_float*),
#                                  whose loop also flies without overrun
#                                  (target_cortex-m3-debug_firmware)
include(ExternalProject)
find_program(ASCORR_ARM_GXX arm-none-eabi-g++ REQUIRED)
find_program(ASCORR_ARM_NM arm-none-eabi-nm REQUIRED)
find_program(ASCORR_QEMU qemu-system-arm REQUIRED)

add_executable(ascorr_target_vectors ${PROJECT_SOURCE_DIR}/tests/target_vectors.cpp)
target_include_directories(ascorr_target_vectors PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(ascorr_target_vectors PRIVATE ascorr_host ascorr_warnings)
target_compile_definitions(ascorr_target_vectors PRIVATE ASCORR_TEST_DATA="${PROJECT_SOURCE_DIR}/tests/data")

# The flight loop's solutions as the host core computes them (tests/target/
# flight_expectation.cpp: the loop's own cycle, flight_cycle.hpp, in each
# image scalar; without fused multiply-adds, as the host core everywhere).
foreach(scalar fixed float)
  add_executable(ascorr_flight_expectation_${scalar} ${PROJECT_SOURCE_DIR}/tests/target/flight_expectation.cpp
                 ${PROJECT_SOURCE_DIR}/firmware/app/core_entry_${scalar}.cpp
                 ${PROJECT_SOURCE_DIR}/firmware/app/velocity_entry_${scalar}.cpp)
  target_include_directories(ascorr_flight_expectation_${scalar} PRIVATE ${PROJECT_SOURCE_DIR}/firmware/app)
  target_link_libraries(ascorr_flight_expectation_${scalar} PRIVATE ascorr_core ascorr::hal ascorr_warnings)
  target_compile_options(ascorr_flight_expectation_${scalar} PRIVATE -ffp-contract=off)
  if(scalar STREQUAL "fixed")
    target_compile_definitions(ascorr_flight_expectation_${scalar} PRIVATE ASCORR_APP_FIXED)
  endif()
endforeach()

# Each target's QEMU board and scalars: toolchain/targets.txt.
include(${PROJECT_SOURCE_DIR}/toolchain/target-table.cmake)
ascorr_read_targets()
set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${ASCORR_TARGET_TABLE})
foreach(t ${ASCORR_TARGET_LIST})
  set(machine_${t} ${ASCORR_TARGET_${t}_MACHINE})
  set(app_scalar_${t} ${ASCORR_TARGET_${t}_SCALAR})
  set(scalars_${t} ${ASCORR_TARGET_${t}_SCALARS})
endforeach()
set(bound_fixed 0.01)
# The 22 Hz loop's report after 352 cycles (16 s), no overrun in either. Both
# images take the boom temperatures through the HAL (firmware/app/
# hal_temperatures.cpp; float on the M4F, fixed point on the M3) with the same
# emulated ADC and faults (boom_channels.hpp): THT00057 open in seconds 4–6 is
# outvoted (no effect); THT00032 and THT00060 open in seconds 9–10 leave T_032
# without quorum, so heads A–C skip the thermal stage for those 44 cycles with
# status 1|8|64 (status seen 75, applied 308). Head D has no model. The
# velocity comes from the on-board service fed by the recorded GNSS orbit
# (firmware/app/gnss_feed.hpp; one state refused as out of order), and in
# steady state it costs no more than the correction of three heads.
set(firmware_expect "352 cycles at 22 Hz, overruns 0.*head 0: applied 308 status seen 75 .*head 1: applied 308 status seen 75 .*head 2: applied 308 status seen 75 .*head 3: applied 0 status seen 257 .*states accepted 2 refused 1")
set(firmware_expect_cortex-m3 "fixed-point core, ${firmware_expect}.*service within the correction's cost")
set(firmware_expect_cortex-m4f "float core, ${firmware_expect}.*service within the correction's cost")

set(bound_float 0.05)
# The loop's solutions against the host core in the image's scalar
# (tests/target/check-flight-solutions): Q30 bit for bit (integer arithmetic;
# the service's double is IEEE software double on both targets and SSE2 on the
# host, sin/cos from sincos.hpp). The M4F image's float core is compiled with
# GCC's default contraction into fused multiply-adds (the host's, like the
# link image, without: -ffp-contract=off), which skips roundings: measured,
# 1 solution of 1408 differs, by 1 ulp of one component (0.003"). Bound: the
# float path's own, bound_float (vs the double core), which a velocity error
# of 73 m/s or a T032 error of 0.03 degC (head C: 2.25"/degC) would exceed.
set(flight_bound_fixed 0)
set(flight_bound_float ${bound_float})
set(flight_match_fixed "solutions match the host core's bit for bit.*mutated expectation refused")
set(flight_match_float "solutions match the host core's within the bound.*mutated expectation refused")
foreach(t ${ASCORR_TARGET_LIST})
  set(bin ${CMAKE_BINARY_DIR}/${t})
  ExternalProject_Add(ascorr_${t}
    SOURCE_DIR ${PROJECT_SOURCE_DIR}
    BINARY_DIR ${bin}
    CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/toolchain/${t}.cmake
               -DASCORR_BUILD_HOST=OFF -DASCORR_WERROR=${ASCORR_WERROR}
               -DCMAKE_BUILD_TYPE=Release
    BUILD_ALWAYS ON
    INSTALL_COMMAND ""
    USES_TERMINAL_BUILD ON)
  foreach(scalar ${scalars_${t}})
    add_test(NAME target_${t}_accuracy_${scalar}
             COMMAND ${PROJECT_SOURCE_DIR}/tests/target/run-accuracy $<TARGET_FILE:ascorr_target_vectors>
                     ${machine_${t}} ${bin}/tests/target/ascorr_target_accuracy_${scalar}.elf ${bound_${scalar}}
                     ${CMAKE_BINARY_DIR}/target-runs/${t}-${scalar})
    set_tests_properties(target_${t}_accuracy_${scalar} PROPERTIES LABELS target TIMEOUT 120)
  endforeach()
  set(s ${app_scalar_${t}})
  add_test(NAME target_${t}_firmware
           COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-flight-solutions $<TARGET_FILE:ascorr_flight_expectation_${s}>
                   ${machine_${t}} ${bin}/firmware/app/ascorr_firmware.elf ${flight_bound_${s}}
                   ${CMAKE_BINARY_DIR}/target-runs/${t}-firmware)
  set_tests_properties(target_${t}_firmware PROPERTIES LABELS target TIMEOUT 60
    PASS_REGULAR_EXPRESSION "${firmware_expect_${t}}.*${flight_match_${s}}")
endforeach()

# Scope: the per-solution path. Since issue 12 the application image holds the
# velocity service's software-double part (frame conversion, propagation, Earth
# series, once per state / node / minute, outside the per-solution path).
set(m3_entry_objs ${CMAKE_BINARY_DIR}/cortex-m3/firmware/app/CMakeFiles/ascorr_core_entry_fixed.dir)

# The M3 build at -O0 (Debug): no constant of the core may be converted from
# double at run time (scalar_traits.hpp, k<T>()), so the per-solution objects
# stay free of soft-float there too. Only the flight image (and with it those
# objects) is built; the image itself, which propagates in double, is the
# negative control.
ExternalProject_Add(ascorr_cortex-m3-debug
  SOURCE_DIR ${PROJECT_SOURCE_DIR}
  BINARY_DIR ${CMAKE_BINARY_DIR}/cortex-m3-debug
  CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/toolchain/cortex-m3.cmake
             -DASCORR_BUILD_HOST=OFF -DASCORR_WERROR=${ASCORR_WERROR}
             -DCMAKE_BUILD_TYPE=Debug
  BUILD_COMMAND ${CMAKE_COMMAND} --build <BINARY_DIR> --target ascorr_firmware
  BUILD_ALWAYS ON
  INSTALL_COMMAND ""
  USES_TERMINAL_BUILD ON)
set(m3_debug_entry_objs ${CMAKE_BINARY_DIR}/cortex-m3-debug/firmware/app/CMakeFiles/ascorr_core_entry_fixed.dir)
add_test(NAME target_cortex-m3-debug_no_soft_float
         COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-no-soft-float ${ASCORR_ARM_NM}
                 ${m3_debug_entry_objs}/core_entry_fixed.cpp.obj ${m3_debug_entry_objs}/velocity_entry_fixed.cpp.obj
                 ${CMAKE_BINARY_DIR}/cortex-m3-debug/firmware/app/CMakeFiles/ascorr_firmware.dir/hal_temperatures.cpp.obj)
add_test(NAME target_cortex-m3-debug_no_soft_float_control
         COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-no-soft-float ${ASCORR_ARM_NM}
                 ${CMAKE_BINARY_DIR}/cortex-m3-debug/firmware/app/ascorr_firmware.elf)
# The -O0 image flies the same loop without overrun (the velocity service's
# cost comparison is an optimised-build figure and is not asked of it).
add_test(NAME target_cortex-m3-debug_firmware
         COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-flight-solutions $<TARGET_FILE:ascorr_flight_expectation_fixed>
                 ${machine_cortex-m3} ${CMAKE_BINARY_DIR}/cortex-m3-debug/firmware/app/ascorr_firmware.elf ${flight_bound_fixed}
                 ${CMAKE_BINARY_DIR}/target-runs/cortex-m3-debug-firmware)
set_tests_properties(target_cortex-m3-debug_firmware PROPERTIES LABELS target TIMEOUT 60
  PASS_REGULAR_EXPRESSION "fixed-point core, ${firmware_expect}.*${flight_match_fixed}")
set_tests_properties(target_cortex-m3-debug_no_soft_float PROPERTIES LABELS target)
set_tests_properties(target_cortex-m3-debug_no_soft_float_control PROPERTIES LABELS target WILL_FAIL ON)

add_test(NAME target_cortex-m3_no_soft_float
         COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-no-soft-float ${ASCORR_ARM_NM}
                 ${m3_entry_objs}/core_entry_fixed.cpp.obj ${m3_entry_objs}/velocity_entry_fixed.cpp.obj
                 ${CMAKE_BINARY_DIR}/cortex-m3/firmware/app/CMakeFiles/ascorr_firmware.dir/hal_temperatures.cpp.obj)
add_test(NAME target_cortex-m3_no_soft_float_control
         COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-no-soft-float ${ASCORR_ARM_NM}
                 ${CMAKE_BINARY_DIR}/cortex-m3/firmware/app/ascorr_firmware.elf)
set_tests_properties(target_cortex-m3_no_soft_float PROPERTIES LABELS target)
set_tests_properties(target_cortex-m3_no_soft_float_control PROPERTIES LABELS target WILL_FAIL ON)
