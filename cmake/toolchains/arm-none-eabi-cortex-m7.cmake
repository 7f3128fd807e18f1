# Bare-metal Cortex-M7 with the double-precision FPU (FPv5-D16), hard-float ABI, Thumb-2, newlib-nano
# (Debian: gcc-arm-none-eabi, libstdc++-arm-none-eabi-newlib). For the gnc core alone plus the
# firmware image (ROCKSTEADY_GNC_ONLY=ON, ROCKSTEADY_BAREMETAL=ON); the image runs on QEMU's
# mps2-an500 board (Cortex-M7) with semihosting output. See firmware/README.md.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR cortex-m7)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
find_program(CMAKE_OBJCOPY arm-none-eabi-objcopy)
find_program(CMAKE_SIZE arm-none-eabi-size)
# No OS to link a test program against: check the compilers by building a static library.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(_rs_cpu "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb")
# -ffunction/data-sections + --gc-sections: only what the image calls is linked.
# -fno-math-errno: sqrt() becomes the FPU's vsqrt.f64 (no errno on bare metal anyway).
set(_rs_common "${_rs_cpu} -ffunction-sections -fdata-sections -fno-math-errno")
# Eigen on bare metal: no debug assertions (no assert/abort path), no SIMD (M-profile has none).
string(APPEND _rs_common " -DEIGEN_NO_DEBUG -DEIGEN_DONT_VECTORIZE")
set(CMAKE_C_FLAGS_INIT "${_rs_common}")
# The flight core's flying configuration: no exceptions, no RTTI, no thread-safe static guards (one
# thread, no OS).
set(CMAKE_CXX_FLAGS_INIT "${_rs_common} -fno-exceptions -fno-rtti -fno-threadsafe-statics")
set(CMAKE_ASM_FLAGS_INIT "${_rs_cpu}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${_rs_cpu} --specs=nano.specs -Wl,--gc-sections")


# Headers and CMake packages of architecture-independent host packages (Eigen: header-only) are
# found in the normal prefixes; there are no target libraries outside the toolchain's own.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
