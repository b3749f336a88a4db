# toolchain/cortex-m4f.cmake: Cortex-M4F, single-precision FPU (FPv4-SP-D16),
# hard-float ABI; the firmware runs the float core here. Its QEMU board,
# scalars and CPU flags: toolchain/targets.txt.
set(ASCORR_TARGET_NAME cortex-m4f)
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-picolibc.cmake)
