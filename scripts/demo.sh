#!/usr/bin/env bash
# Rocksteady's main job, from a fresh Debian 12 machine: install what is missing, build the release
# preset, then despin and point the spacecraft + asteroid of the study's case 1 with the robust NTCL
# tracking the D+PD-based reference (plant and flight core in one process), and show the result.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release
echo
echo "== case 1, ntcl+dpd_ref: 10^5 s of closed loop at 10 Hz =="
build/release/ground/campaign/rocksteady-campaign run --case 1 --strategy ntcl+dpd_ref --out out/demo "$@"
echo
echo "Whole study table (7 cases x 6 strategies):  build/release/ground/campaign/rocksteady-campaign campaign"
