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

# allocation_tests first: one of its shards holds the brute-force enumeration of every mask (the
# longest shard), so it starts while the other core works through the rest.
sanitized=(allocation/allocation_tests gnc/gnc_tests hal/hal_tests fsw/fsw_tests)
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$jobs" --target "${sanitized[@]##*/}"
# Each binary in two gtest shards, run side by side (about 200 s of tests on one core otherwise);
# a shard's output is kept in build/asan and printed if it fails.
asan_shard() {
  local t=$1 s=$2 log="build/asan/${1##*/}.shard$2.log"
  if GTEST_TOTAL_SHARDS=2 GTEST_SHARD_INDEX=$s "build/asan/tests/$t" --gtest_brief=1 >"$log" 2>&1; then
    echo "asan+ubsan: $t shard $((s + 1))/2: $(grep -m1 'PASSED' "$log")"
  else
    echo "asan+ubsan: FAIL: $t shard $((s + 1))/2" >&2
    cat "$log" >&2
    return 1
  fi
}
export -f asan_shard
for t in "${sanitized[@]}"; do printf '%s 0\n%s 1\n' "$t" "$t"; done |
  xargs -P "$jobs" -n 2 bash -c 'asan_shard "$@"' _

cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
scripts/cross.sh
