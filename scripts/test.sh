#!/usr/bin/env bash
# Everything the test suite needs, from a fresh Debian 12 machine: packages, configure, build, run.
#   1. the flight side's unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (asan preset);
#   2. the native suite (release preset): unit, closed-loop, PIL-over-LCM, fuzz and tool tests;
#   3. the cross builds (scripts/cross.sh): the flight side for aarch64 with its tests under
#      qemu-aarch64, PIL on the emulated board, and the bare-metal Cortex-M7 image in qemu-system-arm.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc)

sanitized=(gnc/gnc_tests allocation/allocation_tests hal/hal_tests fsw/fsw_tests)
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$jobs" --target "${sanitized[@]##*/}"
for t in "${sanitized[@]}"; do
  echo "asan+ubsan: $t"
  "build/asan/tests/$t" --gtest_brief=1
done

cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
scripts/cross.sh
