#!/usr/bin/env bash
# PIL benchmarks (printed, not asserted): lockstep throughput over LCM (base ticks per wall second,
# plant + fsw in a private network namespace) and real-time tick jitter of rocksteady-fsw at 10 Hz
# and 100 Hz (|tick start - ideal deadline|: median, p99, max), with a real-time plant on the bus.
#
# Usage: tests/pil/bench.sh [BUILD_DIR] [SECONDS_PER_JITTER_RUN]   (default build/release, 20)
set -euo pipefail
cd "$(dirname "$0")/../.."
build="${1:-build/release}"
secs="${2:-20}"
export B_FSW="$build/fsw/main/rocksteady-fsw" B_PLANT="$build/ground/plantd/rocksteady-plant" B_SECS="$secs"
for p in "$B_FSW" "$B_PLANT"; do [[ -x "$p" ]] || { echo "bench.sh: $p not found" >&2; exit 2; }; done
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
unshare -rn bash -c '
  set -eu
  ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo
  url="udpm://239.255.76.67:7900?ttl=0"
  for tlm in 1 10 100; do
    "$B_FSW" --lcm-url "$url" --case 1 --start-mode DETUMBLE --tlm-every $tlm & f=$!
    s=$("$B_PLANT" --lcm-url "$url" --case 1 --duration 3000 --summary --truth-every $tlm | grep "^summary:")
    kill $f; wait $f 2>/dev/null || true
    periods=$(sed -E "s/.* periods=([0-9]+).*/\1/" <<<"$s"); wall=$(sed -E "s/.* wall_s=([0-9.]+).*/\1/" <<<"$s")
    timeouts=$(sed -E "s/.* timeouts=([0-9]+).*/\1/" <<<"$s")
    awk -v p=$periods -v w=$wall -v t=$tlm -v to=$timeouts "BEGIN{printf \"lockstep: %d ticks in %.2f s = %.0f ticks/s (telemetry and truth every %d ticks, echo timeouts %d)\n\", p, w, p/w, t, to}"
  done
  for rate in 10 100; do
    "$B_PLANT" --lcm-url "$url" --case 1 --mode realtime --duration $((B_SECS + 5)) > /dev/null & p=$!
    "$B_FSW" --lcm-url "$url" --case 1 --clock realtime --rate $rate --start-mode DETUMBLE \
        --exit-after "$B_SECS" --jitter | grep "jitter"
    kill $p; wait $p 2>/dev/null || true
  done
'
