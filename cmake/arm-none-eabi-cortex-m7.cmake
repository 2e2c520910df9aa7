# SPDX-License-Identifier: Apache-2.0
# Cross toolchain: arm-none-eabi-gcc for a Cortex-M7 with the single-precision
# FPU (STM32H743). Used by the cm7-release preset (CMakePresets.json).
#
# float-abi=hard with fpv5-sp-d16: float32 arithmetic runs on the FPU and is
# passed in FPU registers; any double would fall back to soft-float library
# calls, which the firmware warnings (-Wdouble-promotion) keep out.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
# which images this build makes (hal/, target/mps2)
set(BR_TARGET_CPU cortex-m7)

set(BR_CROSS_PREFIX arm-none-eabi- CACHE STRING "Prefix of the cross tools")
find_program(BR_CROSS_GCC ${BR_CROSS_PREFIX}gcc REQUIRED)

set(CMAKE_C_COMPILER   ${BR_CROSS_GCC})
set(CMAKE_ASM_COMPILER ${BR_CROSS_GCC})
get_filename_component(_br_cross_dir ${BR_CROSS_GCC} DIRECTORY)
find_program(CMAKE_OBJCOPY ${BR_CROSS_PREFIX}objcopy HINTS ${_br_cross_dir} REQUIRED)
find_program(CMAKE_SIZE    ${BR_CROSS_PREFIX}size    HINTS ${_br_cross_dir} REQUIRED)

# No OS and no hosted startup: compiler checks build a static library only.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(BR_CM7_CPU_FLAGS "-mcpu=cortex-m7 -mthumb -mfpu=fpv5-sp-d16 -mfloat-abi=hard")
set(CMAKE_C_FLAGS_INIT   "${BR_CM7_CPU_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_ASM_FLAGS_INIT "${BR_CM7_CPU_FLAGS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${BR_CM7_CPU_FLAGS} --specs=nano.specs -Wl,--gc-sections")

# Look for programs on the host, for libraries and headers only in the sysroot.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
