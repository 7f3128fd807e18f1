#!/usr/bin/env bash
# PIL benchmarks (printed, not asserted): lockstep throughput over LCM (base ticks per wall second,
# plant + fsw in a private network namespace) and real-time tick jitter of rocksteady-fsw at 10 Hz
# and 100 Hz (|tick start - ideal deadline|: median, p99, max), with a real-time plant on the bus.
#
# Lockstep is measured in four bus layouts, on case 1 for --sim-s simulated seconds each:
#   one bus        every channel on one LCM URL (every process's receive thread wakes for every message)
#   split          sensor frames on --lcm-url, thruster commands on --actuator-lcm-url, ground channels
#                  (telemetry, truth, events, commands) on --ground-lcm-url: each process receives
#                  only what it consumes
#   split+direct   split, and the hot channel read by each loop itself (--direct-rx): no LCM receive
#                  thread on the hot path, one wake-up per message
# each with telemetry (and plant truth) every tick and every 10th. CPU time and context switches
# per tick are both processes' (every thread, getrusage at exit) divided by the ticks. The figures of merit
# of every layout must be identical (printed).
#
# Usage: tests/pil/bench.sh [BUILD_DIR] [SECONDS_PER_JITTER_RUN] [--sim-s S] [--no-jitter]
#                           [--readme FILE]   (default build/release, 20, 3000)
#   --readme FILE writes the lockstep table into FILE between <!-- pil-bench:begin --> and
#   <!-- pil-bench:end -->.
set -euo pipefail
cd "$(dirname "$0")/../.."
pos=() sim=3000 jitter=1 readme=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --sim-s) sim="$2"; shift 2 ;;
    --no-jitter) jitter=0; shift ;;
    --readme) readme="$2"; shift 2 ;;
    *) pos+=("$1"); shift ;;
  esac
done
build="${pos[0]:-build/release}"
secs="${pos[1]:-20}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export B_FSW="$build/fsw/main/rocksteady-fsw" B_PLANT="$build/ground/plantd/rocksteady-plant" B_SECS="$secs" \
       B_SIM="$sim" B_JITTER="$jitter" B_OUT="$out"
for p in "$B_FSW" "$B_PLANT"; do [[ -x "$p" ]] || { echo "bench.sh: $p not found" >&2; exit 2; }; done
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
unshare -rn bash -c '
  set -eu
  ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo
  url="udpm://239.255.76.67:7900?ttl=0"
  act="udpm://239.255.76.67:7901?ttl=0"
  gnd="udpm://239.255.76.67:7902?ttl=0"
  for layout in one split direct; do
    for tlm in 1 10; do
      fx=(); px=()
      if [[ $layout != one ]]; then
        fx=(--actuator-lcm-url "$act" --ground-lcm-url "$gnd"); px=(--actuator-lcm-url "$act" --ground-lcm-url "$gnd")
      fi
      if [[ $layout == direct ]]; then fx+=(--direct-rx); px+=(--direct-rx); fi
      "$B_FSW" --lcm-url "$url" --lab-mode --case 1 --start-mode DETUMBLE --tlm-every $tlm -v "${fx[@]}" \
          > "$B_OUT/fsw.log" & f=$!
      "$B_PLANT" --lcm-url "$url" --case 1 --duration "$B_SIM" --summary --truth-every $tlm "${px[@]}" \
          > "$B_OUT/plant.log"
      kill $f; wait $f 2> /dev/null || true
      s=$(grep "^summary:" "$B_OUT/plant.log")
      fp=$(grep "^fsw process:" "$B_OUT/fsw.log")
      v() { sed -E "s/.* $1=([^ ]+).*/\1/" <<< "$s"; }
      fv() { sed -E "s/.* $1=([^ ]+).*/\1/" <<< " $fp"; }
      periods=$(v periods); wall=$(v wall_s)
      cpu=$(awk -v a=$(v cpu_s) -v b=$(fv cpu_s) -v p=$periods "BEGIN{printf \"%.1f\", (a+b)*1e6/p}")
      c=$(awk -v a=$(v ctx) -v b=$(fv ctx) -v p=$periods "BEGIN{printf \"%.2f\", (a+b)/p}")
      lname=$layout; [[ $layout == direct ]] && lname="split+direct"
      awk -v p=$periods -v w=$wall -v t=$tlm -v to=$(v timeouts) -v c=$c -v l="$lname" \
        -v cpu=$cpu "BEGIN{printf \"| %s | %d | %d | %.2f | %.0f | %s | %s | %d |\n\", l, t, p, w, p/w, cpu, c, to}" >> "$B_OUT/rows"
      echo "$layout tlm=$tlm: t_omega=$(v t_omega) t_q=$(v t_q) total_fuel=$(v total_fuel) final_rate=$(v final_rate)" >> "$B_OUT/fom"
    done
  done
  if [[ $B_JITTER == 1 ]]; then
    for rate in 10 100; do
      "$B_PLANT" --lcm-url "$url" --case 1 --mode realtime --duration $((B_SECS + 5)) > /dev/null & p=$!
      "$B_FSW" --lcm-url "$url" --lab-mode --case 1 --clock realtime --rate $rate --start-mode DETUMBLE \
          --exit-after "$B_SECS" --jitter | grep "jitter" >> "$B_OUT/jitter"
      kill $p; wait $p 2>/dev/null || true
    done
  fi
'
{
  echo "Measured by \`tests/pil/bench.sh --sim-s $sim\` on $(date -u +%Y-%m-%d), $(nproc) cores: case 1, lockstep, $(( sim * 10 )) ticks per row."
  echo
  echo "| buses | telemetry + truth every | ticks | wall s | ticks/s | CPU µs per tick | context switches per tick | echo timeouts |"
  echo "|---|---|---|---|---|---|---|---|"
  cat "$out/rows"
  echo
  if [[ $(cut -d: -f2 "$out/fom" | sort -u | wc -l) -eq 1 ]]; then
    echo "Figures of merit identical in every row:$(cut -d: -f2 "$out/fom" | head -1)"
  else
    echo "FIGURES OF MERIT DIFFER:"; sed 's/^/    /' "$out/fom"
  fi
} > "$out/table.md"
cat "$out/table.md"
[[ -f "$out/jitter" ]] && cat "$out/jitter"
if [[ -n "$readme" ]]; then
  "$(dirname "$0")/../../scripts/put-block.py" "$readme" pil-bench "$out/table.md"
fi
