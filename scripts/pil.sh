#!/usr/bin/env bash
# Processor-in-the-loop demo: rocksteady-plant, rocksteady-fsw and lcm-logger as separate processes on
# an LCM bus inside a private network namespace (works on any machine, touches no network), one case
# in lockstep; prints the plant's summary (SPEC §7 figures of merit, bus statistics) and leaves an
# LCM log for lcm-logplayer / lcm-spy.
#
# Usage: scripts/pil.sh [CASE] [options]
#   CASE                 case number (configs/cases/caseN.yaml) or a case file (default 1)
#   --law NAME           control law of the flight software (default ntcl: the ntcl+dpd_ref strategy)
#   --duration S         simulated seconds (default: the case's)
#   --mode M             lockstep (default) or realtime (wall clock: 10^5 s take 10^5 s)
#   --tlm-every N        telemetry and truth every N ticks (default 100 = every 10 s simulated)
#   --log-all            also log RS_SENSORS and RS_THRUSTER_CMD (10^6 messages each for case 1)
#   --build DIR          build tree with the programs (default build/release)
#   --out DIR            output folder (default out/pil): <case>.lcmlog, <case>.csv, <case>.*.log
#   --port P             LCM port inside the namespace (default 7667)
#   --one-bus            every channel on one bus (the default for --mode realtime and --log-all);
#                        otherwise lockstep runs on three buses, sensor frames on port P, thruster
#                        commands on P+1, ground channels (logged) on P+2, with the hot channels read
#                        directly by each loop (--direct-rx): several times faster, the same figures
# Live on a workstation with lcm-spy instead: see fsw/main/README.md.
set -euo pipefail
cd "$(dirname "$0")/.."

case_arg=1 law=ntcl duration="" mode=lockstep tlm_every=100 log_all=0 build=build/release out=out/pil
port=7667 one_bus=0
while (($#)); do
  case "$1" in
    --law) law="$2"; shift 2 ;;
    --duration) duration="$2"; shift 2 ;;
    --mode) mode="$2"; shift 2 ;;
    --tlm-every) tlm_every="$2"; shift 2 ;;
    --log-all) log_all=1; shift ;;
    --build) build="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --port) port="$2"; shift 2 ;;
    --one-bus) one_bus=1; shift ;;
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "pil.sh: unknown option $1" >&2; exit 2 ;;
    *) case_arg="$1"; shift ;;
  esac
done

fsw="$build/fsw/main/rocksteady-fsw"
plant="$build/ground/plantd/rocksteady-plant"
for p in "$fsw" "$plant"; do
  [[ -x "$p" ]] || { echo "pil.sh: $p not found: build first (cmake --preset release && cmake --build --preset release)" >&2; exit 2; }
done
command -v lcm-logger >/dev/null || { echo "pil.sh: lcm-logger not found (apt-get install liblcm-bin)" >&2; exit 2; }
command -v unshare >/dev/null || { echo "pil.sh: unshare not found (util-linux)" >&2; exit 2; }

if [[ "$case_arg" =~ ^[0-9]+$ ]]; then name="case$case_arg"; else name="$(basename "$case_arg" .yaml)"; fi
mkdir -p "$out"
log="$out/$name.lcmlog"
rm -f "$log"
channels='RS_(GNC_TLM|PLANT_TRUTH|EVENTS|CMD_ACK|GROUND_CMD|TRAJ_UPLINK)'
((log_all)) && channels='.*'
clock=$mode; [[ "$mode" == lockstep ]] || clock=realtime

export PIL_FSW="$fsw" PIL_PLANT="$plant" PIL_CASE="$case_arg" PIL_LAW="$law" PIL_LOG="$log"
export PIL_CHANNELS="$channels" PIL_OUT="$out" PIL_NAME="$name" PIL_TLM="$tlm_every"
export PIL_MODE="$mode" PIL_CLOCK="$clock" PIL_DURATION="$duration"
export PIL_URL="udpm://239.255.76.67:$port?ttl=0" PIL_LOG_URL="udpm://239.255.76.67:$port?ttl=0"
PIL_BUSES=""
if ((!one_bus && !log_all)) && [[ "$mode" == lockstep ]]; then
  PIL_LOG_URL="udpm://239.255.76.67:$((port + 2))?ttl=0"
  PIL_BUSES="--actuator-lcm-url udpm://239.255.76.67:$((port + 1))?ttl=0 --ground-lcm-url $PIL_LOG_URL --direct-rx"
fi
export PIL_BUSES

echo "== PIL: $name, law $law, $mode; plant + fsw + lcm-logger in a private network namespace =="
rc=0
unshare -rn bash -c '
  set -u
  ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo
  lcm-logger -q --lcm-url="$PIL_LOG_URL" --channel="$PIL_CHANNELS" -f "$PIL_LOG" > /dev/null 2>&1 & logger=$!
  "$PIL_FSW" --lcm-url "$PIL_URL" --case "$PIL_CASE" --law "$PIL_LAW" --clock "$PIL_CLOCK" \
      --start-mode DETUMBLE --tlm-every "$PIL_TLM" -v $PIL_BUSES > "$PIL_OUT/$PIL_NAME.fsw.log" 2>&1 & fsw=$!
  trap "kill $fsw $logger 2>/dev/null" EXIT
  sleep 0.5   # the logger and the flight software subscribe; the plant waits for frame 0 anyway
  dur=(); [[ -n "$PIL_DURATION" ]] && dur=(--duration "$PIL_DURATION")
  "$PIL_PLANT" --lcm-url "$PIL_URL" --case "$PIL_CASE" --mode "$PIL_MODE" --summary \
      --truth-every "$PIL_TLM" --out "$PIL_OUT/$PIL_NAME.csv" "${dur[@]}" $PIL_BUSES 2> "$PIL_OUT/$PIL_NAME.plant.err"
  rc=$?
  sleep 0.3   # the last telemetry reaches the log
  kill -INT $fsw $logger 2>/dev/null; wait $fsw $logger 2>/dev/null
  trap - EXIT
  exit $rc
' || rc=$?
echo
echo "LCM log:      $log ($(du -h "$log" | cut -f1)); flight software log: $out/$name.fsw.log; time series: $out/$name.csv"
echo "Replay it:    lcm-logplayer -s 10 $log   (with ground/spy/rocksteady-spy running, see fsw/main/README.md)"
exit $rc
