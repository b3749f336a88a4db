# toolchain/cortex-m3.cmake: Cortex-M3, no FPU (soft-float ABI), QEMU mps2-an385.
# The firmware runs the fixed-point core (Q30) here.
set(ASCORR_TARGET_NAME cortex-m3)
set(ASCORR_QEMU_MACHINE mps2-an385)
set(ASCORR_APP_SCALAR fixed)
set(ASCORR_CPU_FLAGS "-mcpu=cortex-m3 -mthumb -mfloat-abi=soft")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-picolibc.cmake)
