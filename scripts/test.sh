#!/usr/bin/env bash
# Everything the test suite needs, from a fresh Debian 12 machine: packages, configure, build, run.
#   1. the native suite (release preset): unit, closed-loop, PIL-over-LCM, fuzz and tool tests;
#   2. the cross builds (scripts/cross.sh): the flight side for aarch64 with its tests under
#      qemu-aarch64, and the bare-metal Cortex-M7 image run in qemu-system-arm.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc)
cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
scripts/cross.sh
