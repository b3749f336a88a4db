# tests/target/target-tests.cmake: what the Cortex-M images must do, as CTest
# tests of the host build (label `target`; included by toolchain/
# targets.cmake, which builds the images: ASCORR_TARGET_<cpu>_BINARY_DIR, the
# boards and scalars of toolchain/targets.txt):
#   target_<t>_accuracy_<scalar>   worked examples + random set vs the double core
#   target_<t>_firmware            the 22 Hz loop for 352 cycles, no overrun, its
#                                  report as below, its solutions those of
#                                  the host core and its estimator's model
#                                  history the host's (check-flight-solutions)
#   target_<t>_no_soft_float       on a fixed-point target (no FPU), the
#                                  per-solution and per-cycle code (the
#                                  core's entry, the velocity query,
#                                  the estimator's per-cycle part,
#                                  firmware/app/*_entry_fixed.cpp, and the
#                                  fixed-point thermistor acquisition,
#                                  hal_temperatures.cpp) references no
#                                  soft-float routine (negative control: its
#                                  application image, whose velocity service
#                                  propagates in double, has); the same on its
#                                  Debug (-O0) build
#                                  (target_<t>-debug_no_soft_float*),
#                                  whose loop also flies without overrun and
#                                  with the same solutions
#                                  (target_<t>-debug_firmware)

# The host's side of the accuracy tests: inputs and the double core's check.
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
                 ${PROJECT_SOURCE_DIR}/firmware/app/velocity_entry_${scalar}.cpp
                 ${PROJECT_SOURCE_DIR}/firmware/app/calib_entry_${scalar}.cpp
                 ${PROJECT_SOURCE_DIR}/firmware/app/calib_idle_${scalar}.cpp
                 ${PROJECT_SOURCE_DIR}/firmware/app/combine_entry_${scalar}.cpp
                 ${PROJECT_SOURCE_DIR}/firmware/app/sun_entry_${scalar}.cpp
                 ${PROJECT_SOURCE_DIR}/firmware/app/sun_learner_entry.cpp)
  target_include_directories(ascorr_flight_expectation_${scalar} PRIVATE ${PROJECT_SOURCE_DIR}/firmware/app)
  target_link_libraries(ascorr_flight_expectation_${scalar} PRIVATE ascorr_core ascorr::hal ascorr_warnings)
  target_compile_options(ascorr_flight_expectation_${scalar} PRIVATE -ffp-contract=off)
  if(scalar STREQUAL "fixed")
    target_compile_definitions(ascorr_flight_expectation_${scalar} PRIVATE ASCORR_APP_FIXED)
  endif()
endforeach()

# Accuracy against the double core, arcsec: tests/target/accuracy-bounds.txt
# (also read by toolchain/target-info bound, and by tests/CMakeLists.txt for
# the replay tests).
include(${CMAKE_CURRENT_LIST_DIR}/accuracy-bounds.cmake)
ascorr_read_accuracy_bounds()
set(bound_fixed ${ASCORR_BOUND_fixed})
set(bound_float ${ASCORR_BOUND_float})
# The 22 Hz loop's report after 352 cycles (16 s), no overrun in either. Both
# images take the boom temperatures through the HAL (firmware/app/
# boom_temperatures.hpp; float on the M4F, fixed point on the M3) with the same
# emulated ADC and faults (boom_channels.hpp): THT00057 open in seconds 4–6 is
# outvoted (no effect); THT00032 and THT00060 open in seconds 9–10 leave T_032
# without quorum, so heads A–C skip the thermal stage for those 44 cycles with
# status 1|8|64 (status seen 75, applied 308). Head D has no model. The
# velocity comes from the on-board service fed by the recorded GNSS orbit
# (firmware/app/gnss_feed.hpp; one state refused as out of order), and in
# steady state it costs no more than the correction of three heads.
set(firmware_expect "352 cycles at 22 Hz, overruns 0.*head 0: applied 308 status seen 75 .*head 1: applied 308 status seen 75 .*head 2: applied 308 status seen 75 .*head 3: applied 0 status seen 257 .*states accepted 2 refused 1")
# The report names the image's scalar (firmware/app/CMakeLists.txt, ASCORR_APP_SCALAR_NAME).
set(scalar_name_fixed "fixed-point")
set(scalar_name_float "float")

# The loop's solutions and the estimator's model history against the host
# in the image's scalar (tests/target/check-flight-solutions). Q30 bit for
# bit: integer arithmetic; the service's and the estimator's double is IEEE
# software double on the target and SSE2 on the host, sin/cos from
# sincos.hpp, exp and hypot from calib/portable_math.hpp. The M4F image's
# float code is compiled with GCC's default contraction into fused
# multiply-adds (the host's, like the link image, without:
# -ffp-contract=off), which skips roundings: measured, 23 of 92 printed
# solutions differ, by at most 0.026", and the model history has the same
# versions from the same cycles, its models' angles within the bound of each
# other at the loop's temperatures. Bound: the float path's own, bound_float
# (vs the double core), which a velocity error of 73 m/s or a T032 error of
# 0.03 degC (head C: 2.25"/degC) would exceed. The flight loop runs the
# estimator on a bench that deforms with temperature and has the star
# tracker's noise (firmware/app/flight_bench.hpp): 44 accelerated orbits, a
# model adopted after 30 (the check fails when none is).
set(flight_bound_fixed 0)
set(flight_bound_float ${bound_float})
set(flight_match_fixed "solutions match the host core's bit for bit.*model history .* matches the host's bit for bit.*mutated expectation refused")
set(flight_match_float "solutions match the host core's within the bound.*model history .* matches the host's within the bound.*mutated expectation refused")

foreach(t ${ASCORR_TARGET_LIST})
  set(bin ${ASCORR_TARGET_${t}_BINARY_DIR})
  set(machine ${ASCORR_TARGET_${t}_MACHINE})
  foreach(scalar ${ASCORR_TARGET_${t}_SCALARS})
    add_test(NAME target_${t}_accuracy_${scalar}
             COMMAND ${PROJECT_SOURCE_DIR}/tests/target/run-accuracy $<TARGET_FILE:ascorr_target_vectors>
                     ${machine} ${bin}/tests/target/ascorr_target_accuracy_${scalar}.elf ${bound_${scalar}}
                     ${CMAKE_BINARY_DIR}/target-runs/${t}-${scalar})
    set_tests_properties(target_${t}_accuracy_${scalar} PROPERTIES LABELS target TIMEOUT 120)
  endforeach()
  set(s ${ASCORR_TARGET_${t}_SCALAR})
  add_test(NAME target_${t}_firmware
           COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-flight-solutions $<TARGET_FILE:ascorr_flight_expectation_${s}>
                   ${machine} ${bin}/firmware/app/ascorr_firmware.elf ${flight_bound_${s}}
                   ${CMAKE_BINARY_DIR}/target-runs/${t}-firmware)
  set_tests_properties(target_${t}_firmware PROPERTIES LABELS target TIMEOUT 60
    PASS_REGULAR_EXPRESSION "${scalar_name_${s}} core, ${firmware_expect}.*service within the correction's cost.*estimator within the correction's cost.*${flight_match_${s}}")
endforeach()

# No soft-float routine in the M3's per-solution path. Scope: the
# application image holds the velocity service's software-double part
# (frame conversion, propagation, Earth series, once per state / node /
# minute, outside the per-solution path), so the check names the objects of
# the per-solution and per-cycle code; the image is the negative control.
set(no_fpu_builds "")
foreach(t ${ASCORR_TARGET_LIST})
  if(ASCORR_TARGET_${t}_SCALAR STREQUAL "fixed")  # the fixed-point core: a target without FPU
    list(APPEND no_fpu_builds ${t})
  endif()
endforeach()
foreach(build ${no_fpu_builds} ${ASCORR_TARGET_DEBUG_BUILDS})
  set(app ${ASCORR_TARGET_${build}_BINARY_DIR}/firmware/app)
  set(entry_objs ${app}/CMakeFiles/ascorr_core_entry_fixed.dir)
  # The Sun term's entry: the flight image links it (a fixed model's term), a debug build's too.
  set(bench_entries ${app}/CMakeFiles/ascorr_sun_entry_fixed.dir/sun_entry_fixed.cpp.obj)
  add_test(NAME target_${build}_no_soft_float
           COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-no-soft-float ${ASCORR_ARM_NM}
                   ${entry_objs}/core_entry_fixed.cpp.obj ${entry_objs}/velocity_entry_fixed.cpp.obj
                   ${entry_objs}/calib_entry_fixed.cpp.obj
                   ${bench_entries} ${app}/CMakeFiles/ascorr_firmware.dir/hal_temperatures.cpp.obj)
  add_test(NAME target_${build}_no_soft_float_control
           COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-no-soft-float ${ASCORR_ARM_NM} ${app}/ascorr_firmware.elf)
  set_tests_properties(target_${build}_no_soft_float PROPERTIES LABELS target)
  set_tests_properties(target_${build}_no_soft_float_control PROPERTIES LABELS target WILL_FAIL ON)
endforeach()

# The -O0 image flies the same loop without overrun and with the same
# solutions (the velocity service's cost comparison is an optimised-build
# figure and is not asked of it).
foreach(build ${ASCORR_TARGET_DEBUG_BUILDS})
  set(cpu ${ASCORR_TARGET_${build}_CPU})
  add_test(NAME target_${build}_firmware
           COMMAND ${PROJECT_SOURCE_DIR}/tests/target/check-flight-solutions $<TARGET_FILE:ascorr_flight_expectation_fixed>
                   ${ASCORR_TARGET_${cpu}_MACHINE} ${ASCORR_TARGET_${build}_BINARY_DIR}/firmware/app/ascorr_firmware.elf
                   ${flight_bound_fixed} ${CMAKE_BINARY_DIR}/target-runs/${build}-firmware)
  set_tests_properties(target_${build}_firmware PROPERTIES LABELS target TIMEOUT 60
    PASS_REGULAR_EXPRESSION "${scalar_name_fixed} core, ${firmware_expect}.*${flight_match_fixed}")
endforeach()
