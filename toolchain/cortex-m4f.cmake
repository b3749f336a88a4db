# toolchain/cortex-m4f.cmake: Cortex-M4F, single-precision FPU (FPv4-SP-D16),
# hard-float ABI, QEMU mps2-an386. The firmware runs the float core here.
set(ASCORR_TARGET_NAME cortex-m4f)
set(ASCORR_QEMU_MACHINE mps2-an386)
set(ASCORR_APP_SCALAR float)
set(ASCORR_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-picolibc.cmake)
