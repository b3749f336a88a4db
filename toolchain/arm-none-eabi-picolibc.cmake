# toolchain/arm-none-eabi-picolibc.cmake: the part of the Cortex-M toolchain
# files common to every core (included by each toolchain/<cpu>.cmake of
# toolchain/targets.txt).
#
# Debian 12's gcc-arm-none-eabi with picolibc-arm-none-eabi (picolibcpp.specs):
# bare metal, no exceptions, no RTTI, no thread-safe statics, sections per
# function so that --gc-sections keeps only what is used. Images run on QEMU's
# MPS2 boards (toolchain/qemu-run) with semihosting for stdio and exit status;
# the board's memory map is passed to picolibc's linker script here.
# The including file sets ASCORR_TARGET_NAME (a cpu of toolchain/targets.txt);
# its line there gives ASCORR_CPU_FLAGS, ASCORR_QEMU_MACHINE, ASCORR_APP_SCALAR
# (fixed or float: the scalar the firmware runs) and ASCORR_TARGET_SCALARS
# (the accuracy images').
include(${CMAKE_CURRENT_LIST_DIR}/target-table.cmake)
ascorr_read_targets()
if(NOT ASCORR_TARGET_NAME IN_LIST ASCORR_TARGET_LIST)
  message(FATAL_ERROR "ASCORR_TARGET_NAME '${ASCORR_TARGET_NAME}' is not a cpu of ${ASCORR_TARGET_TABLE}")
endif()
set(ASCORR_CPU_FLAGS "${ASCORR_TARGET_${ASCORR_TARGET_NAME}_FLAGS}")
set(ASCORR_QEMU_MACHINE ${ASCORR_TARGET_${ASCORR_TARGET_NAME}_MACHINE})
set(ASCORR_APP_SCALAR ${ASCORR_TARGET_${ASCORR_TARGET_NAME}_SCALAR})
set(ASCORR_TARGET_SCALARS ${ASCORR_TARGET_${ASCORR_TARGET_NAME}_SCALARS})
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(CMAKE_CXX_FLAGS_INIT
    "${ASCORR_CPU_FLAGS} --specs=picolibcpp.specs -ffunction-sections -fdata-sections -fno-exceptions -fno-rtti -fno-threadsafe-statics -fno-unwind-tables -fno-asynchronous-unwind-tables")
set(CMAKE_C_FLAGS_INIT "${ASCORR_CPU_FLAGS} --specs=picolibc.specs -ffunction-sections -fdata-sections")
# MPS2 AN385/AN386: 4 MiB code SSRAM at 0x0 (our "flash"), 4 MiB data SSRAM at
# 0x20000000. picolibc's crt0 sets up .data/.bss, the vector table and the FPU;
# its linker script, with the stack's size: ascorr-picolibc.ld.
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "--oslib=semihost --crt0=semihost -Wl,--gc-sections -Wl,--defsym=__flash=0x0 -Wl,--defsym=__flash_size=0x400000 -Wl,--defsym=__ram=0x20000000 -Wl,--defsym=__ram_size=0x400000 -T${CMAKE_CURRENT_LIST_DIR}/ascorr-picolibc.ld")

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
