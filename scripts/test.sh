#!/usr/bin/env bash
# Everything the test suite needs, from a fresh Debian 12 machine: packages, configure, build, run.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc)
cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
