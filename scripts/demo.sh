#!/usr/bin/env bash
# Rocksteady's main job, from a fresh Debian 12 machine: install what is missing, build the release
# preset, then despin and point the spacecraft + asteroid of the study's case 1 with the robust NTCL
# tracking the D+PD-based reference, processor-in-the-loop: the plant and the flight software as two
# processes on an LCM bus (with lcm-logger recording it) in a private network namespace, in lockstep.
# Prints the plant's summary and leaves out/pil/case1.lcmlog for lcm-logplayer / lcm-spy.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release
echo
echo "== case 1, ntcl+dpd_ref: 10^5 s of closed loop at 10 Hz, plant and flight software over LCM =="
scripts/pil.sh 1 "$@"
echo
echo "Same case in one process:  build/release/ground/campaign/rocksteady-campaign run --case 1 --strategy ntcl+dpd_ref"
echo "Whole study table (7 cases x 6 strategies):  build/release/ground/campaign/rocksteady-campaign campaign"
echo "Live with lcm-spy, replaying the log:  fsw/main/README.md"
ground=build/release/ground/cli/rocksteady-ground
log=out/pil/case1.lcmlog
if [[ -f "$log" ]] && png=$("$ground" plot "$log" -o out/pil/case1.png 2>/dev/null); then
  echo "Figure 3 of this run:  $png"
fi
echo "Operations console (NASA Open MCT in the browser):  $ground serve   then open http://127.0.0.1:8090/"
echo "  (on this bus: live telemetry and events, commands, sequences; see ground/console/README.md)"
