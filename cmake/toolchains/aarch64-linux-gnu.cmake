# Cross build of the flight side for 64-bit ARM Linux (aarch64), with Debian's cross compiler
# (g++-aarch64-linux-gnu) and Debian multiarch target libraries (/usr/lib/aarch64-linux-gnu, e.g.
# libgtest-dev:arm64, libglib2.0-dev:arm64). Cross-built tests run under qemu-aarch64 through
# CMAKE_CROSSCOMPILING_EMULATOR, so plain `ctest` works on an x86-64 host.
#
# Libraries that are not multi-arch in Debian (LCM: installing liblcm-dev:arm64 would remove the
# host's lcm-gen and lcm.jar; yaml-cpp: libyaml-cpp-dev:arm64 would remove the host's; IPOPT, in
# /usr/lib, likewise) come from a private sysroot unpacked inside the build tree
# (scripts/cross.sh: `apt-get download` + `dpkg -x`). Point ROCKSTEADY_TARGET_SYSROOT at it; it is
# searched in addition to the multiarch directories, by find_* and by pkg-config.
#
# Header-only host packages (Eigen) are architecture-independent and used from /usr as they are.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

# Bit-identical to the host: no fused multiply-add anywhere in the target's code. Two sources of FMA
# on aarch64 that x86-64 (SSE2, no -mfma) never uses, each changing results in the last bits:
#  - GCC's default -ffp-contract=fast fuses a*b + c into one FMA instruction: -ffp-contract=off;
#  - Eigen's NEON packet math calls the vfmaq_f64 intrinsic for pmadd whenever __ARM_FEATURE_FMA is
#    defined, whatever the contraction setting: undefining the macro selects its vmlaq_f64 path,
#    which GCC implements as a separate multiply and add (unfused under -ffp-contract=off).
# With both, the board's GNC steps are bit-identical to the host's (and the PIL figures of merit,
# scripts/pil-qemu.sh), so the host's bit-for-bit tests speak for the board. With the defaults, and
# still with -ffp-contract=off alone, the fast case 1's fuel and end state differ by 1e-16..1e-14
# relative (same convergence times). These flags apply at a fresh configure (scripts/cross.sh
# configures afresh when this file is newer than the build's cache). Cost on the target,
# instructions per Gnc::step (scripts/cross.sh --bench): DETUMBLE 856 -> 892 (+4 %), HOLD 1276 ->
# 1372 (+8 %); -ffp-contract=off alone gives 871 / 1334 and is not enough.
set(CMAKE_C_FLAGS_INIT "-ffp-contract=off")
set(CMAKE_CXX_FLAGS_INIT "-ffp-contract=off -U__ARM_FEATURE_FMA")

# Try-compile projects re-read this file: forward the sysroot location to them.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES ROCKSTEADY_TARGET_SYSROOT)

set(_rs_multiarch_pc /usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig)
# Unpack the private sysroot (the script is a no-op when its stamp lists the current packages, and
# unpacks again when the package list has grown).
if(ROCKSTEADY_TARGET_SYSROOT)
  execute_process(COMMAND "${CMAKE_CURRENT_LIST_DIR}/arm64-sysroot.sh" "${ROCKSTEADY_TARGET_SYSROOT}"
                  RESULT_VARIABLE _rs_sysroot_rc)
  if(NOT _rs_sysroot_rc EQUAL 0)
    message(WARNING "Could not unpack the arm64 sysroot into ${ROCKSTEADY_TARGET_SYSROOT} "
                    "(needs `dpkg --add-architecture arm64` and apt-get update; see scripts/cross.sh)")
  endif()
endif()
if(ROCKSTEADY_TARGET_SYSROOT AND IS_DIRECTORY "${ROCKSTEADY_TARGET_SYSROOT}")
  # find_package/find_library/find_path: the private sysroot first, then the multiarch /usr.
  list(PREPEND CMAKE_PREFIX_PATH "${ROCKSTEADY_TARGET_SYSROOT}/usr")
  # pkg-config: only target .pc files, never the host's x86-64 ones. The sysroot's .pc files have
  # their prefix rewritten to the sysroot when it is unpacked.
  set(ENV{PKG_CONFIG_LIBDIR}
      "${ROCKSTEADY_TARGET_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${ROCKSTEADY_TARGET_SYSROOT}/usr/lib/pkgconfig:${_rs_multiarch_pc}")
  set(_rs_guest_env -E
      "LD_LIBRARY_PATH=${ROCKSTEADY_TARGET_SYSROOT}/usr/lib/aarch64-linux-gnu:${ROCKSTEADY_TARGET_SYSROOT}/usr/lib")
else()
  set(ENV{PKG_CONFIG_LIBDIR} "${_rs_multiarch_pc}")
  set(_rs_guest_env)
endif()
unset(ENV{PKG_CONFIG_PATH})

# Programs (lcm-gen, pkg-config) are the host's; libraries and headers are the target's. Without a
# CMAKE_FIND_ROOT_PATH, find_* search the normal prefixes; CMAKE_LIBRARY_ARCHITECTURE restricts
# library lookups to the aarch64 multiarch directories.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)

# Run cross-built programs (tests, gtest discovery) under user-mode qemu. The loader and multiarch
# libraries are found at their normal paths (/lib/ld-linux-aarch64.so.1): no QEMU_LD_PREFIX, which
# would mix the cross C library with the multiarch one.
find_program(ROCKSTEADY_QEMU_AARCH64 qemu-aarch64 REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR ${ROCKSTEADY_QEMU_AARCH64} ${_rs_guest_env})
