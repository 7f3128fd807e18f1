#!/usr/bin/env bash
# Real-time jitter benchmark of rocksteady-fsw (a benchmark that prints, not a test).
#
# For each base rate (10 Hz, 100 Hz), without and with the hardening, and under each load (none; a CPU
# load on every core; a garbage flood on the ground command channel), runs rocksteady-fsw --clock
# realtime against rocksteady-plant --mode realtime for a fixed time and reports the tick-start
# lateness (tick start - its absolute deadline: p50, p99, max, from rocksteady-fsw --jitter) and the
# frames the flight software missed (GNC ticks without a new sensor frame, frames superseded before
# a tick used them, base ticks skipped).
#
#   hardening off:  normal scheduling, one bus for everything
#   hardening on:   fsw --sched-fifo 80 --mlockall --cpu 1, plant --sched-fifo 70 --mlockall --cpu 0,
#                   ground channels on their own bus (--ground-lcm-url); the flood then hits that bus
#   load cpu:       stress-ng --cpu <cores> (a busy loop per core without stress-ng)
#   load flood:     scripts/lcm-flood.py, as fast as it can, on RS_GROUND_CMD
#
# Usage: scripts/jitter-bench.sh [--build DIR] [--seconds S] [--rates "10 100"] [--readme FILE]
#   --readme FILE  also writes the table into FILE between the markers
#                  <!-- jitter-bench:begin --> and <!-- jitter-bench:end -->
# Runs in a private network namespace. SCHED_FIFO needs real root (or CAP_SYS_NICE / RLIMIT_RTPRIO):
# as root the namespace is network-only (`unshare -n`); otherwise `unshare -rn`, where the kernel
# refuses SCHED_FIFO and the hardened rows say so instead of running degraded.
set -euo pipefail
cd "$(dirname "$0")/.."
build=build/release secs=20 rates="10 100" readme=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --seconds) secs="$2"; shift 2 ;;
    --rates) rates="$2"; shift 2 ;;
    --readme) readme="$2"; shift 2 ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    *) echo "jitter-bench.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
fsw="$build/fsw/main/rocksteady-fsw" plant="$build/ground/plantd/rocksteady-plant"
for p in "$fsw" "$plant"; do [[ -x "$p" ]] || { echo "jitter-bench.sh: $p not found (build first)" >&2; exit 2; }; done
if [[ $(id -u) -eq 0 ]]; then ns=(unshare -n); else ns=(unshare -rn); fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

export B_FSW="$fsw" B_PLANT="$plant" B_SECS="$secs" B_RATES="$rates" B_OUT="$out" B_NCPU="$(nproc)"
"${ns[@]}" bash -c '
  set -u
  ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo
  port=7950
  load_start() {  # $1 = none|cpu|flood, $2 = ground url
    case "$1" in
      cpu) if command -v stress-ng > /dev/null; then stress-ng --cpu "$B_NCPU" --timeout $((B_SECS + 10))s -q & else
             for i in $(seq "$B_NCPU"); do (while :; do :; done) & done; fi ;;
      flood) python3 scripts/lcm-flood.py --url "$2" --seconds $((B_SECS + 10)) > /dev/null & ;;
    esac
  }
  load_stop() { jobs -p | xargs -r kill 2> /dev/null; wait 2> /dev/null || true; }
  for rate in $B_RATES; do
    for hard in off on; do
      for load in none cpu flood; do
        port=$((port + 2))
        url="udpm://239.255.76.67:$port?ttl=0"; gurl="$url"
        fx=(); px=()
        if [[ $hard == on ]]; then
          gurl="udpm://239.255.76.67:$((port + 1))?ttl=0"
          fx=(--sched-fifo 80 --mlockall --cpu 1 --ground-lcm-url "$gurl")
          px=(--sched-fifo 70 --mlockall --cpu 0 --ground-lcm-url "$gurl")
        fi
        load_start "$load" "$gurl"
        sleep 0.5
        "$B_PLANT" --lcm-url "$url" --case 1 --mode realtime --duration $((B_SECS + 3)) "${px[@]}" \
            > "$B_OUT/plant.log" 2>&1 &
        pp=$!
        "$B_FSW" --lcm-url "$url" --lab-mode --case 1 --clock realtime --rate "$rate" --start-mode DETUMBLE \
            --exit-after "$B_SECS" --jitter "${fx[@]}" > "$B_OUT/fsw.log" 2>&1
        rc=$?
        kill $pp 2> /dev/null; wait $pp 2> /dev/null
        load_stop
        j=$(grep "^fsw jitter:" "$B_OUT/fsw.log" || true)
        b=$(grep "^fsw bus:" "$B_OUT/fsw.log" || true)
        if [[ $rc -ne 0 || -z "$j" ]]; then
          why=$(grep -m1 "refused\|cannot" "$B_OUT/fsw.log" | sed "s/|/\\\\|/g" || true)
          echo "| $rate | $hard | $load | – | – | – | – | – | – | fsw exit $rc: ${why:-see log} |" >> "$B_OUT/rows"
          continue
        fi
        v() { sed -E "s/.* $1=([0-9.]+).*/\1/" <<< "$2"; }
        echo "| $rate | $hard | $load | $(v median "$j") | $(v p99 "$j") | $(v max "$j") | $(v ticks "$b") | $(v frameless "$b") | $(v superseded "$b") | missed base ticks $(v missed "$b"), ground dropped $(v ground_dropped "$b") |" >> "$B_OUT/rows"
      done
    done
  done
'
{
  echo "Measured by \`scripts/jitter-bench.sh --seconds $secs\` on $(date -u +%Y-%m-%d), $(nproc) cores, kernel $(uname -r), $(if [[ $(id -u) -eq 0 ]]; then echo root; else echo "not root"; fi); lateness = tick start − its deadline, µs."
  echo
  echo "| Hz | hardening | load | p50 µs | p99 µs | max µs | ticks | GNC ticks without a frame | frames superseded | notes |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
  cat "$out/rows"
} > "$out/table.md"
cat "$out/table.md"
if [[ -n "$readme" ]]; then
  "$(dirname "$0")/put-block.py" "$readme" jitter-bench "$out/table.md"
fi
