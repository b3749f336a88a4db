# toolchain/cortex-m3.cmake: Cortex-M3, no FPU (soft-float ABI); the firmware
# runs the fixed-point core (Q30) here. Its QEMU board, scalars and CPU flags:
# toolchain/targets.txt.
set(ASCORR_TARGET_NAME cortex-m3)
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-picolibc.cmake)
